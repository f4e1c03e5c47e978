#pragma once
// Bodies baked in-process for the narrow-phase tests (small trees, to keep the tests fast).

#include <cstdlib>
#include <string>

#include "clod/bake.h"
#include "clod/closest_feature_map.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/proximity.h"
#include "support/test_scale.h"

namespace clod::test {

/// A body with sphere-tree (medial, 8-ary, `depth` levels below the root), closest feature map
/// (16 root stacks: finer than the paper's 10 so the sphere tests' tolerances stay small) and
/// contact tree (errorRel 2e-3). The map and the tree are the expensive parts (most of the
/// suite's time under the sanitizers): tests that do not use them leave them out.
inline CollisionBody makeTestBody(const TriangleMesh& mesh, std::uint32_t depth, bool withContactTree = true,
                                  bool withClosestFeatureMap = true) {
  BakeSettings settings;
  settings.sphereTree.depth = depth;
  settings.sphereTree.medialSamples = 2000;
  settings.measureFit = false;
  settings.buildClosestFeatureMap = false;  // built below with finer settings
  settings.buildContactTree = false;       // likewise
  const BakeResult baked = bakeMesh(mesh, settings);
  CollisionBody body = CollisionBody::fromBake(baked.contents);
  const MeshDistance distance(mesh);
  if (withClosestFeatureMap) {
    ClosestFeatureMapSettings cfm;
    cfm.rootStacks = 16;
    body.setClosestFeatureMap(buildClosestFeatureMap(distance, body.sphereTree(), cfm));
  }
  if (withContactTree) {
    ContactTreeSettings ct;
    ct.errorRel = 2e-3;
    ct.maxDepth = 7;
    body.setContactTree(buildContactTree(distance, ct));
  }
  return body;
}

}  // namespace clod::test
