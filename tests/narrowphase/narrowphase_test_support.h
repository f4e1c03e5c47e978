#pragma once
// Bodies baked in-process for the narrow-phase tests (small trees, to keep the tests fast).

#include <cstdlib>
#include <map>
#include <mutex>
#include <random>
#include <string>

#include "clod/bake.h"
#include "clod/closest_feature_map.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "support/test_scale.h"

#include "clod/query.h"

namespace clod::test {

/// An octree sphere-tree of depth 3 and the default closest feature map, no contact tree: the
/// cfm model's view of a body as `clod experiment flat-contact` bakes it (cfm and exact use these).
inline CollisionBody octreeBodyForCfm(const TriangleMesh& mesh) {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 3;
  settings.measureFit = false;
  settings.buildContactTree = false;
  return CollisionBody::fromBake(bakeMesh(mesh, settings).contents);
}

/// A body with sphere-tree (medial, 8-ary, `depth` levels below the root), closest feature map
/// (16 root stacks: finer than the paper's 10 so the sphere tests' tolerances stay small) and
/// contact tree (errorRel 2e-3). The map and the tree are the expensive parts (most of the
/// suite's time under the sanitizers): tests that do not use them leave them out.
inline CollisionBody buildTestBody(const TriangleMesh& mesh, std::uint32_t depth, bool withContactTree,
                                   bool withClosestFeatureMap) {
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

/// buildTestBody, built once per process for each mesh and settings: many suites of a runner
/// use the same cube, sphere or shared mesh, and a fixture is constructed for every test of its
/// suite. Builds are deterministic, so a copy of the first build is the body a fresh build gives.
inline CollisionBody makeTestBody(const TriangleMesh& mesh, std::uint32_t depth, bool withContactTree = true,
                                  bool withClosestFeatureMap = true) {
  std::string key(reinterpret_cast<const char*>(mesh.vertices.data()), mesh.vertices.size() * sizeof(Vec3));
  key.append(reinterpret_cast<const char*>(mesh.triangles.data()), mesh.triangles.size() * sizeof(mesh.triangles[0]));
  key += std::to_string(mesh.vertices.size()) + '/' + std::to_string(depth) + '/' + char('0' + withContactTree) +
         char('0' + withClosestFeatureMap);
  static std::mutex mutex;
  static std::map<std::string, CollisionBody> built;
  const std::lock_guard lock(mutex);
  auto it = built.find(key);
  if (it == built.end()) it = built.emplace(key, buildTestBody(mesh, depth, withContactTree, withClosestFeatureMap)).first;
  return it->second;
}

/// The sphere-tree depth of the suites that check curved shared meshes at many poses (error
/// bounds, containment): 3, and under the sanitizers 2, the depth other suites of the runner
/// build those meshes at, so makeTestBody builds each once per process. Depth 3 adds levels,
/// not code paths; the rates that need it are asserted in Release only.
inline std::uint32_t curvedMeshTestDepth() { return sanitizerRun() ? 2 : 3; }

/// A shared test mesh (../shared/data/meshes/NAME), centred and scaled to unit bounding-box
/// diagonal, so tolerances in units of the diagonal read as plain numbers.
inline TriangleMesh loadUnitMesh(const std::string& name) {
  TriangleMesh mesh = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/" + name).mesh;
  const Aabb box = mesh.bounds();
  for (Vec3& v : mesh.vertices) v = (v - box.center()) / box.diagonal();
  return mesh;
}

/// A random rotation (a normalised quaternion of uniform components: not uniform over the
/// rotations, but it reaches every orientation) and a translation in [-spread, spread]^3.
inline Pose randomPose(std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Pose p;
  p.rotation = Quat(u(rng), u(rng), u(rng), u(rng)).normalized();
  p.translation = spread * Vec3(u(rng), u(rng), u(rng));
  return p;
}

/// Query settings for `model` at a budget of `budget` tests (kUnlimitedTests: none), manifold of 8.
inline QuerySettings settingsFor(ContactModel model, std::uint64_t budget) {
  QuerySettings s;
  s.model = model;
  s.budget.maxTests = budget;
  s.maxContacts = 8;
  return s;
}

}  // namespace clod::test
