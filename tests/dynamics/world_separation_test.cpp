// World::separation against analytic distances of boxes and the bounds of tessellated spheres,
// its branch-and-bound descent against brute force over every triangle pair, and uniformly scaled
// bodies (World::addBody with a scale, scaleCollisionBody) against the analytic distance field of
// the scaled box.
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/world.h"
#include "narrowphase/separation.h"
#include "dynamics/world_test_support.h"
#include "support/test_scale.h"

namespace clod {
namespace {

std::shared_ptr<const CollisionBody> bake(const TriangleMesh& mesh, bool contactTree = false) {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 3;
  settings.measureFit = false;
  settings.buildContactTree = false;
  auto body = std::make_shared<CollisionBody>(CollisionBody::fromBake(bakeMesh(mesh, settings).contents));
  if (contactTree) {
    ContactTreeSettings ct;
    ct.maxDepth = 6;
    body->setContactTree(buildContactTree(MeshDistance(mesh), ct));
  }
  return body;
}

const std::shared_ptr<const CollisionBody>& cube() {  // half extent 0.5
  static const auto shape = bake(makeBox(Vec3(0.5, 0.5, 0.5)), true);
  return shape;
}

RigidBodyDesc placed(const std::shared_ptr<const CollisionBody>& shape, const Vec3& position,
                     const Quat& orientation = Quat::Identity(), BodyType type = BodyType::kStatic) {
  RigidBodyDesc d;
  d.shape = shape;
  d.type = type;
  d.position = position;
  d.orientation = orientation;
  return d;
}

Separation separationOf(const RigidBodyDesc& a, const RigidBodyDesc& b, double maxDistance = INFINITY) {
  World world;
  const BodyId ia = world.addBody(a);
  const BodyId ib = world.addBody(b);
  return world.separation(ia, ib, maxDistance);
}

// Distances are of order 1 here; the descent is exact up to rounding of a few operations on
// coordinates of order 1: 1e-12 is ~1e4 ulps.
constexpr double kTol = 1e-12;

TEST(WorldSeparation, BoxesFaceToFaceEdgeToFaceAndCornerToCornerMatchTheirAnalyticGaps) {
  const Separation faces = separationOf(placed(cube(), Vec3::Zero()), placed(cube(), Vec3(1.3, 0.2, -0.1)));
  ASSERT_TRUE(faces.withinMax);
  EXPECT_NEAR(faces.distance, 0.3, kTol);
  EXPECT_FALSE(faces.overlapping);
  EXPECT_NEAR(faces.pointA.x(), 0.5, kTol);  // on A's +x face, B's -x face, 0.3 apart
  EXPECT_NEAR(faces.pointB.x(), 0.8, kTol);
  EXPECT_NEAR((faces.pointA - faces.pointB).norm(), faces.distance, kTol);

  // B turned 45 deg about z presents an edge: its reach along x is 0.5 sqrt(2).
  const Quat turn(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()));
  const Separation edge = separationOf(placed(cube(), Vec3::Zero()), placed(cube(), Vec3(2.0, 0.0, 0.0), turn));
  EXPECT_NEAR(edge.distance, 2.0 - 0.5 - 0.5 * std::sqrt(2.0), kTol);
  EXPECT_NEAR(edge.pointB.x(), 2.0 - 0.5 * std::sqrt(2.0), kTol);

  // Offset along (1, 1, 1): corner (0.5, 0.5, 0.5) to corner (c - 0.5, ...).
  const double c = 1.7;
  const Separation corners = separationOf(placed(cube(), Vec3::Zero()), placed(cube(), Vec3(c, c, c)));
  EXPECT_NEAR(corners.distance, std::sqrt(3.0) * (c - 1.0), kTol);
  EXPECT_NEAR((corners.pointA - Vec3(0.5, 0.5, 0.5)).norm(), 0.0, kTol);
}

TEST(WorldSeparation, CrossingSurfacesGiveZeroAndContainmentIsOverlapWithTheInnerGap) {
  const Separation crossing = separationOf(placed(cube(), Vec3::Zero()), placed(cube(), Vec3(0.8, 0.3, 0.1)));
  EXPECT_EQ(crossing.distance, 0.0);
  EXPECT_TRUE(crossing.overlapping);
  EXPECT_LE((crossing.pointA - crossing.pointB).norm(), kTol);

  static const auto big = bake(makeBox(Vec3(2.0, 2.0, 2.0)));
  // The cube inside the big box, offset 0.3 in x: nearest faces are +x, 2 - 0.8 = 1.2 apart.
  const Separation inside = separationOf(placed(big, Vec3::Zero()), placed(cube(), Vec3(0.3, 0.0, 0.0)));
  EXPECT_TRUE(inside.overlapping);
  EXPECT_NEAR(inside.distance, 1.2, kTol);
  const Separation insideSwapped = separationOf(placed(cube(), Vec3(0.3, 0.0, 0.0)), placed(big, Vec3::Zero()));
  EXPECT_TRUE(insideSwapped.overlapping);
  EXPECT_NEAR(insideSwapped.distance, 1.2, kTol);
  // Boxes overlapping but surfaces apart is only possible by containment: beside it, not overlapping.
  EXPECT_FALSE(separationOf(placed(big, Vec3::Zero()), placed(cube(), Vec3(3.0, 0.0, 0.0))).overlapping);
}

TEST(WorldSeparation, MaxDistanceStopsEarlyWithALowerBound) {
  const RigidBodyDesc a = placed(cube(), Vec3::Zero()), b = placed(cube(), Vec3(11.0, 0.0, 0.0));
  const Separation full = separationOf(a, b);
  EXPECT_NEAR(full.distance, 10.0, kTol);
  const Separation capped = separationOf(a, b, 1.0);
  EXPECT_FALSE(capped.withinMax);
  EXPECT_GT(capped.distance, 1.0);
  EXPECT_LE(capped.distance, 10.0 + kTol);
  EXPECT_TRUE(separationOf(a, b, 10.5).withinMax);
}

TEST(WorldSeparation, TessellatedSpheresLieBetweenCircumscribedAndInscribedBallsAndMatchBruteForce) {
  const TriangleMesh mesh = makeIcosphere(1.0, 2);
  static const auto sphere = bake(mesh);
  // Inscribed radius: the nearest face plane to the centre (independent of the descent).
  double inscribed = INFINITY;
  for (const auto& t : mesh.triangles) {
    const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]).normalized();
    inscribed = std::min(inscribed, std::abs(n.dot(mesh.vertices[t[0]])));
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Under the sanitizers 5 poses: the brute-force oracle (320 x 320 triangle pairs) is the cost.
  const int trials = test::sanitizerRun() ? 5 : 20;
  for (int trial = 0; trial < trials; ++trial) {
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    const Quat qa(Eigen::AngleAxisd(3.0 * u(rng), axis)), qb(Eigen::AngleAxisd(3.0 * u(rng), axis.unitOrthogonal()));
    const double centres = 2.2 + 1.5 * (u(rng) + 1.0);
    const Vec3 direction = Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 pa(u(rng), u(rng), u(rng));
    const Vec3 pb = pa + centres * direction;
    const Separation s = separationOf(placed(sphere, pa, qa), placed(sphere, pb, qb));
    // The mesh lies between the inscribed and the unit ball: the gap between the balls bounds it.
    EXPECT_GE(s.distance, centres - 2.0 - kTol) << trial;
    EXPECT_LE(s.distance, centres - 2.0 * inscribed + kTol) << trial;
    EXPECT_NEAR(s.distance, test::bruteForceSurfaceDistance(mesh, Pose{qa, pa}, mesh, Pose{qb, pb}), kTol) << trial;
    EXPECT_NEAR((s.pointA - s.pointB).norm(), s.distance, kTol) << trial;
  }
}

TEST(WorldSeparation, BadArgumentsAreErrors) {
  World world;
  const BodyId a = world.addBody(placed(cube(), Vec3::Zero()));
  const BodyId b = world.addBody(placed(cube(), Vec3(3, 0, 0)));
  EXPECT_THROW(world.separation(a, a), Error);
  EXPECT_THROW(world.separation(a, b, -1.0), Error);
  EXPECT_THROW(world.separation(a, b, NAN), Error);
  EXPECT_THROW(world.separation(a, 2), Error);
  world.removeBody(b);
  EXPECT_THROW(world.separation(a, b), Error);
}

TEST(WorldScale, AScaledBodyHasScaledDistancesAndRestsAtItsScaledHeight) {
  World probe;
  const BodyId a = probe.addBody(placed(cube(), Vec3::Zero()), 2.0);  // half extent 1
  const BodyId b = probe.addBody(placed(cube(), Vec3(3.0, 0.0, 0.0)));
  EXPECT_NEAR(probe.separation(a, b).distance, 3.0 - 1.0 - 0.5, kTol);
  EXPECT_NEAR(probe.desc(a).shape->diagonal(), 2.0 * cube()->diagonal(), kTol);
  // Two bodies with the same shape and scale share one copy.
  const BodyId c = probe.addBody(placed(cube(), Vec3(0.0, 5.0, 0.0)), 2.0);
  EXPECT_EQ(probe.desc(a).shape, probe.desc(c).shape);
  for (double bad : {0.0, -1.0, double(NAN), double(INFINITY)}) EXPECT_THROW(probe.addBody(placed(cube(), Vec3::Zero()), bad), Error);

  // A cube of half extent 0.5 x 1.5 dropped on the ground settles with its centre 0.75 above it.
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kContactTree}) {
    WorldSettings ws;
    ws.model = model;
    World world(ws);
    world.addBody(placed(cube(), Vec3(0.0, 0.0, -0.5), Quat::Identity(), BodyType::kStatic), 1.0);  // top z = 0
    RigidBodyDesc d = placed(cube(), Vec3(0.0, 0.0, 0.8), Quat::Identity(), BodyType::kDynamic);
    d.mass = 1.0;
    d.inertia = Mat3::Identity() * (2.0 / 3.0 * 0.75 * 0.75);
    const BodyId id = world.addBody(d, 1.5);
    for (int i = 0; i < 90; ++i) world.step(1.0 / 60.0);
    // Resting within 1 % of the scaled diagonal (the world's allowed penetration and drift).
    EXPECT_NEAR(world.state(id).position.z(), 0.75, 0.01 * 1.5 * std::sqrt(3.0)) << contactModelName(model);
  }
}

TEST(WorldScale, ScaledContactTreeAndSphereTreeBoundTheScaledBox) {
  const double s = 3.0;
  const auto scaled = scaleCollisionBody(*cube(), s);
  // The analytic signed distance of a box of half extent h (negative inside).
  auto boxDistance = [](const Vec3& p, double h) {
    const Vec3 q = p.cwiseAbs() - Vec3::Constant(h);
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  };
  ASSERT_TRUE(scaled->hasContactTree());
  const ContactTree& tree = scaled->contactTree();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.6 * s, 0.6 * s);
  int checked = 0;
  for (int i = 0; i < 500; ++i) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const ContactFieldSample f = tree.sample(p);
    if (!f.insideRoot) continue;
    ++checked;
    // The field is within its own error bound of the truth (contact_tree.h), plus float rounding
    // of the scaled values (relative 1e-6 of the scaled box size is generous for one multiply).
    EXPECT_LE(std::abs(f.distance - boxDistance(p, 0.5 * s)), f.errorBound + 1e-6 * s) << p.transpose();
  }
  EXPECT_GT(checked, 250);  // the root cube holds most of the sampled box around the body
  // Every vertex of the scaled mesh is inside the scaled root sphere.
  const SphereTree& st = scaled->sphereTree();
  for (const Vec3& v : scaled->mesh().vertices) EXPECT_LE((v - st.center(0)).norm(), st.radius[0] * (1 + 1e-12));
  EXPECT_THROW(scaleCollisionBody(*cube(), 0.0), Error);
}

}  // namespace
}  // namespace clod
