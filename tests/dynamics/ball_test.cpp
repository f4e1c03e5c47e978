// Balls (RigidBodyDesc::ballRadius, docs/dynamics.md "Balls") against analytic answers: the hull
// encloses the ball, a ball rolls down a slope at 5/7 g sin(theta) and on the flat without
// losing speed, rests at its radius, and two balls meet along their centre line.
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/mass_properties.h"
#include "clod/primitives.h"
#include "clod/world.h"
#include "support/test_scale.h"
#include "world_test_support.h"

namespace clod {
namespace {

using test::sanitizerRun;

constexpr double kGravity = 9.81;

RigidBodyDesc ballDesc(const std::shared_ptr<const CollisionBody>& hull, double radius) {
  const MassProperties mp = ballMassProperties(radius, 1000.0);
  RigidBodyDesc d;
  d.shape = hull;
  d.ballRadius = radius;
  d.mass = mp.mass;
  d.inertia = mp.inertia;
  return d;
}

RigidBodyDesc staticSlab(const std::shared_ptr<const CollisionBody>& slab, const Pose& pose, double friction) {
  RigidBodyDesc d;
  d.shape = slab;
  d.type = BodyType::kStatic;
  d.friction = friction;
  d.position = pose.translation;
  d.orientation = pose.rotation;
  return d;
}

// A world of `model` at `budget` tests per frame holding `slab` (0.25 thick to either side of its
// middle plane), static, turned to `slope` about the origin, and a ball of `radius` at rest on its
// top face 4 m up the slope; returns the ball's description (its start).
RigidBodyDesc ballOnASlope(World& world, const std::shared_ptr<const CollisionBody>& slab, const Quat& slope,
                           const std::shared_ptr<const CollisionBody>& hull, double radius, double friction) {
  world.addBody(staticSlab(slab, Pose{slope, Vec3::Zero()}, friction));
  RigidBodyDesc d = ballDesc(hull, radius);
  d.friction = friction;
  d.position = slope * Vec3(-4.0, 0.0, 0.25 + radius);
  return d;
}

// How far a solid ball rolling from rest without slipping goes in `seconds`: a t^2 / 2 with
// a = 5/7 g sin(theta).
double rollingDistance(double slopeDeg, double seconds) {
  return 5.0 / 14.0 * kGravity * std::sin(slopeDeg * std::numbers::pi / 180.0) * seconds * seconds;
}

// Oracle: every face plane's distance from the centre, and every vertex's, by brute force. The
// hull must hold the ball (planes >= r) and hug it: an icosphere of 2 subdivisions has its most
// tilted faces' planes at cos 10.9 deg of its circumradius, so its vertices reach 1.81 % beyond.
TEST(BallHull, EnclosesTheBallAndHugsIt) {
  for (double radius : {1e-3, 0.2, 7.0, 1e6}) {
    const TriangleMesh hull = makeBallHull(radius, 2);
    EXPECT_EQ(hull.triangles.size(), 320u);
    double nearestPlane = INFINITY, farthestVertex = 0.0;
    for (const Triangle& t : hull.triangles) {
      const Vec3 &a = hull.vertices[t[0]], &b = hull.vertices[t[1]], &c = hull.vertices[t[2]];
      const Vec3 n = (b - a).cross(c - a).normalized();
      EXPECT_GT(n.dot(a), 0.0) << "faces outward";
      nearestPlane = std::min(nearestPlane, n.dot(a));
    }
    for (const Vec3& v : hull.vertices) farthestVertex = std::max(farthestVertex, v.norm());
    EXPECT_GE(nearestPlane, radius) << radius;
    EXPECT_LT(farthestVertex, 1.0185 * radius) << radius;
  }
  EXPECT_THROW(makeBallHull(0.0, 2), Error);
  EXPECT_THROW(makeBallHull(NAN, 2), Error);
}

TEST(BallHull, MassPropertiesAreTheSolidBalls) {
  const MassProperties mp = ballMassProperties(0.5, 2.0);
  EXPECT_NEAR(mp.volume, 4.0 / 3.0 * std::numbers::pi * 0.125, 1e-15);
  EXPECT_NEAR(mp.mass, 2.0 * mp.volume, 1e-15);
  EXPECT_TRUE(mp.centerOfMass.isZero());
  EXPECT_TRUE(mp.inertia.isApprox(Mat3::Identity() * 0.4 * mp.mass * 0.25));
  EXPECT_THROW(ballMassProperties(-1.0), Error);
}

// A world refuses a ball its mesh does not enclose (the contacts put on the ball would miss what
// the narrow phase saw) or whose centre of mass is off its centre.
TEST(Ball, AddBodyRefusesABallItsMeshDoesNotEncloseOrThatTurnsOffCentre) {
  World world;
  const auto inscribed = test::bakeWorldShape(makeIcosphere(0.2, 2));
  EXPECT_THROW(world.addBody(ballDesc(inscribed, 0.2)), Error);
  const auto hull = test::bakeWorldShape(makeBallHull(0.2, 2));
  RigidBodyDesc offCentre = ballDesc(hull, 0.2);
  offCentre.centerOfMass = Vec3(0.01, 0.0, 0.0);
  EXPECT_THROW(world.addBody(offCentre), Error);
  RigidBodyDesc negative = ballDesc(hull, 0.2);
  negative.ballRadius = -1.0;
  EXPECT_THROW(world.addBody(negative), Error);
  EXPECT_NO_THROW(world.addBody(ballDesc(hull, 0.2)));
}

// From rest on a slope with enough friction to roll without slipping (mu >= 2/7 tan theta), a
// solid ball's centre covers a t^2 / 2 with a = 5/7 g sin(theta). At 6 deg the 320-triangle
// icosphere alone stood still on a facet with every model; at 15 deg it rolled 10-20 % short. The
// oracle is the analytic distance; 0.5 % + 1 mm: the sequential-impulse solver's residual over
// 120 steps (measured < 1e-4 relative in every model and budget).
TEST(Ball, RollsDownASlopeAtFiveSeventhsGSinThetaWithEveryModelAndBudget) {
  constexpr double kRadius = 0.2, kSeconds = 2.0;
  const auto slab = test::bakeWorldShape(makeBox(Vec3(6.0, 1.5, 0.25)));
  const auto hull = test::bakeWorldShape(makeBallHull(kRadius, 2));
  const bool sanitized = sanitizerRun();
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree}) {
    for (std::uint64_t budget : {16u, 256u, 0u}) {
      if (sanitized && budget == 256u) continue;
      for (double slopeDeg : {6.0, 15.0}) {
        if (sanitized && slopeDeg == 6.0) continue;  // one slope under the sanitizers (CI time)
        const Quat slope(Eigen::AngleAxisd(slopeDeg * std::numbers::pi / 180.0, Vec3::UnitY()));
        WorldSettings ws;
        ws.model = model;
        ws.budgetTests = budget;
        World world(ws);
        const RigidBodyDesc d = ballOnASlope(world, slab, slope, hull, kRadius, 0.8);
        const BodyId id = world.addBody(d);
        for (int i = 0; i < int(kSeconds * 60); ++i) world.step(1.0 / 60.0);
        const double travelled = (world.state(id).position - d.position).norm();
        const double expected = rollingDistance(slopeDeg, kSeconds);
        EXPECT_NEAR(travelled, expected, 0.005 * expected + 0.001)
            << contactModelName(model) << " budget " << budget << " slope " << slopeDeg;
      }
    }
  }
}

// The sphere models at 16 tests per frame answer a ball on a slab from coarse spheres; the ball's
// contacts are put on the ball from the slab's exact field at each contact's seed point. A seed
// deep in the slab, nearer its underside than its top, gave the underside's normal, and the ball
// (the average model; a random scene of the probe's `roll` kind, seed 1433: r = 0.155 m on a
// 10.7 deg slope, mu 0.54) was pushed down through the slab after 0.93 s. Oracle: the slab's top
// plane (the centre never lower over it than the radius less 1 % of the diameter, issue 17's sink
// bound) and the rolling ball's a t^2 / 2, within issue 17's 10 % for a slope slide.
TEST(Ball, SphereModelsRollItDownASlopeNotThroughIt) {
  constexpr double kRadius = 0.1549, kSeconds = 2.0, kSlopeDeg = 10.72;
  const auto slab = test::bakeWorldShape(makeBox(Vec3(5.0, 1.5, 0.25)));
  const auto hull = test::bakeWorldShape(makeBallHull(kRadius, 2));
  const Quat slope(Eigen::AngleAxisd(kSlopeDeg * std::numbers::pi / 180.0, Vec3::UnitY()));
  for (ContactModel model : {ContactModel::kDos, ContactModel::kAverage}) {
    WorldSettings ws;
    ws.model = model;
    ws.budgetTests = 16;
    World world(ws);
    const RigidBodyDesc d = ballOnASlope(world, slab, slope, hull, kRadius, 0.539);
    const BodyId id = world.addBody(d);
    double lowest = INFINITY;
    for (int i = 0; i < int(kSeconds * 60); ++i) {
      world.step(1.0 / 60.0);
      lowest = std::min(lowest, (slope.conjugate() * world.state(id).position).z() - 0.25);
    }
    const std::string what(contactModelName(model));
    EXPECT_GT(lowest, kRadius - 0.02 * kRadius) << what;
    const double travelled = (world.state(id).position - d.position).norm();
    const double expected = rollingDistance(kSlopeDeg, kSeconds);
    EXPECT_NEAR(travelled, expected, 0.1 * expected) << what;
  }
}

// Rolling without slipping on the flat, a rigid ball keeps its speed (no rolling resistance on a
// pair with a ball) and its centre stays at its radius over the floor. 1e-6 m/s: rounding over 60
// steps; the height within the solver's slop (WorldSettings::slopRel of the ball's diagonal).
TEST(Ball, RollingOnTheFlatKeepsItsSpeedAndHeight) {
  constexpr double kRadius = 0.2;
  const auto slab = test::bakeWorldShape(makeBox(Vec3(6.0, 1.5, 0.25)));
  const auto hull = test::bakeWorldShape(makeBallHull(kRadius, 2));
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree}) {
    WorldSettings ws;
    ws.model = model;
    World world(ws);
    world.addBody(staticSlab(slab, Pose{Quat::Identity(), Vec3(0.0, 0.0, -0.25)}, 0.7));
    RigidBodyDesc d = ballDesc(hull, kRadius);
    d.friction = 0.7;
    d.position = Vec3(-3.0, 0.0, kRadius);
    d.velocity = Vec3(1.0, 0.0, 0.0);
    d.angularVelocity = Vec3(0.0, 1.0 / kRadius, 0.0);
    const BodyId id = world.addBody(d);
    for (int i = 0; i < 60; ++i) world.step(1.0 / 60.0);
    const RigidBodyState s = world.state(id);
    EXPECT_NEAR(s.velocity.x(), 1.0, 1e-6) << contactModelName(model);
    EXPECT_NEAR(s.position.x(), -2.0, 1e-4) << contactModelName(model);
    EXPECT_NEAR(s.position.z(), kRadius, ws.slopRel * hull->diagonal()) << contactModelName(model);
  }
}

// A ball dropped from 1 m (its bottom over the floor) with restitution 0.5 rises to e^2 x 1 m =
// 0.25 m. Its hull meets the floor before the ball does, so the impact began as a speculative
// contact, which the solve only slowed to close the gap: the ball met the floor at that speed in
// the next substep, below the bounce threshold, and did not bounce at all. 3 %: the impact falls
// within a substep (a box dropped the same way rises 2.6 % short).
TEST(Ball, BouncesToRestitutionSquaredTimesItsDropHeight) {
  constexpr double kRadius = 0.1, kDrop = 1.0, kRestitution = 0.5;
  const auto slab = test::bakeWorldShape(makeBox(Vec3(3.0, 3.0, 0.25)));
  const auto hull = test::bakeWorldShape(makeBallHull(kRadius, 2));
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree}) {
    for (std::uint64_t budget : {16u, 0u}) {
      WorldSettings ws;
      ws.model = model;
      ws.budgetTests = budget;
      World world(ws);
      world.addBody(staticSlab(slab, Pose{Quat::Identity(), Vec3(0.0, 0.0, -0.25)}, 0.5));
      RigidBodyDesc d = ballDesc(hull, kRadius);
      d.restitution = kRestitution;
      d.position = Vec3(0.0, 0.0, kRadius + kDrop);
      const BodyId id = world.addBody(d);
      double apex = 0.0;
      bool bounced = false;
      for (int i = 0; i < 240; ++i) {
        world.step(1.0 / 240.0);
        const RigidBodyState st = world.state(id);
        bounced = bounced || st.velocity.z() > 0.0;
        if (bounced) apex = std::max(apex, st.position.z() - kRadius);
      }
      const double expected = kRestitution * kRestitution * kDrop;
      EXPECT_NEAR(apex, expected, 0.03 * expected) << contactModelName(model) << " budget " << budget;
    }
  }
}

// Two equal frictionless balls in zero gravity, one at 1 m/s into the other, restitution 0:
// momentum conservation and no bounce along the centre line leave B with half of A's normal
// velocity, and neither turns (the contact is on the centre line). Their pair costs one test a substep, no query.
TEST(Ball, TwoBallsMeetAlongTheirCentreLineForOneTest) {
  constexpr double kRadius = 0.2;
  const auto hull = test::bakeWorldShape(makeBallHull(kRadius, 2));
  WorldSettings ws;
  ws.gravity = Vec3::Zero();
  ws.model = ContactModel::kExact;
  World world(ws);
  RigidBodyDesc a = ballDesc(hull, kRadius), b = ballDesc(hull, kRadius);
  a.friction = b.friction = 0.0;  // frictionless: the tangential part stays with A, no turn
  a.position = Vec3(-0.5, 0.0, 0.0);
  a.velocity = Vec3(1.0, 0.0, 0.0);
  b.position = Vec3(0.0, 0.03, 0.0);  // off-centre by 0.03: the normal leans, and the oracle with it
  const BodyId ia = world.addBody(a), ib = world.addBody(b);
  std::uint64_t tests = 0, substeps = 0;
  for (int i = 0; i < 60; ++i) {
    const StepReport& r = world.step(1.0 / 60.0);
    tests += r.testsSpent;
    substeps += r.substeps;
  }
  // Along the centre line n at impact (sin = 0.03 / 0.4), the perfectly inelastic exchange moves
  // half the normal velocity to B; the tangential part stays with A.
  const Vec3 n = Vec3(std::sqrt(0.4 * 0.4 - 0.03 * 0.03), 0.03, 0.0).normalized();  // from A toward B
  const Vec3 vB = 0.5 * n.dot(Vec3(1.0, 0.0, 0.0)) * n;
  EXPECT_NEAR((world.state(ib).velocity - vB).norm(), 0.0, 1e-3);
  EXPECT_NEAR((world.state(ia).velocity + world.state(ib).velocity - Vec3(1.0, 0.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_LT(world.state(ia).angularVelocity.norm() + world.state(ib).angularVelocity.norm(), 1e-9);
  EXPECT_LE(tests, substeps) << "one test per substep the pair is in the broad phase";
}

}  // namespace
}  // namespace clod
