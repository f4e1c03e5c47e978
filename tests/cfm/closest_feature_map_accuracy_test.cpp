// The claim of the closest-feature-map paper, as a property test against the exact oracle:
// on closed meshes, the CFM contact normal is closer to the exact surface normal than the D&O
// normal and than the averaged normal, at every sphere-tree level (median angle error).
// Contact points and reference normals come from MeshDistance::closestPoint (the exact
// proximity layer), never from the map (see normal_accuracy.h for the distribution).
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "clod/closest_feature_map.h"
#include "clod/contact_normal.h"
#include "clod/mesh_io.h"
#include "clod/normal_accuracy.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"
#include "support/test_scale.h"

namespace clod {
namespace {

using test::sanitizerRun;

struct AccuracyCase {
  const char* name;  // a shared mesh file, or "box"
};

TriangleMesh loadCase(const std::string& name) {
  if (name == "box") return makeBox(Vec3(1.0, 0.6, 0.3));
  return loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / name).mesh;
}

class CfmAccuracy : public ::testing::TestWithParam<const char*> {};

TEST_P(CfmAccuracy, CfmMedianErrorBeatsDoAndAverageOnEveryLevel) {
  const MeshDistance distance(loadCase(GetParam()));
  SphereTreeSettings treeSettings;  // the bake default: medial, 8-ary, 5 levels
  treeSettings.medialSamples = sanitizerRun() ? 3000 : 20000;
  if (sanitizerRun()) treeSettings.depth = 3;  // every level is still compared; fewer spheres to map
  const SphereTree tree = buildSphereTree(distance, treeSettings);
  // 16 stacks, the paper's finer setting. At its default 10 stacks the root level of fandisk is
  // worse than D&O (44 vs 36 degrees median, docs/closest-feature-maps.md): 65 samples are too
  // sparse for its sharp features at root scale. Below the root 10 stacks also wins.
  ClosestFeatureMapSettings mapSettings;
  mapSettings.rootStacks = 16;
  const ClosestFeatureMap maps = buildClosestFeatureMap(distance, tree, mapSettings);

  const NormalAccuracyCandidate candidates[] = {
      {"dos", ContactNormalModel::kDingliana, &maps},
      {"average", ContactNormalModel::kAverage, &maps},
      {"cfm", ContactNormalModel::kClosestFeatureMap, &maps},
  };
  NormalAccuracySettings settings;
  // 800 points put the standard error of a median well below the gaps measured in
  // docs/closest-feature-maps.md (several degrees at every level); 200 under the sanitizers.
  settings.pointsPerLevel = sanitizerRun() ? 200 : 800;
  settings.maxAttemptsPerLevel = 200000;
  const std::vector<NormalAccuracyLevel> levels = measureNormalAccuracy(distance, tree, candidates, settings);
  ASSERT_EQ(levels.size(), tree.levelCount());
  for (const NormalAccuracyLevel& level : levels) {
    ASSERT_GE(level.points, settings.pointsPerLevel / 2) << "level " << level.level << ": too few contact points near the surface";
    const double dos = level.models[0].medianDeg;
    const double average = level.models[1].medianDeg;
    const double cfm = level.models[2].medianDeg;
    // The map's normals are encoded (16-bit octahedral): an exact model (the average over one
    // face of a box) can beat it by at most the encoding error, so that is the margin granted.
    const double codecDeg = normalCodecErrorBound(mapSettings.codec) * 180.0 / 3.141592653589793;
    EXPECT_LT(cfm, dos + codecDeg) << GetParam() << " level " << level.level;
    EXPECT_LT(cfm, average + codecDeg) << GetParam() << " level " << level.level;
    std::printf("  %-12s level %u: %5u points, median deg dos %6.2f average %6.2f cfm %6.2f\n", GetParam(), level.level,
                level.points, dos, average, cfm);
  }
}

INSTANTIATE_TEST_SUITE_P(ClosedMeshes, CfmAccuracy, ::testing::Values("box", "spot.obj", "fandisk.obj"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           std::string name = p.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace clod
