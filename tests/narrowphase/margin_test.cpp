// QuerySettings::marginAbs: bodies apart by at most the margin get one speculative contact at
// their closest points, in every model. Oracles are analytic: two boxes with parallel faces a
// known gap apart, a box turned so that one edge comes lowest, and convex or curved meshes over a
// box's top face, whose closest point to that plane is their lowest vertex (a brute-force minimum
// over the vertices, no narrow-phase or distance-query code).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string_view>
#include <vector>

#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::settingsFor;

const ContactModel kModels[] = {ContactModel::kCfm, ContactModel::kContactTree, ContactModel::kExact};
const std::uint64_t kBudgets[] = {16, kUnlimitedTests};

// A = a box of half extents (2, 2, 0.5), its top face at z = 0.5. The bodies above it have
// diagonals of about 1 to 1.7, so the gaps below (1e-2) are ~1 % of a diagonal.
const CollisionBody& ground() {
  static const CollisionBody body = test::makeTestBody(makeBox(Vec3(2.0, 2.0, 0.5)), 2);
  return body;
}

// The speculative contact of one query, checked against the analytic gap and normal: no contact
// penetrates beyond its error bound (the contact tree may report a sample within its field error
// of touching), exactly one is speculative with error bound 0, at depth -gap, normal -z (B lies
// above A; normals point from B toward A), its point midway between the top face and B's lowest
// point.
// Tolerance: 1e-9 of the ~1 m bodies -- the closest points are exact in double precision up to
// the rounding of the poses (~1e-16 relative).
void expectSpeculativeContact(const QueryResult& r, double gap, double pointZ, std::string_view what) {
  SCOPED_TRACE(what);
  const Contact* speculative = nullptr;
  std::size_t count = 0;
  for (const Contact& c : r.contacts) {
    EXPECT_LE(c.depth - c.errorBound, 0.0) << "a contact certainly penetrates bodies that are apart";
    if (c.depth < 0.0 && c.errorBound == 0.0) {
      speculative = &c;
      ++count;
    }
  }
  ASSERT_EQ(count, 1u);
  const Contact& c = *speculative;
  EXPECT_NEAR(c.depth, -gap, 1e-9);
  EXPECT_NEAR(c.normal.z(), -1.0, 1e-9);
  EXPECT_NEAR(c.point.z(), pointZ, 1e-9);
  EXPECT_EQ(c.featureKind, ContactFeature::kTriangle);
  // The contact's two points are the closest points: on A's top face and at B's lowest height.
  EXPECT_NEAR(contactPointOnA(c).z(), pointZ - gap / 2, 1e-9);
  EXPECT_NEAR(contactPointOnB(c).z(), pointZ + gap / 2, 1e-9);
}

// Body B at poseB over the ground, queried with a margin.
QueryResult queryOverGround(const CollisionBody& b, const Pose& poseB, ContactModel model, std::uint64_t budget,
                            double margin) {
  QuerySettings s = settingsFor(model, budget);
  s.marginAbs = margin;
  return queryContacts(ground(), Pose{}, b, poseB, s);
}

TEST(ContactMargin, ParallelFacesAGapApartGetTheirGapInEveryModel) {
  const CollisionBody cube = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
  const double gap = 0.01;
  const Pose poseB{Quat::Identity(), Vec3(0.3, -0.2, 0.5 + gap + 0.5)};
  for (ContactModel model : kModels) {
    for (std::uint64_t budget : kBudgets) {
      const QueryResult r = queryOverGround(cube, poseB, model, budget, 0.02);
      expectSpeculativeContact(r, gap, 0.5 + gap / 2, contactModelName(model));
      EXPECT_FALSE(r.colliding);
      // The closest points of two parallel faces: anywhere in their overlap, |x - 0.3| and
      // |y + 0.2| <= 0.5 (B's bottom face).
      EXPECT_LE(std::abs(r.contacts.front().point.x() - 0.3), 0.5 + 1e-9);
      EXPECT_LE(std::abs(r.contacts.front().point.y() + 0.2), 0.5 + 1e-9);
      // A margin below the gap: no contact at all.
      EXPECT_TRUE(queryOverGround(cube, poseB, model, budget, 0.009).contacts.empty()) << contactModelName(model);
    }
  }
}

// B turned 45 deg about x: its lowest feature is an edge along x, 0.5 sqrt 2 below its centre.
TEST(ContactMargin, EdgeOverAFaceGetsTheEdgesGapInEveryModel) {
  const CollisionBody cube = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
  const double gap = 0.004;
  const Pose poseB{Quat(Eigen::AngleAxisd(std::acos(-1.0) / 4, Vec3::UnitX())),
                   Vec3(0.0, 0.1, 0.5 + gap + 0.5 * std::sqrt(2.0))};
  for (ContactModel model : kModels) {
    for (std::uint64_t budget : kBudgets) {
      const QueryResult r = queryOverGround(cube, poseB, model, budget, 0.01);
      expectSpeculativeContact(r, gap, 0.5 + gap / 2, contactModelName(model));
      EXPECT_FALSE(r.colliding);
      EXPECT_NEAR(r.contacts.front().point.y(), 0.1, 1e-9);  // under the edge
    }
  }
}

// Convex and curved meshes at random turns, their lowest vertex `gap` above the top face: the
// gap is exact (a polyhedron's closest point to a plane is a vertex), and the contact's point on
// B is a lowest vertex's height.
TEST(ContactMargin, CurvedMeshesOverAFaceGetTheirLowestVertexGap) {
  const std::vector<CollisionBody> shapes = {test::makeTestBody(makeIcosphere(0.5, 2), 2),
                                             test::makeTestBody(test::loadUnitMesh("bunny-1500.obj"), 2)};
  std::mt19937_64 rng(7);
  for (const CollisionBody& shape : shapes) {
    for (int trial = 0; trial < 3; ++trial) {
      Pose poseB = test::randomPose(rng, 0.3);
      double lowest = std::numeric_limits<double>::infinity();
      for (const Vec3& v : shape.mesh().vertices) lowest = std::min(lowest, poseB.apply(v).z());
      const double gap = 0.002 + 0.004 * trial;
      poseB.translation.z() += 0.5 + gap - lowest;
      for (ContactModel model : kModels) {
        for (std::uint64_t budget : kBudgets) {
          const QueryResult r = queryOverGround(shape, poseB, model, budget, 0.02);
          expectSpeculativeContact(r, gap, 0.5 + gap / 2, contactModelName(model));
        }
      }
    }
  }
}

// Penetrating bodies keep the model's answer as it is: no speculative contact is added.
TEST(ContactMargin, PenetratingBodiesGetTheModelsAnswerUnchanged) {
  const CollisionBody cube = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
  const Pose poseB{Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ())), Vec3(0.1, 0.0, 0.99)};
  for (ContactModel model : kModels) {
    const QueryResult plain = queryOverGround(cube, poseB, model, kUnlimitedTests, 0.0);
    const QueryResult withMargin = queryOverGround(cube, poseB, model, kUnlimitedTests, 0.05);
    ASSERT_FALSE(plain.contacts.empty());
    ASSERT_EQ(withMargin.contacts.size(), plain.contacts.size()) << contactModelName(model);
    for (std::size_t i = 0; i < plain.contacts.size(); ++i) {
      EXPECT_GT(withMargin.contacts[i].depth, 0.0);
      EXPECT_EQ(withMargin.contacts[i].point, plain.contacts[i].point);
    }
  }
}

TEST(ContactMargin, NegativeOrNonFiniteMarginIsRefused) {
  const CollisionBody cube = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 1, false, false);
  for (double margin : {-1e-3, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    QuerySettings s = settingsFor(ContactModel::kExact, kUnlimitedTests);
    s.marginAbs = margin;
    try {
      queryContacts(cube, Pose{}, cube, Pose{Quat::Identity(), Vec3(0, 0, 2)}, s);
      ADD_FAILURE() << "margin " << margin << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    }
  }
}

}  // namespace
}  // namespace clod
