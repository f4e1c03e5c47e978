// The exact model's contact normal against an independent reference: the gradient of the two
// bodies' intersection volume (tests/support/overlap_reference.h), computed from MeshDistance's
// inside/outside tests by surface quadrature, sharing no code with the narrow phase. The reference
// itself is first checked against an analytic box-on-box overlap.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"
#include "support/overlap_reference.h"

namespace clod {
namespace {

constexpr double kRadiansToDegrees = 180.0 / 3.14159265358979323846;

double angleDegrees(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadiansToDegrees; }

TEST(VolumeReference, MatchesAnAnalyticBoxOnBoxOverlap) {
  // A: half extents (1, 1, 1). B: half extents (0.5, 0.4, 0.3), centred above A's top face so
  // that its bottom face sinks d = 0.05 into A, its footprint x in [-0.3, 0.7], y in [-0.5, 0.3]
  // well inside A's top. Inside the other body: B's bottom face (area 0.8, normal -z), B's four
  // side walls over height d (opposite normals cancel), A's top face under B (area 0.8, normal
  // +z). So dV/dt = (0, 0, -0.8) from either side, the normal from B to A is -z, the pieces' area
  // is 1.6 + 3.6 d, and the deepest point is d deep. The whole scene is moved by a random rigid
  // motion so no cut falls on a subdivision midpoint by symmetry.
  constexpr double d = 0.05;
  const MeshDistance a(makeBox(Vec3(1.0, 1.0, 1.0)));
  const MeshDistance b(makeBox(Vec3(0.5, 0.4, 0.3)));
  std::mt19937_64 rng(17);
  const int trials = test::sanitizerRun() ? 1 : 3;
  for (int trial = 0; trial < trials; ++trial) {
    const Pose world = test::randomPose(rng, 1.0);
    Pose offset;
    offset.translation = Vec3(0.2, -0.1, 1.0 + 0.3 - d);
    constexpr double kLeafRadius = 1e-3;
    const test::OverlapReference r = test::overlapReference(a, world, b, world * offset, kLeafRadius);

    // Quadrature error: only leaves cut by the other surface can be misjudged; they lie along
    // the cut curves (B's walls crossing A's top: length 2 (1.0 + 0.8) = 3.6; A's top crossing
    // B's walls: the footprint's perimeter, 3.6 again), each at most 2 kLeafRadius wide, so the
    // area is off by at most 2 * 3.6 * 2 kLeafRadius; the same bound applies to any component of
    // either gradient.
    const double areaBound = 2.0 * 3.6 * 2.0 * kLeafRadius;
    EXPECT_NEAR(r.area, 1.6 + 3.6 * d, areaBound) << "trial " << trial;
    const Vec3 down = world.rotation * Vec3(0.0, 0.0, -1.0);
    EXPECT_NEAR((r.gradientB - 0.8 * down).norm(), 0.0, areaBound) << "trial " << trial;
    EXPECT_NEAR((r.gradientA + 0.8 * down).norm(), 0.0, areaBound) << "trial " << trial;
    // Angle of a vector of length 1.6 tilted by at most 2 areaBound: asin(2 areaBound / 1.6).
    EXPECT_LT(angleDegrees(r.normal(), down), std::asin(2.0 * areaBound / 1.6) * kRadiansToDegrees) << "trial " << trial;
    // Centroid: pieces at heights 1 - d (B's bottom), 1 (A's top), 1 - d/2 (walls), in the
    // offset's frame; x and y at the footprint's centre (0.2, -0.1) by symmetry of each pair.
    const double z = (0.8 * (1.0 - d) + 0.8 * 1.0 + 3.6 * d * (1.0 - 0.5 * d)) / (1.6 + 3.6 * d);
    // Moving a leaf's worth of area (areaBound in all) by at most the pieces' extent (~1.3) moves
    // the centroid by at most areaBound * 1.3 / area.
    EXPECT_NEAR((r.centroid - world.apply(Vec3(0.2, -0.1, z))).norm(), 0.0, areaBound * 1.3 / 1.6) << "trial " << trial;
    // Corners and centroids of B's bottom face are sampled: exactly d deep up to rounding.
    EXPECT_NEAR(r.depth, d, 1e-9) << "trial " << trial;
  }
}

TEST(VolumeReference, SeparatedBodiesHaveNoOverlap) {
  const MeshDistance a(makeBox(Vec3(1.0, 1.0, 1.0)));
  Pose far;
  far.translation = Vec3(0.0, 0.0, 2.01);
  const test::OverlapReference r = test::overlapReference(a, Pose{}, a, far, 1e-3);
  EXPECT_EQ(r.area, 0.0);
  EXPECT_EQ(r.normal(), Vec3::Zero());
}

// Largest t in [0, 2] at which the exact model still reports an intersection with B moved by t
// along `dir` (bisection). Only generates touching poses; the normals are judged by the reference.
double touchingDistance(const CollisionBody& body, const Quat& rotation, const Vec3& dir) {
  QuerySettings settings;
  settings.model = ContactModel::kExact;
  double lo = 0.0, hi = 2.0;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    const Pose pb{rotation, mid * dir};
    (queryContacts(body, Pose{}, body, pb, settings).colliding ? lo : hi) = mid;
  }
  return lo;
}

TEST(VolumeReference, ExactModelNormalFollowsTheVolumeGradientOnTheBunny) {
  // bunny-1500 against itself, scaled to unit diagonal: random orientation and direction, moved
  // to touching and then 0.005 deeper (the accuracy harness's poses).
  const TriangleMesh bunny = test::loadUnitMesh("bunny-1500.obj");
  const CollisionBody body = test::makeTestBody(bunny, 3, false, false);
  const MeshDistance distance(bunny);
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Under the sanitizers 5 of the 12 poses: with 3 the median was the middle one of three
  // single-pose errors (1.3, 2.7 and 2.2 deg), and a change of which 8 contacts the manifold
  // keeps moved it across the bound while the 12-pose median went down (1.52 -> 1.35 deg).
  const int poses = test::sanitizerRun() ? 5 : 12;
  std::vector<double> errors;
  for (int k = 0; k < poses; ++k) {
    const Quat rotation = Quat(u(rng), u(rng), u(rng), u(rng)).normalized();
    const Vec3 dir = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Pose pb{rotation, (touchingDistance(body, rotation, dir) - 0.005) * dir};
    QuerySettings settings;
    settings.model = ContactModel::kExact;
    const QueryResult exact = queryContacts(body, Pose{}, body, pb, settings);
    ASSERT_TRUE(exact.finished);
    ASSERT_FALSE(exact.contacts.empty()) << "pose " << k;
    Vec3 resultant = Vec3::Zero();
    for (const Contact& c : exact.contacts) resultant += std::max(c.depth, 1e-12) * c.normal;

    // Leaf radius 1e-3 of the diagonal: 1/5 of the 0.005 overlap. The reference's own accuracy is
    // the angle between its two surface integrals (equal for a closed mesh); the bunny is open
    // only at its base, and at this resolution they agreed to 0.06 deg median, 0.34 deg p95 on
    // the harness's poses. 1 degree here means the reference cannot judge this pose.
    const test::OverlapReference reference = test::overlapReference(distance, Pose{}, distance, pb, 1e-3);
    ASSERT_GT(reference.area, 0.0) << "pose " << k;
    EXPECT_LT(reference.selfConsistencyDegrees(), 1.0) << "pose " << k;
    errors.push_back(angleDegrees(resultant, reference.normal()));
  }
  std::sort(errors.begin(), errors.end());
  // The exact model reports at most 8 contacts, its patches' depth-weighted normals, not the full
  // surface integral: on the harness's 300 poses that summary was 0.88 deg off the reference
  // (median) and 5.4 deg at p95 (docs/benchmarks/narrowphase.md). A median over these poses under
  // 2 deg and no pose over 20 deg leave room for the few poses' spread while failing any
  // systematic error (a sign, a misweighted patch normal: FCL's per-triangle-pair normals are
  // 4.2 deg off at the median).
  EXPECT_LT(errors[errors.size() / 2], 2.0);
  EXPECT_LT(errors.back(), 20.0);
}

}  // namespace
}  // namespace clod
