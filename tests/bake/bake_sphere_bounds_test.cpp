// Issue 21, B17: a bake edited so that its spheres no longer bound the mesh (checksums
// recomputed) must be refused, not loaded to report "no collision". Oracle: the edits move a
// sphere by ten bounding-box diagonals, so by the triangle inequality no vertex it lists can lie
// within its radius (at most one diagonal for a sphere of a valid tree, whose centre lies near the
// mesh); the tests pick only spheres whose triangles no other sphere of the level covers.
#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "bake/mesh_section.h"
#include "bake/sphere_tree_section.h"
#include "bake_test_support.h"
#include "clod/mesh_io.h"

namespace clod {
namespace {

using test::thrownCode;

BakeContents realBake() {
  TriangleMesh mesh = makeIcosphere(1.0, 2);
  for (Vec3& v : mesh.vertices) v = Vec3(2.0 * v.x() + 0.3, v.y() - 1.0, 0.5 * v.z() + 4.0);
  BakeSettings settings;
  settings.sphereTree.depth = 2;
  settings.sphereTree.medialSamples = 2000;
  settings.measureFit = false;
  settings.buildClosestFeatureMap = settings.buildContactTree = false;
  return bakeMesh(mesh, settings).contents;
}

// The file encodeBake would write, without encodeBake's own refusal: what an editor that
// recomputes the checksums produces.
std::vector<std::byte> encodeUnchecked(const BakeContents& c) {
  BakeFileWriter writer;
  writer.addSection(kBakeMeshTag, kBakeMeshVersion, detail::encodeMeshSection(c.mesh, meshContentHash(c.mesh), c.sourceName));
  writer.addSection(kBakeSphereTreeTag, kBakeSphereTreeVersion, detail::encodeSphereTreeSection(c.sphereTree, c.sphereTreeSettings));
  return writer.encode();
}

void moveSphere(SphereTree& tree, std::uint32_t i, double by) { tree.centerX[i] += by; }

// Both doors refuse it: decodeBake (kBakeCorrupt) and encodeBake (kInvalidArgument), each naming
// the sphere and its level.
void expectRefused(const BakeContents& edited, const std::string& sphereAndLevel) {
  try {
    decodeBake(encodeUnchecked(edited));
    ADD_FAILURE() << "decodeBake accepted a tree that does not bound its mesh";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBakeCorrupt);
    EXPECT_NE(std::string(e.what()).find(sphereAndLevel), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not contain vertex"), std::string::npos) << e.what();
  }
  EXPECT_EQ(thrownCode([&] { encodeBake(edited); }), ErrorCode::kInvalidArgument);
}

TEST(BakeSphereBounds, AnUneditedBakeRoundTrips) {
  const BakeContents original = realBake();
  EXPECT_NO_THROW(decodeBake(encodeBake(original)));
}

TEST(BakeSphereBounds, ARootMovedTenDiagonalsIsRefused) {
  BakeContents edited = realBake();
  moveSphere(edited.sphereTree, 0, 10.0 * edited.mesh.bounds().diagonal());
  expectRefused(edited, "sphere 0 (level 0)");
}

TEST(BakeSphereBounds, ARootMovedByTenMetresAsInTheAuditIsRefused) {
  // The audit's edit: centerX[0] += 10 on a bake of metre-sized geometry.
  BakeContents edited = realBake();
  moveSphere(edited.sphereTree, 0, 10.0);
  expectRefused(edited, "sphere 0 (level 0)");
}

TEST(BakeSphereBounds, AChildMovedOutOfItsParentIsRefusedOnItsLevel) {
  const BakeContents original = realBake();
  const SphereTree& tree = original.sphereTree;
  ASSERT_GE(tree.levelCount(), 3u);
  const double far = 10.0 * original.mesh.bounds().diagonal();
  for (std::uint32_t level : {1u, tree.levelCount() - 1}) {
    // A sphere of the level with a triangle no other sphere of the level lists: moved away, no
    // sphere of the level covers that triangle's corners.
    std::map<std::uint32_t, int> listings;
    for (std::uint32_t i = tree.levelBegin(level); i < tree.levelEnd(level); ++i)
      for (std::uint32_t k = tree.triangleOffsets[i]; k < tree.triangleOffsets[i + 1]; ++k) ++listings[tree.triangleList[k]];
    std::uint32_t chosen = kNoSphere;
    for (std::uint32_t i = tree.levelBegin(level); i < tree.levelEnd(level) && chosen == kNoSphere; ++i)
      for (std::uint32_t k = tree.triangleOffsets[i]; k < tree.triangleOffsets[i + 1]; ++k)
        if (listings[tree.triangleList[k]] == 1) chosen = i;
    ASSERT_NE(chosen, kNoSphere) << "level " << level;
    BakeContents edited = original;
    moveSphere(edited.sphereTree, chosen, far);
    expectRefused(edited, "sphere " + std::to_string(chosen) + " (level " + std::to_string(level) + ")");
  }
}

TEST(BakeSphereBounds, ALevelThatStopsListingATriangleIsRefused) {
  // Spheres that still contain everything but drop a triangle from the deepest level's lists:
  // the level no longer covers the surface (the CFM would never search that triangle).
  BakeContents edited = test::makeTestContents();  // brute-force tree: one leaf per triangle
  SphereTree& tree = edited.sphereTree;
  const std::uint32_t leaf = tree.levelEnd(tree.levelCount() - 1) - 1;
  ASSERT_EQ(tree.triangleOffsets[leaf + 1] - tree.triangleOffsets[leaf], 1u);
  const std::uint32_t dropped = tree.triangleList[tree.triangleOffsets[leaf]];
  // Give the leaf the previous leaf's triangle instead (lists stay sorted and structurally valid).
  tree.triangleList[tree.triangleOffsets[leaf]] = tree.triangleList[tree.triangleOffsets[leaf] - 1];
  tree.radius[leaf] = 100.0;  // and let it contain everything
  try {
    decodeBake(encodeUnchecked(edited));
    ADD_FAILURE() << "decodeBake accepted a level that does not list triangle " << dropped;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBakeCorrupt);
    EXPECT_NE(std::string(e.what()).find("lists triangle " + std::to_string(dropped)), std::string::npos) << e.what();
  }
}

TEST(BakeSphereBounds, EverySharedMeshBakesAndLoads) {
  // The check must pass every valid bake: both builders on the shared corpus (closed, open,
  // non-manifold), at a reduced depth to keep the runner short.
  namespace fs = std::filesystem;
  std::size_t meshes = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(CLOD_SHARED_MESH_DIR)) {
    if (entry.path().extension() != ".obj") continue;
    const TriangleMesh mesh = loadMesh(entry.path()).mesh;
    ++meshes;
    // Under the sanitizers the meshes up to 10k triangles (closed, open and non-manifold ones):
    // the Stanford bunny's 69k, the rocker arm's 20k and the fandisk's 13k took most of this
    // runner's time there and run no other code path.
    if (test::sanitizerRun() && mesh.triangleCount() > 10000) continue;
    for (SphereTreeMethod method : {SphereTreeMethod::kOctree, SphereTreeMethod::kMedial}) {
      SCOPED_TRACE(entry.path().filename().string() + " " + sphereTreeMethodName(method));
      BakeSettings settings;
      settings.sphereTree.method = method;
      settings.sphereTree.depth = test::sanitizerRun() ? 2 : 3;
      settings.sphereTree.medialSamples = 3000;
      settings.measureFit = false;
      settings.buildClosestFeatureMap = settings.buildContactTree = false;  // the check reads the tree only
      const BakeContents baked = bakeMesh(mesh, settings).contents;
      EXPECT_NO_THROW(decodeBake(encodeBake(baked)));
    }
  }
  EXPECT_GE(meshes, 8u);
}

}  // namespace
}  // namespace clod
