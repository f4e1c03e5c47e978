#pragma once
// The bake the world tests run on: an octree sphere-tree of depth 3 and a contact tree of depth
// 6, as the scene loader bakes primitives (include/clod/scene.h), so the tests see the trees
// that `clod simulate` scenes get.

#include <memory>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
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

}  // namespace clod::test
