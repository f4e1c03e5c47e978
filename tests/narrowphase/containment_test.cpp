// Containment: a closed body wholly inside another closed body has no surface pair that meets,
// yet it is the deepest penetration there is. Every model, at every budget, must push the inner
// body out toward the outer surface nearest it. Oracles: analytic (a small icosphere or box at a
// known offset inside a big box or icosphere: nearest face and distance in closed form), and
// MeshDistance (the proximity layer, no narrow-phase code) for the shared closed meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "clod/mesh_topology.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/query.h"
#include "narrowphase/containment.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::settingsFor;

constexpr double kDegree = 3.14159265358979323846 / 180.0;
const std::vector<std::uint64_t> kBudgets = {1, 16, 256, kUnlimitedTests};

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Bodies {
  // Outer bodies: a box of half extent 1 (diagonal 3.46) and an icosphere of radius 1.
  CollisionBody bigBox = test::makeTestBody(makeBox(Vec3::Constant(1.0)), 2);
  CollisionBody bigSphere = test::makeTestBody(makeIcosphere(1.0, 4), 2);
  // Inner bodies: an icosphere of radius 0.1 and a 0.2 x 0.3 x 0.4 box.
  CollisionBody smallSphere = test::makeTestBody(makeIcosphere(0.1, 2), 2);
  CollisionBody smallBox = test::makeTestBody(makeBox(Vec3(0.1, 0.15, 0.2)), 2);
};

const Bodies& bodies() {
  static const Bodies b;
  return b;
}

// One containment case: `inner` at `offset` from the outer body's centre (the outer body at the
// origin, unrotated); `exitDir` the unit direction toward the nearest outer surface, `distance`
// the analytic distance from the inner body's centre to it.
struct Case {
  std::string name;
  const CollisionBody* outer;
  const CollisionBody* inner;
  Pose innerPose;
  Vec3 exitDir;
  double distance;
};

// Checks every model at every budget, both body orders. Normal: from B toward A, so with the
// inner body as A it is exitDir, as B it is -exitDir. Tolerances: the normal is the outer
// field's gradient at the inner body's centre, exact (0 deg) from the sphere-tree and within the
// contact tree's gradient error (2e-3 x diagonal field error over cells of >= 1/128 of the root
// cube: well under 1 deg away from edges) -- 3 deg is a few degrees, as the issue asks; the
// sphere models' own contacts at small budgets (when the frontier is not empty) are checked by
// their resultant. Depth: the deepest contact reaches the analytic distance less its bound.
void checkCase(const Case& c, double angleTol, double distanceTolRel) {
  for (bool innerIsA : {true, false}) {
    const CollisionBody& a = innerIsA ? *c.inner : *c.outer;
    const CollisionBody& b = innerIsA ? *c.outer : *c.inner;
    const Pose poseA = innerIsA ? c.innerPose : Pose{};
    const Pose poseB = innerIsA ? Pose{} : c.innerPose;
    const Vec3 expected = innerIsA ? c.exitDir : Vec3(-c.exitDir);
    for (ContactModel model : allContactModels()) {
      for (std::uint64_t budget : kBudgets) {
        const std::string what = c.name + (innerIsA ? " inner=A " : " inner=B ") +
                                 std::string(contactModelName(model)) + " budget " + std::to_string(budget);
        const QueryResult r = queryContacts(a, poseA, b, poseB, settingsFor(model, budget));
        ASSERT_TRUE(r.colliding) << what;
        ASSERT_GE(r.contacts.size(), 1u) << what;
        EXPECT_LE(r.tests, budget) << what;
        Vec3 resultant = Vec3::Zero();
        double deepest = -1e300, deepestBound = 0.0;
        for (const Contact& ct : r.contacts) {
          resultant += std::max(ct.depth, 1e-12) * ct.normal;
          if (ct.depth > deepest) {
            deepest = ct.depth;
            deepestBound = ct.errorBound;
          }
        }
        EXPECT_LT(angleBetween(resultant, expected), angleTol) << what << ": resultant " << resultant.transpose();
        const double tol = distanceTolRel * c.outer->diagonal();
        EXPECT_GE(deepest, c.distance - deepestBound - tol) << what;
      }
    }
  }
}

TEST(Containment, SmallSphereInsideABigBoxIsPushedTowardTheNearestFace) {
  const Bodies& b = bodies();
  std::vector<Case> cases;
  // Offsets along +x, -y and +z, far enough from the centre that one face is nearest for the
  // whole inner body (offset > its radius), and near a face (0.8: 0.1 from the face).
  for (double d : {0.3, 0.6, 0.8}) {
    cases.push_back({"sphere in box +x " + std::to_string(d), &b.bigBox, &b.smallSphere,
                     Pose{Quat::Identity(), Vec3(d, 0.05, -0.02)}, Vec3::UnitX(), 1.0 - d});
  }
  cases.push_back({"sphere in box -y", &b.bigBox, &b.smallSphere, Pose{Quat::Identity(), Vec3(0.1, -0.5, 0.0)},
                   -Vec3::UnitY(), 0.5});
  cases.push_back({"sphere in box +z", &b.bigBox, &b.smallSphere, Pose{Quat::Identity(), Vec3(0.0, 0.2, 0.7)},
                   Vec3::UnitZ(), 0.3});
  // Tolerances: angle 3 deg (see checkCase); distance: the box is exact, 1e-9 x diagonal is rounding.
  for (const Case& c : cases) checkCase(c, 3.0 * kDegree, 1e-9);
}

TEST(Containment, BoxInsideABigBoxIsPushedTowardTheNearestFace) {
  const Bodies& b = bodies();
  const Quat turned(Eigen::AngleAxisd(0.4, Vec3(1.0, 2.0, 3.0).normalized()));
  std::vector<Case> cases;
  cases.push_back({"box in box +x", &b.bigBox, &b.smallBox, Pose{Quat::Identity(), Vec3(0.5, 0.0, 0.1)},
                   Vec3::UnitX(), 0.5});
  cases.push_back({"turned box in box -z", &b.bigBox, &b.smallBox, Pose{turned, Vec3(0.1, -0.1, -0.55)},
                   -Vec3::UnitZ(), 0.45});
  for (const Case& c : cases) checkCase(c, 3.0 * kDegree, 1e-9);
}

TEST(Containment, SmallSphereInsideABigSphereIsPushedOutAlongTheRadius) {
  const Bodies& b = bodies();
  std::vector<Case> cases;
  for (const Vec3& dir : {Vec3(1.0, 0.0, 0.0), Vec3(0.3, -0.5, 0.8).normalized(), Vec3(-0.6, 0.7, -0.2).normalized()}) {
    for (double d : {0.4, 0.7}) {
      cases.push_back({"sphere in sphere " + std::to_string(d), &b.bigSphere, &b.smallSphere,
                       Pose{Quat::Identity(), Vec3(d * dir)}, dir, 1.0 - d});
    }
  }
  // The outer icosphere (4 subdivisions, 5,120 triangles) is inscribed in the unit sphere. The
  // gradient inside it is the normal of the nearest face, which is off the radius through the
  // point by at most the face's angular circumradius: edges of ~ 63.4 deg / 16 ~ 4 deg, so about
  // 4 / sqrt(3) ~ 2.3 deg (measured max below 3 deg); tolerance 4 deg. Distance: the faces lie up
  // to 1 - cos(2.3 deg) ~ 0.0008 inside the sphere; 0.001 / diagonal 2 = 5e-4.
  for (const Case& c : cases) checkCase(c, 4.0 * kDegree, 5e-4);
}

TEST(Containment, BodiesApartOrTouchingOnlyGetTheirOwnContacts) {
  const Bodies& b = bodies();
  for (ContactModel model : allContactModels()) {
    for (std::uint64_t budget : kBudgets) {
      const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget);
      // Root spheres apart: no contact, no work beyond the root test.
      QueryResult r = queryContacts(b.smallSphere, Pose{Quat::Identity(), Vec3(5.0, 0.0, 0.0)}, b.bigBox, Pose{},
                                    settingsFor(model, budget));
      EXPECT_FALSE(r.colliding) << what;
      EXPECT_TRUE(r.contacts.empty()) << what;
      EXPECT_EQ(r.tests, 1u) << what;
      // Root spheres overlap (the box's root sphere has radius sqrt 3), the bodies are apart
      // (0.05 gap beside the +x face): the seed's field query says outside, no contact. (dos and
      // average keep their loose leaf spheres' contacts there, as before: not checked.)
      if (model == ContactModel::kDos || model == ContactModel::kAverage) continue;
      r = queryContacts(b.smallSphere, Pose{Quat::Identity(), Vec3(1.15, 0.0, 0.0)}, b.bigBox, Pose{},
                        settingsFor(model, kUnlimitedTests));
      EXPECT_FALSE(r.colliding) << what;
      EXPECT_TRUE(r.contacts.empty()) << what;
    }
  }
}

TEST(Containment, AnOpenMeshHasNoInside) {
  // bunny-1500 is open (71 boundary edges, data README): a small sphere inside it gets no
  // containment contacts; only closed meshes have an inside.
  const TriangleMesh bunny = test::loadUnitMesh("bunny-1500.obj");
  ASSERT_FALSE(MeshTopology(bunny).closed());
  const CollisionBody outer = test::makeTestBody(bunny, 2, false, true);
  const MeshDistance oracle(bunny);
  // A point deep inside (winding number), found by a coarse grid search.
  Vec3 inside = Vec3::Zero();
  double best = 0.0;
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j)
      for (int k = -4; k <= 4; ++k) {
        const Vec3 p(0.06 * i, 0.06 * j, 0.06 * k);
        const double sd = oracle.signedDistance(p);
        if (sd < best) {
          best = sd;
          inside = p;
        }
      }
  ASSERT_LT(best, -0.03);
  const CollisionBody inner = test::makeTestBody(makeIcosphere(0.01, 1), 1, false, true);
  for (ContactModel model : {ContactModel::kDos, ContactModel::kCfm, ContactModel::kExact}) {
    const QueryResult r = queryContacts(inner, Pose{Quat::Identity(), inside}, outer, Pose{},
                                        settingsFor(model, kUnlimitedTests));
    EXPECT_TRUE(r.contacts.empty()) << contactModelName(model);
  }
}

TEST(Containment, ExactFieldThroughTheTriangleBvhMatchesMeshDistance) {
  // The containment field (a best-first search of the body's triangle BVH, signed by the closest
  // feature's pseudonormal) against the proximity layer's exact signed distance, at random points
  // around closed meshes: boxes, an icosphere and spot (5,856 triangles, non-convex). Searched
  // within a radius, it answers exactly where the surface lies within it.
  const Bodies& b = bodies();
  static const CollisionBody spot = test::makeTestBody(test::loadUnitMesh("spot.obj"), 1, false, false);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.4, 1.4), radius(0.0, 0.5);
  detail::ContainmentScratch scratch;
  for (const CollisionBody* body : {&b.bigBox, &b.bigSphere, &b.smallBox, &spot}) {
    const MeshDistance oracle(body->mesh());
    for (int i = 0; i < 300; ++i) {
      const Vec3 p(u(rng), u(rng), u(rng));
      const detail::FieldValue f = detail::exactBodyField(*body, p, scratch);
      const double expected = oracle.signedDistance(p);
      // Exact in double precision: both take the minimum of closestPointOnTriangle.
      EXPECT_NEAR(f.distance, expected, 1e-12 * body->diagonal()) << p.transpose();
      EXPECT_NEAR(f.gradient.norm(), 1.0, 1e-9);
      const double r = radius(rng) * body->diagonal();
      if (std::abs(std::abs(expected) - r) <= 1e-9 * body->diagonal()) continue;  // a tie at the radius
      detail::FieldValue within;
      EXPECT_EQ(detail::exactBodyFieldWithin(*body, p, r, scratch, within), std::abs(expected) < r) << p.transpose();
      if (std::abs(expected) < r) {
        EXPECT_NEAR(within.distance, expected, 1e-12 * body->diagonal());
      }
    }
  }
}

TEST(Containment, SmallSpotInsideSpotIsPushedTowardTheNearestSurface) {
  // Shared meshes: spot is closed (data README; checked here), a copy scaled to 4 % sits inside
  // it, 0.05 diagonals below a face, where the nearest surface point of every point of the small
  // copy is on that face's plane neighbourhood. Oracle: MeshDistance (closest point, sign).
  const TriangleMesh spot = test::loadUnitMesh("spot.obj");
  ASSERT_TRUE(MeshTopology(spot).closed());
  TriangleMesh small = spot;
  for (Vec3& v : small.vertices) v *= 0.04;
  const CollisionBody outer = test::makeTestBody(spot, test::curvedMeshTestDepth());
  const CollisionBody inner = test::makeTestBody(small, 1);
  const MeshDistance oracle(spot);
  // A point 0.05 behind a triangle's centroid whose closest surface point is that centroid, and
  // from which the surface is farther than the small copy's extent (radius 0.02) all round.
  const double depth = 0.05;
  Vec3 centre = Vec3::Zero(), exitDir = Vec3::UnitX();
  bool found = false;
  for (std::uint32_t t = 0; t < spot.triangleCount() && !found; t += 7) {
    const Vec3 q = (spot.corner(t, 0) + spot.corner(t, 1) + spot.corner(t, 2)) / 3.0;
    const Vec3 n = spot.triangleNormal(t);
    const Vec3 p = q - depth * n;
    const MeshDistance::Signed s = oracle.signedQuery(p);
    if (std::abs(s.signedDistance + depth) > 1e-9) continue;  // another part of the surface is nearer
    found = true;
    centre = p;
    exitDir = n;
  }
  ASSERT_TRUE(found);
  const Case c{"small spot in spot", &outer, &inner, Pose{Quat::Identity(), centre}, exitDir, depth};
  // Angle: the outer gradient at the small copy's root-sphere centre (within 0.02 of `centre`)
  // may see a neighbouring face as nearest where spot bends: 8 deg covers the curvature of a
  // unit-diagonal cow over 0.02 at 0.05 depth (measured max 2.4 deg). Distance: contact-tree
  // field error 2e-3 x diagonal, plus 1e-3 margin.
  checkCase(c, 8.0 * kDegree, 3e-3);
}

}  // namespace
}  // namespace clod
