#pragma once
// The bake the world tests run on: an octree sphere-tree of depth 3 and a contact tree of depth
// 6, as the scene loader bakes primitives (include/clod/scene.h), so the tests see the trees
// that `clod simulate` scenes get.

#include <algorithm>
#include <cmath>
#include <memory>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/world.h"
#include "narrowphase/separation.h"

namespace clod::test {

inline std::shared_ptr<const CollisionBody> bakeWorldShape(const TriangleMesh& mesh) {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 3;
  settings.measureFit = false;
  settings.buildContactTree = false;  // set below with maxDepth 6
  BakeResult baked = bakeMesh(mesh, settings);
  auto body = std::make_shared<CollisionBody>(CollisionBody::fromBake(baked.contents));
  ContactTreeSettings ct;
  ct.maxDepth = 6;
  body->setContactTree(buildContactTree(MeshDistance(mesh), ct));
  return body;
}

/// The distance between two posed meshes by brute force: the minimum over every triangle pair
/// (detail::triangleDistance), the definition the world's separation and the narrow phase's
/// proven gaps are held to.
inline double bruteForceSurfaceDistance(const TriangleMesh& ma, const Pose& pa, const TriangleMesh& mb, const Pose& pb) {
  double best = INFINITY;
  for (const auto& ta : ma.triangles)
    for (const auto& tb : mb.triangles) {
      const auto d = detail::triangleDistance(pa.apply(ma.vertices[ta[0]]), pa.apply(ma.vertices[ta[1]]),
                                              pa.apply(ma.vertices[ta[2]]), pb.apply(mb.vertices[tb[0]]),
                                              pb.apply(mb.vertices[tb[1]]), pb.apply(mb.vertices[tb[2]]));
      best = std::min(best, d.distanceSquared);
    }
  return std::sqrt(best);
}

/// How far a body's up axis has turned from the world's (degrees).
inline double tiltDegrees(const Quat& q) {
  const Vec3 up = q * Vec3::UnitZ();
  return std::acos(std::clamp(up.z(), -1.0, 1.0)) * 180.0 / M_PI;
}

/// A unit cube (side 1) baked as above, once per test binary.
/// The inertia of a solid box of half sides (a, b, c) and `mass`: m (b^2 + c^2) / 3 about x, and
/// so on.
inline Mat3 solidBoxInertia(const Vec3& half, double mass) {
  const Vec3 sq = half.cwiseProduct(half);
  return Vec3(sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y()).asDiagonal() * (mass / 3.0);
}

inline const std::shared_ptr<const CollisionBody>& unitWorldCube() {
  static const std::shared_ptr<const CollisionBody> shape = bakeWorldShape(makeBox(Vec3(0.5, 0.5, 0.5)));
  return shape;
}

/// A world of `model` at `budget` tests per frame (0: unlimited) holding one static body, the
/// ground: `shape` scaled by `scale` (World::addBody), placed at `position` turned by `turn`.
inline World staticGroundWorld(ContactModel model, std::uint64_t budget, std::shared_ptr<const CollisionBody> shape,
                               const Vec3& position, const Quat& turn, double friction, double scale = 1.0) {
  WorldSettings ws;
  ws.model = model;
  ws.budgetTests = budget;
  World world(ws);
  RigidBodyDesc ground;
  ground.type = BodyType::kStatic;
  ground.shape = std::move(shape);
  ground.position = position;
  ground.orientation = turn;
  ground.friction = friction;
  world.addBody(ground, scale);
  return world;
}

}  // namespace clod::test
