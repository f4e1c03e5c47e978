// Proven apart (QueryResult::separation, proveApart, docs/dynamics.md "Proven apart"): a gap the
// narrow phase proves from its bounding spheres must never exceed the surfaces' true distance, or
// the world would skip a pair that touches. Oracle: brute force over every triangle pair
// (detail::triangleDistance, itself tested against analytic gaps in world_separation_test.cpp).
// And the world built on it: a ball rolling at a bar skips the substeps in which its gap is
// proven, and still stops at the bar.
#include <cmath>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "clod/primitives.h"
#include "clod/query.h"
#include "clod/world.h"
#include "narrowphase/separation.h"
#include "dynamics/world_test_support.h"
#include "support/test_scale.h"

namespace clod {
namespace {

// Random poses of B around A, from touching-close to a body's size apart, turned at random: every
// model at 16, 256 tests and unlimited, and proveApart with 64 and 4,096 tests. Whenever a gap is
// claimed it is at most the brute-force distance (rounding: 1e-9 of the diagonal). Not vacuous:
// proofs must occur (counted), also between surfaces closer than a tenth of a diagonal.
TEST(ProvenApart, AClaimedGapIsNeverMoreThanTheSurfacesDistance) {
  const auto ball = test::bakeWorldShape(makeIcosphere(0.5, 2));
  const auto box = test::bakeWorldShape(makeBox(Vec3(0.6, 0.3, 0.4)));
  const std::shared_ptr<const CollisionBody> shapes[] = {ball, box};
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  QueryScratch scratch;
  QueryResult result;
  int claims = 0, closeClaims = 0;
  const int poses = test::sanitizerRun() ? 8 : 60;
  for (int k = 0; k < poses; ++k) {
    const CollisionBody& a = *shapes[k % 2];
    const CollisionBody& b = *shapes[(k / 2) % 2];
    const Vec3 axis = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Quat turn(Eigen::AngleAxisd(M_PI * unit(rng), Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized()));
    // Centre distance from 1.0 (the bodies overlap) to 2.2 (a size apart).
    const Pose poseB{turn, (1.0 + 1.2 * unit(rng)) * axis};
    const double truth = test::bruteForceSurfaceDistance(a.mesh(), Pose{}, b.mesh(), poseB);
    const double rounding = 1e-9 * std::max(a.diagonal(), b.diagonal());
    auto check = [&](double claimed, const std::string& what) {
      if (claimed <= 0.0) return;
      ++claims;
      if (truth < 0.1 * a.diagonal()) ++closeClaims;
      EXPECT_LE(claimed, truth + rounding) << what << " at pose " << k;
    };
    for (ContactModel model : {ContactModel::kDos, ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree})
      for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(256), std::uint64_t(0)}) {
        QuerySettings qs;
        qs.model = model;
        qs.budget = budget == 0 ? QueryBudget::unlimited() : QueryBudget::tests(budget);
        queryContacts(a, Pose{}, b, poseB, qs, scratch, result);
        if (result.separation > 0.0) {
          EXPECT_TRUE(result.contacts.empty()) << contactModelName(model);
        }
        check(result.separation, std::string(contactModelName(model)) + " at " + std::to_string(budget));
      }
    for (std::uint64_t tests : {std::uint64_t(64), std::uint64_t(4096)})
      check(proveApart(a, Pose{}, b, poseB, tests, scratch), "proveApart with " + std::to_string(tests));
  }
  EXPECT_GT(claims, poses) << "too few gaps proven: the test would prove nothing";
  EXPECT_GT(closeClaims, 0) << "no gap proven closer than a tenth of a diagonal";
}

// A body wholly inside another has apart surfaces and the deepest overlap there is: no gap.
TEST(ProvenApart, ABodyInsideAnotherIsNotApart) {
  const auto big = test::bakeWorldShape(makeBox(Vec3(2.0, 2.0, 2.0)));
  const auto ball = test::bakeWorldShape(makeIcosphere(0.3, 2));
  QueryScratch scratch;
  EXPECT_EQ(proveApart(*big, Pose{}, *ball, Pose{Quat::Identity(), Vec3(0.2, -0.1, 0.3)}, 4096, scratch), 0.0);
  EXPECT_EQ(proveApart(*ball, Pose{Quat::Identity(), Vec3(0.2, -0.1, 0.3)}, *big, Pose{}, 4096, scratch), 0.0);
  // Control: beside the box it is proven apart.
  EXPECT_GT(proveApart(*big, Pose{}, *ball, Pose{Quat::Identity(), Vec3(3.0, 0.0, 0.0)}, 4096, scratch), 0.0);
}

// A ball rolling on a slab toward a static bar that lies turned 45 deg across its path: the ball
// is inside the bar's bounding box long before it reaches the bar, so the broad phase pairs them;
// with the exact model at an unlimited budget the pair's queries prove the gap, and the substeps in which the
// ball cannot have closed it are skipped (no query). It still meets the bar and stops at it.
// Oracle: the bar's face, 0.1 from its axis, and the ball's radius: its centre never comes nearer
// the bar's axis than 0.1 + r less 1 % of its diagonal (issue 17's sink allowance; the icosphere
// of 320 faces lies within 2 % inside its sphere).
TEST(ProvenApart, ABallRollingAtABarSkipsProvenSubstepsAndStillStopsAtIt) {
  constexpr double kRadius = 0.2;
  const auto slab = test::bakeWorldShape(makeBox(Vec3(2.0, 2.0, 0.25)));
  const auto bar = test::bakeWorldShape(makeBox(Vec3(1.0, 0.1, 0.1)));
  const auto ball = test::bakeWorldShape(makeIcosphere(kRadius, 2));
  WorldSettings ws;
  ws.model = ContactModel::kExact;
  World world(ws);
  auto addStatic = [&](const std::shared_ptr<const CollisionBody>& shape, const Vec3& at, const Quat& q) {
    RigidBodyDesc d;
    d.shape = shape;
    d.type = BodyType::kStatic;
    d.position = at;
    d.orientation = q;
    world.addBody(d);
  };
  addStatic(slab, Vec3(0.0, 0.0, -0.25), Quat::Identity());
  addStatic(bar, Vec3(0.0, 0.0, 0.1), Quat(Eigen::AngleAxisd(M_PI / 4.0, Vec3::UnitZ())));  // along y = x
  const Vec3 towardBar = Vec3(-1.0, 1.0, 0.0).normalized();
  RigidBodyDesc d;
  d.shape = ball;
  d.mass = 1.0;
  d.inertia = Mat3::Identity() * (0.4 * kRadius * kRadius);
  d.position = Vec3(0.5, -0.5, kRadius);  // 0.71 from the bar's axis, inside its box (|x|, |y| < 0.78)
  d.velocity = 1.0 * towardBar;
  d.angularVelocity = Vec3::UnitZ().cross(towardBar) * (1.0 / kRadius);  // rolling
  const BodyId id = world.addBody(d);
  std::uint64_t proven = 0;
  double nearest = INFINITY;
  for (int i = 0; i < 120; ++i) {
    proven += world.step(1.0 / 60.0).pairsProvenApart;
    const Vec3 c = world.state(id).position;
    nearest = std::min(nearest, std::abs(c.y() - c.x()) / std::sqrt(2.0));  // from the axis y = x
  }
  EXPECT_GT(proven, 0u) << "no substep was proven apart: the test would prove nothing";
  EXPECT_GT(nearest, 0.1 + 0.98 * kRadius - 0.01 * ball->diagonal());
  EXPECT_LT(nearest, 0.1 + kRadius + 0.05) << "the ball never reached the bar";
}

}  // namespace
}  // namespace clod
