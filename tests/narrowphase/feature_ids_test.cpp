// Contact::featureA / featureB / featureKind and the two points of a contact (contact.h), checked
// against brute force: the triangles an exact contact names contain its point, the spheres a
// sphere-model contact names contain it, the contact tree names real cells; and the two points
// of a box resting in a box lie on the two faces (analytic).
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "clod/primitives.h"
#include "narrowphase/narrowphase_test_support.h"

namespace clod {
namespace {

using test::makeTestBody;
using test::randomPose;
using test::settingsFor;

const CollisionBody& ball() {
  // Not a faceted patch (80 face normals), so the exact model tests triangles.
  static const CollisionBody body = makeTestBody(makeIcosphere(0.5, 2), 2);
  return body;
}
const CollisionBody& cube() {
  static const CollisionBody body = makeTestBody(makeBox(Vec3(0.5, 0.5, 0.5)), 2);
  return body;
}

double distanceToTriangle(const TriangleMesh& mesh, std::uint32_t t, const Vec3& pLocal) {
  return std::sqrt(closestPointOnTriangle(pLocal, mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)).distanceSquared);
}

// Overlapping balls at random orientations, 0.8-0.95 apart (radius 0.5: always overlapping).
template <class Check>
void forOverlappingBalls(ContactModel model, std::uint64_t budget, Check check) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> gap(0.8, 0.95);
  QueryScratch scratch;
  QueryResult result;
  int contacts = 0;
  for (int i = 0; i < 20; ++i) {
    Pose xfA = randomPose(rng, 0.0);
    Pose xfB = randomPose(rng, 0.0);
    xfB.translation = gap(rng) * randomPose(rng, 1.0).translation.normalized();
    queryContacts(ball(), xfA, ball(), xfB, settingsFor(model, budget), scratch, result);
    for (const Contact& c : result.contacts) {
      check(c, xfA, xfB);
      ++contacts;
    }
  }
  // At least one contact per pose: the overlapping balls always touch, so no check was vacuous.
  EXPECT_GE(contacts, 20) << contactModelName(model);
}

TEST(FeatureIds, ExactContactsNameTrianglesThatContainTheirPoints) {
  const TriangleMesh& mesh = ball().mesh();
  // The ball is a convex polyhedron, so the exact model answers two balls with the vertices of
  // each inside the other (docs/narrow-phase.md, "exact"): such a contact's point on A
  // (contactPointOnA) lies on featureA and its point on B on featureB -- a vertex, and where its
  // normal line leaves the other ball. A patch without such vertices keeps its points on the
  // intersection curve, each on both triangles. All are computed from the triangles' planes: on
  // them to rounding (1e-9 of the unit ball's size).
  const double tol = 1e-9;
  int vertexContacts = 0;
  forOverlappingBalls(ContactModel::kExact, kUnlimitedTests, [&](const Contact& c, const Pose& xfA, const Pose& xfB) {
    ASSERT_EQ(c.featureKind, ContactFeature::kTriangle);
    ASSERT_LT(c.featureA, mesh.triangleCount());
    ASSERT_LT(c.featureB, mesh.triangleCount());
    const bool onCurve = distanceToTriangle(mesh, c.featureA, xfA.applyInverse(c.point)) < tol &&
                         distanceToTriangle(mesh, c.featureB, xfB.applyInverse(c.point)) < tol;
    const bool onSurfaces = distanceToTriangle(mesh, c.featureA, xfA.applyInverse(contactPointOnA(c))) < tol &&
                            distanceToTriangle(mesh, c.featureB, xfB.applyInverse(contactPointOnB(c))) < tol;
    EXPECT_TRUE(onCurve || onSurfaces) << c.point.transpose() << ", depth " << c.depth;
    vertexContacts += onSurfaces && !onCurve;
  });
  EXPECT_GT(vertexContacts, 20);  // most are vertices: the surface-point check ran
}

TEST(FeatureIds, SphereModelContactsNameSpheresThatHoldTheirPoint) {
  const SphereTree& tree = ball().sphereTree();
  for (ContactModel model : {ContactModel::kDos, ContactModel::kCfm}) {
    for (std::uint64_t budget : {std::uint64_t(8), kUnlimitedTests}) {
      forOverlappingBalls(model, budget, [&](const Contact& c, const Pose& xfA, const Pose& xfB) {
        ASSERT_EQ(c.featureKind, ContactFeature::kSphere) << contactModelName(model);
        ASSERT_LT(c.featureA, tree.sphereCount());
        ASSERT_LT(c.featureB, tree.sphereCount());
        // The D&O point lies in both spheres. A cfm point between faceted patches is a corner of
        // the overlap of the two patches' faces projected along the normal, on one face: within
        // the other sphere's reach by the contact's error bound (r_A + r_B) plus its depth.
        // 1e-9: rounding. Not for the exact face corners between convex bodies (error bound 0):
        // those lie on the bodies' faces the patches face along, which may reach beyond the
        // spheres (contact.h, ContactFeature::kSphere).
        if (model == ContactModel::kCfm && c.errorBound == 0.0) return;
        const double reach = std::abs(c.depth) + (model == ContactModel::kDos ? 0.0 : c.errorBound) + 1e-9;
        EXPECT_LE((xfA.applyInverse(c.point) - tree.center(c.featureA)).norm(), tree.radius[c.featureA] + reach)
            << contactModelName(model) << " budget " << budget;
        EXPECT_LE((xfB.applyInverse(c.point) - tree.center(c.featureB)).norm(), tree.radius[c.featureB] + reach)
            << contactModelName(model) << " budget " << budget;
      });
    }
  }
}

TEST(FeatureIds, ContactTreeContactsNameCellsOfBothTrees) {
  const ContactTree& tree = ball().contactTree();
  forOverlappingBalls(ContactModel::kContactTree, kUnlimitedTests, [&](const Contact& c, const Pose&, const Pose&) {
    ASSERT_EQ(c.featureKind, ContactFeature::kCell);
    EXPECT_LT(c.featureA, tree.nodeCount());
    EXPECT_LT(c.featureB, tree.nodeCount());
  });
}

// A unit cube B 0.1 into a unit cube A from above (A's top face at z = 0.5, B's bottom at 0.4):
// every contact's point on A lies on A's top face and its point on B on B's bottom face, 0.1
// apart along the normal -- for the exact model and cfm exactly (face clipping of two convex
// polyhedra, error bound 0). (Not the contact tree: its samples lie on one surface, contact.h.)
TEST(FeatureIds, BothPointsOfABoxInABoxLieOnTheTwoFaces) {
  const Pose xfA;  // identity
  Pose xfB;
  xfB.translation = Vec3(0.1, -0.05, 0.9);
  QueryScratch scratch;
  QueryResult result;
  for (ContactModel model : {ContactModel::kExact, ContactModel::kCfm}) {
    queryContacts(cube(), xfA, cube(), xfB, settingsFor(model, kUnlimitedTests), scratch, result);
    ASSERT_FALSE(result.contacts.empty()) << contactModelName(model);
    for (const Contact& c : result.contacts) {
      const double tol = 1e-9;  // rounding
      EXPECT_NEAR(contactPointOnA(c).z(), 0.5, tol) << contactModelName(model);
      EXPECT_NEAR(contactPointOnB(c).z(), 0.4, tol) << contactModelName(model);
      EXPECT_NEAR((contactPointOnA(c) - contactPointOnB(c)).dot(c.normal), -c.depth, 1e-12);
      EXPECT_NE(c.featureKind, ContactFeature::kNone) << contactModelName(model);
    }
  }
}

}  // namespace
}  // namespace clod
