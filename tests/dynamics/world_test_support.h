#pragma once
// The bake the world tests run on: an octree sphere-tree of depth 3 and a contact tree of depth
// 6, as the scene loader bakes primitives (include/clod/scene.h), so the tests see the trees
// that `clod simulate` scenes get.

#include <memory>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

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

/// A unit cube (side 1) baked as above, once per test binary.
inline const std::shared_ptr<const CollisionBody>& unitWorldCube() {
  static const std::shared_ptr<const CollisionBody> shape = bakeWorldShape(makeBox(Vec3(0.5, 0.5, 0.5)));
  return shape;
}

}  // namespace clod::test
