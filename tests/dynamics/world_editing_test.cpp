// World editing (world.h): forces, torques and impulses against v = F dt / m and its rotational
// twin, removal and filters against free fall, the contact callback, setState's validation, the id
// policy, and the contact points the step reports.
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/world.h"

namespace clod {
namespace {

std::shared_ptr<const CollisionBody> bakeBox(const Vec3& halfExtents) {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 3;
  settings.measureFit = false;
  settings.buildContactTree = false;
  return std::make_shared<const CollisionBody>(CollisionBody::fromBake(bakeMesh(makeBox(halfExtents), settings).contents));
}

const std::shared_ptr<const CollisionBody>& cube() {  // half extent 0.5: diagonal sqrt(3)
  static const auto shape = bakeBox(Vec3(0.5, 0.5, 0.5));
  return shape;
}
const std::shared_ptr<const CollisionBody>& slab() {  // the ground: top face at z = 0.25
  static const auto shape = bakeBox(Vec3(3.0, 3.0, 0.25));
  return shape;
}

// A solid box of mass m and half extents h: I = m/3 diag(hy^2 + hz^2, ...).
RigidBodyDesc box(double mass, const Vec3& h, const Vec3& position) {
  RigidBodyDesc d;
  d.shape = cube();
  d.mass = mass;
  d.inertia = Mat3::Zero();
  d.inertia.diagonal() = mass / 3.0 * Vec3(h.y() * h.y() + h.z() * h.z(), h.x() * h.x() + h.z() * h.z(),
                                           h.x() * h.x() + h.y() * h.y());
  d.position = position;
  return d;
}

RigidBodyDesc ground() {
  RigidBodyDesc d;
  d.name = "ground";
  d.shape = slab();
  d.type = BodyType::kStatic;
  return d;
}

WorldSettings zeroGravity() {
  WorldSettings s;
  s.gravity = Vec3::Zero();
  return s;
}

std::string errorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    return e.what();
  }
  return "no error";
}

constexpr double kDt = 1.0 / 60.0;
const Vec3 kHalf(0.5, 0.5, 0.5);

TEST(WorldEditing, AppliedForceGivesVelocityForceTimesDtOverMassForOneStepOnly) {
  World world(zeroGravity());
  const BodyId id = world.addBody(box(2.0, kHalf, Vec3::Zero()));
  const Vec3 force(3.0, -1.0, 0.5);
  world.applyForce(id, force);
  world.applyForce(id, force);  // accumulates: 2 F
  world.step(kDt);
  // v = 2F dt / m, a sum of n substep increments: rounding only (1e-12 relative).
  const Vec3 expected = 2.0 * force * kDt / 2.0;
  EXPECT_LE((world.state(id).velocity - expected).norm(), 1e-12 * expected.norm());
  EXPECT_LE(world.state(id).angularVelocity.norm(), 1e-15);  // through the centre: no spin
  world.step(kDt);  // cleared after the step: the velocity stays
  EXPECT_LE((world.state(id).velocity - expected).norm(), 1e-12 * expected.norm());
}

TEST(WorldEditing, TorqueAndOffCentreForceSpinAboutAPrincipalAxisAsIOmegaEqualsTauDt) {
  World world(zeroGravity());
  const Vec3 h(0.5, 0.5, 0.5);
  const BodyId id = world.addBody(box(3.0, h, Vec3::Zero()));
  const double izz = 3.0 / 3.0 * (h.x() * h.x() + h.y() * h.y());
  world.applyTorque(id, Vec3(0.0, 0.0, 0.6));
  world.step(kDt);
  // About a principal axis the angular momentum I w keeps its direction: w = tau dt / I.
  EXPECT_NEAR(world.state(id).angularVelocity.z(), 0.6 * kDt / izz, 1e-12);
  // A force F x at the point (0, 1, 0) from the centre: torque r x F = -F z, plus v = F dt / m.
  World world2(zeroGravity());
  const BodyId id2 = world2.addBody(box(3.0, h, Vec3::Zero()));
  world2.applyForce(id2, Vec3(1.5, 0.0, 0.0), Vec3(0.0, 1.0, 0.0));
  world2.step(kDt);
  EXPECT_NEAR(world2.state(id2).angularVelocity.z(), -1.5 * kDt / izz, 1e-12);
  EXPECT_NEAR(world2.state(id2).velocity.x(), 1.5 * kDt / 3.0, 1e-12);
}

TEST(WorldEditing, ImpulseChangesVelocityAtOnceAndStaticBodiesIgnoreForces) {
  World world(zeroGravity());
  const BodyId g = world.addBody(ground());
  const BodyId id = world.addBody(box(4.0, kHalf, Vec3(0.0, 0.0, 5.0)));
  world.applyImpulse(id, Vec3(0.0, 8.0, 0.0), world.state(id).position);
  EXPECT_NEAR(world.state(id).velocity.y(), 2.0, 1e-15);  // J / m, before any step
  world.applyForce(g, Vec3(1e6, 0.0, 0.0));
  world.applyImpulse(g, Vec3(1e6, 0.0, 0.0), Vec3::Zero());
  world.step(kDt);
  EXPECT_EQ(world.state(g).position, Vec3::Zero());
  EXPECT_EQ(world.state(g).velocity, Vec3::Zero());
  EXPECT_NE(errorOf([&] { world.applyForce(id, Vec3(NAN, 0, 0)); }), "no error");
  EXPECT_NE(errorOf([&] { world.applyImpulse(id, Vec3::Zero(), Vec3(0, INFINITY, 0)); }), "no error");
  EXPECT_EQ(errorOf([&] { world.applyTorque(7, Vec3::Zero()); }),
            "World::applyTorque: body id 7 out of range (the world has 2 bodies)");
}

// Height of a box dropped from z0 after n steps of free fall, as semi-implicit Euler integrates
// it: v_k = -g k h, z_n = z0 - g h^2 n (n + 1) / 2 with h the substep (exact for the scheme).
double freeFallHeight(double z0, double g, double h, int n) { return z0 - g * h * h * n * (n + 1) / 2.0; }

// Drops a cube from rest onto the ground; returns its final centre height after `steps` steps.
// `edit` runs once after the bodies are added.
double dropOnGround(int steps, const std::function<void(World&, BodyId ground, BodyId cube)>& edit,
                    std::uint32_t* substeps = nullptr) {
  WorldSettings s;
  s.minSubsteps = 1;
  World world(s);
  const BodyId g = world.addBody(ground());
  const BodyId c = world.addBody(box(1.0, kHalf, Vec3(0.0, 0.0, 0.76)));
  edit(world, g, c);
  std::uint32_t total = 0;
  for (int i = 0; i < steps; ++i) total += world.step(kDt).substeps;
  if (substeps) *substeps = total;
  return world.state(c).position.z();
}

TEST(WorldEditing, ARemovedBodyNoLongerCollidesAndTheOtherIdsStayValid) {
  // Control: the cube rests on the slab (centre at top 0.25 + 0.5, within 1 % of its diagonal).
  const double resting = dropOnGround(60, [](World&, BodyId, BodyId) {});
  EXPECT_NEAR(resting, 0.75, 0.01 * std::sqrt(3.0));
  std::uint32_t substeps = 0;
  const double fallen = dropOnGround(60, [](World& w, BodyId g, BodyId c) {
    w.removeBody(g);
    EXPECT_FALSE(w.contains(g));
    EXPECT_TRUE(w.contains(c));
    EXPECT_EQ(w.bodyCount(), 2u);
    EXPECT_EQ(errorOf([&] { w.state(g); }), "World::state: body 0 was removed");
    EXPECT_EQ(errorOf([&] { w.removeBody(g); }), "World::removeBody: body 0 was removed");
    EXPECT_EQ(w.state(c).position.z(), 0.76);  // id 1 still names the cube
  }, &substeps);
  // Nothing to meet: one substep per step, and the fall is the scheme's free fall exactly.
  ASSERT_EQ(substeps, 60u);
  EXPECT_NEAR(fallen, freeFallHeight(0.76, 9.81, kDt, 60), 1e-9);
}

TEST(WorldEditing, AFilteredPairFallsThroughAndAMatchingOneDoesNot) {
  const double fallen = dropOnGround(60, [](World& w, BodyId, BodyId c) {
    w.setFilter(c, CollisionFilter{2u, ~1u});  // group 2, ignores group 1 (the ground's default)
    EXPECT_EQ(w.filter(c).group, 2u);
  });
  EXPECT_NEAR(fallen, freeFallHeight(0.76, 9.81, kDt, 60), 1e-9);
  const double kept = dropOnGround(60, [](World& w, BodyId g, BodyId c) {
    w.setFilter(g, CollisionFilter{4u, 2u});
    w.setFilter(c, CollisionFilter{2u, 4u});
  });
  EXPECT_NEAR(kept, 0.75, 0.01 * std::sqrt(3.0));
  // Filters are checked both ways: the ground's mask excludes the cube's group.
  const double oneWay = dropOnGround(60, [](World& w, BodyId g, BodyId c) {
    w.setFilter(g, CollisionFilter{1u, 4u});
    w.setFilter(c, CollisionFilter{2u, 0xffffffffu});
  });
  EXPECT_LT(oneWay, 0.0);
}

TEST(WorldEditing, ContactCallbackSeesEachPairOnceASubstepAndCanDisableIt) {
  int calls = 0;
  bool sawContacts = true, ordered = true;
  const double kept = dropOnGround(60, [&](World& w, BodyId, BodyId) {
    w.setContactCallback([&](const ContactPairEvent& e) {
      ++calls;
      sawContacts = sawContacts && !e.contacts.empty();
      ordered = ordered && e.a == 0 && e.b == 1;
      // The ground is a, the cube b: normals point from the cube toward the ground (down).
      for (const Contact& c : e.contacts) ordered = ordered && c.normal.z() < -0.9;
      return true;
    });
  });
  EXPECT_GT(calls, 30);  // the cube rests from about step 4 on: one call per substep after that
  EXPECT_TRUE(sawContacts);
  EXPECT_TRUE(ordered);
  EXPECT_NEAR(kept, 0.75, 0.01 * std::sqrt(3.0));
  int disabledCalls = 0;
  std::uint32_t substeps = 0;
  const double fallen = dropOnGround(30, [&](World& w, BodyId, BodyId) {
    w.setContactCallback([&](const ContactPairEvent&) {
      ++disabledCalls;
      return false;
    });
  }, &substeps);
  // Disabled in each step where it touches: the cube sinks through, and each step calls at most once.
  EXPECT_LT(fallen, 0.0);
  EXPECT_GT(disabledCalls, 0);
  EXPECT_LE(disabledCalls, 30);
}

TEST(WorldEditing, SetStateTeleportsAndIsValidated) {
  World world(zeroGravity());
  const BodyId g = world.addBody(ground());
  const BodyId id = world.addBody(box(1.0, kHalf, Vec3(0.0, 0.0, 3.0)));
  RigidBodyState s;
  s.position = Vec3(1.0, 2.0, 4.0);
  s.orientation = Quat(std::cos(0.15) * 1.0004, std::sin(0.15) * 1.0004, 0.0, 0.0);  // |q| 1.0004: normalised
  s.velocity = Vec3(0.0, 1.0, 0.0);
  s.angularVelocity = Vec3(0.0, 0.0, 2.0);
  world.setState(id, s);
  const RigidBodyState got = world.state(id);
  EXPECT_LE((got.position - s.position).norm(), 1e-15);
  EXPECT_NEAR(got.orientation.norm(), 1.0, 1e-15);
  EXPECT_NEAR(got.orientation.angularDistance(Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()))), 0.0, 1e-12);
  EXPECT_EQ(got.velocity, s.velocity);
  world.step(kDt);  // free flight: x += v dt
  EXPECT_NEAR(world.state(id).position.y(), 2.0 + kDt, 1e-12);

  RigidBodyState bad = s;
  bad.position.x() = NAN;
  EXPECT_EQ(errorOf([&] { world.setState(id, bad); }), "World::setState: body 1: position must be finite");
  bad = s;
  bad.orientation = Quat(2.0, 0.0, 0.0, 0.0);
  EXPECT_EQ(errorOf([&] { world.setState(id, bad); }),
            "World::setState: body 1: orientation must be a unit quaternion (|q| = 2.000000)");
  bad = s;
  bad.orientation = Quat(0.0, 0.0, 0.0, 0.0);
  EXPECT_NE(errorOf([&] { world.setState(id, bad); }), "no error");
  bad = s;
  bad.angularVelocity.z() = INFINITY;
  EXPECT_NE(errorOf([&] { world.setState(id, bad); }), "no error");
  EXPECT_EQ(errorOf([&] { world.setState(g, s); }), "World::setState: body 0 is static: its velocities must be zero");
  RigidBodyState still;
  still.position = Vec3(0.0, 0.0, -1.0);
  world.setState(g, still);  // a static body may be moved
  EXPECT_EQ(world.state(g).position, still.position);
  EXPECT_EQ(errorOf([&] { world.setState(99, s); }), "World::setState: body id 99 out of range (the world has 2 bodies)");
}

TEST(WorldEditing, StepReportsBothAnchoredPointsOfEachContact) {
  WorldSettings s;
  World world(s);
  world.addBody(ground());
  world.addBody(box(1.0, kHalf, Vec3(0.0, 0.0, 0.76)));
  const StepReport* r = nullptr;
  for (int i = 0; i < 60; ++i) r = &world.step(kDt);
  ASSERT_FALSE(r->contacts.empty());
  ASSERT_EQ(r->contactPoints.size(), r->contacts.size());
  for (std::size_t i = 0; i < r->contacts.size(); ++i) {
    const auto& [onA, onB] = r->contactPoints[i];
    // Resting: both points lie on the slab's top face z = 0.25 and within the cube's footprint;
    // they may be apart by the allowed penetration (slopRel 0.002) plus the anchor drift a
    // persistent contact tolerates (1 % of the smaller diagonal, world.cpp): 0.012 x sqrt(3).
    const double tol = 0.012 * std::sqrt(3.0);
    EXPECT_NEAR(onA.z(), 0.25, tol);
    EXPECT_NEAR(onB.z(), 0.25, tol);
    EXPECT_LE(std::abs(onB.x()), 0.5 + tol);
    EXPECT_LE(std::abs(onB.y()), 0.5 + tol);
    // Their gap along the normal is the separation the solver sees: at most the tolerance deep.
    EXPECT_GE((onA - onB).dot(r->contacts[i].normal), -tol);
  }
}

}  // namespace
}  // namespace clod
