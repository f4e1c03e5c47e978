// Property tests on the shared mesh corpus (closed, open, non-manifold) and on primitives:
// every level of every tree covers the whole surface. Oracle: direct |p - c| <= r checks of
// uniform area-weighted random surface points (plus every vertex and edge midpoint) against
// the level's spheres. No tolerance: the builders promise exact coverage.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"
#include "sphere_tree_structure_check.h"
#include "sphere_tree_test_support.h"

namespace clod {
namespace {

void expectEveryLevelCovers(const SphereTree& tree, const std::vector<Vec3>& points) {
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    const test::LevelSphereIndex index(tree, l);
    std::size_t uncovered = 0;
    for (const Vec3& p : points)
      if (!index.covers(p) && ++uncovered <= 3)
        ADD_FAILURE() << "level " << l << ": point (" << p.transpose() << ") is in no sphere";
    EXPECT_EQ(uncovered, 0u) << "level " << l << " of " << points.size() << " points";
  }
}

// Octree, the default medial builder (per node the better of merge/burst and k-means) and the
// merge/burst reduction alone (with fewer medial samples: coverage does not depend on them, and
// it keeps the runner short). Under sanitizers the trees stop one level earlier and the medial
// sampling is sparser: every builder and reduction still runs (the default runs merge/burst on
// every node), at an eighth of the leaves.
void checkBothBuilders(const TriangleMesh& mesh, std::size_t sampleCount, bool mergeBurstAlone = true) {
  const bool reduced = test::sanitizerRun();
  if (reduced) mergeBurstAlone = false;
  const MeshDistance distance(mesh);
  const std::vector<Vec3> points = test::sampleSurfaceUniformly(mesh, sampleCount, 20260521);
  struct Case {
    const char* name;
    SphereTreeMethod method;
    MedialReduction reduction;
    std::uint32_t medialSamples;
  };
  const std::uint32_t defaultSamples = SphereTreeSettings{}.medialSamples;
  for (const Case& c : {Case{"octree", SphereTreeMethod::kOctree, MedialReduction::kBest, defaultSamples},
                        Case{"medial", SphereTreeMethod::kMedial, MedialReduction::kBest, defaultSamples},
                        Case{"medial merge/burst", SphereTreeMethod::kMedial, MedialReduction::kMergeBurst, 3000}}) {
    if (c.reduction == MedialReduction::kMergeBurst && !mergeBurstAlone) continue;
    SCOPED_TRACE(c.name);
    SphereTreeSettings settings;  // defaults: 8-ary, 4 levels below the root
    settings.method = c.method;
    settings.medialReduction = c.reduction;
    settings.medialSamples = reduced ? std::min<std::uint32_t>(c.medialSamples, 3000) : c.medialSamples;
    if (reduced) settings.depth = 3;
    const SphereTree tree = buildSphereTree(distance, settings);
    test::expectWellFormedTree(tree, distance.mesh(), settings);
    expectEveryLevelCovers(tree, points);
  }
}

class SharedMeshSphereTrees : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedMeshSphereTrees, BothBuildersCoverEveryLevelAndKeepTheTreeInvariants) {
  const std::string name = GetParam();
  if (test::sanitizerRun() && name == "stanford-bunny.obj") GTEST_SKIP() << "69k triangles: Release run only";
  // Closed smooth meshes add no code path under sanitizers that fandisk (closed, sharp), rocker-arm
  // (genus > 0), teapot, suzanne and bunny-1500 (open, non-manifold) do not already take.
  if (test::sanitizerRun() && (name == "spot.obj" || name == "cow.obj")) GTEST_SKIP() << "Release run only";
  const LoadedMesh loaded = loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / name);
  // The 69k-triangle bunny checks the default builders only (its default medial build runs the
  // merge/burst reduction on every node already), to keep the runner short.
  checkBothBuilders(loaded.mesh, test::sanitizerRun() ? 5000 : 50000, name != "stanford-bunny.obj");
}

INSTANTIATE_TEST_SUITE_P(Corpus, SharedMeshSphereTrees,
                         ::testing::Values("spot.obj", "fandisk.obj", "rocker-arm.obj", "cow.obj", "bunny-1500.obj",
                                           "teapot.obj", "suzanne.obj", "stanford-bunny.obj"),
                         test::meshParamName);

TEST(PrimitiveSphereTrees, BothBuildersCoverBoxesIcospheresAndCylinders) {
  const std::size_t samples = test::sanitizerRun() ? 3000 : 20000;
  {
    SCOPED_TRACE("flat box");
    checkBothBuilders(makeBox(Vec3(2.0, 1.0, 0.05)), samples);
  }
  {
    SCOPED_TRACE("icosphere");
    checkBothBuilders(makeIcosphere(1.5, 3), samples);
  }
  {
    SCOPED_TRACE("cylinder");
    checkBothBuilders(makeCylinder(0.3, 3.0, 32), samples);
  }
}

TEST(PrimitiveSphereTrees, FlatMeshesWithoutVolumeAreCovered) {
  // All samples in one plane: qhull cannot tetrahedralise them, and there is no medial axis.
  TriangleMesh square;
  square.vertices = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0), Vec3(0, 1, 0), Vec3(1, 0.5, 0)};
  square.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  checkBothBuilders(square, 2000);
}

TEST(PrimitiveSphereTrees, DegenerateTrianglesAreAssignedAndCovered) {
  // A box plus a zero-area sliver triangle (three collinear points) sticking out of it.
  TriangleMesh mesh = makeBox(Vec3(1, 1, 1));
  const auto base = mesh.vertexCount();
  mesh.vertices.push_back(Vec3(1.0, 0.0, 0.0));
  mesh.vertices.push_back(Vec3(1.5, 0.0, 0.0));
  mesh.vertices.push_back(Vec3(2.0, 0.0, 0.0));
  mesh.triangles.push_back({base, base + 1, base + 2});
  checkBothBuilders(mesh, 2000);
}

}  // namespace
}  // namespace clod
