#pragma once
// Contact trees of the shared meshes, built once per test process (they cost seconds each).

#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>

#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "support/test_scale.h"

namespace clod::test {

/// eps_s used for the shared-mesh trees: 1e-3 of the diagonal (the headline value);
/// 4e-3 under sanitizers, where a 1e-3 build of three meshes would take minutes.
inline double treeErrorRel() { return sanitizerRun() ? 4e-3 : 1e-3; }

struct BuiltTree {
  std::unique_ptr<MeshDistance> exact;
  ContactTree tree;
  ContactTreeBuildStats stats;
  ContactTreeSettings settings;
};

inline const BuiltTree& sharedTree(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<BuiltTree>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[name];
  if (!slot) {
    slot = std::make_unique<BuiltTree>();
    LoadedMesh loaded = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/" + name);
    slot->exact = std::make_unique<MeshDistance>(std::move(loaded.mesh));
    slot->settings.errorRel = treeErrorRel();
    slot->tree = buildContactTree(*slot->exact, slot->settings, &slot->stats);
  }
  return *slot;
}

/// A point within `band` of the surface: a uniformly area-weighted surface point plus a
/// uniform offset in the ball of radius `band`, so |exact signed distance| <= band.
inline Vec3 randomBandPoint(const TriangleMesh& mesh, const std::vector<double>& areaPrefix, double band,
                            std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double pick = uni(rng) * areaPrefix.back();
  const auto t = static_cast<std::uint32_t>(std::upper_bound(areaPrefix.begin(), areaPrefix.end(), pick) -
                                            areaPrefix.begin());
  const std::uint32_t tri = std::min<std::uint32_t>(t, mesh.triangleCount() - 1);
  double a = uni(rng), b = uni(rng);
  if (a + b > 1.0) {
    a = 1.0 - a;
    b = 1.0 - b;
  }
  const Vec3 onSurface = mesh.corner(tri, 0) + a * (mesh.corner(tri, 1) - mesh.corner(tri, 0)) +
                         b * (mesh.corner(tri, 2) - mesh.corner(tri, 0));
  Vec3 offset;
  do {
    offset = Vec3(uni(rng), uni(rng), uni(rng)) * 2.0 - Vec3::Ones();
  } while (offset.squaredNorm() > 1.0);
  return onSurface + band * offset;
}

inline std::vector<double> areaPrefix(const TriangleMesh& mesh) {
  std::vector<double> prefix;
  double sum = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) prefix.push_back(sum += mesh.triangleArea(t));
  return prefix;
}

}  // namespace clod::test
