// bakeMesh with the library's real builders, and damage to a real bake file.
#include <algorithm>

#include <gtest/gtest.h>

#include "bake_test_support.h"

namespace clod {
namespace {

using test::expectSameContents;
using test::thrownCode;

BakeSettings smallSettings(SphereTreeMethod method) {
  BakeSettings settings;
  settings.sphereTree.method = method;
  settings.sphereTree.branching = 8;
  settings.sphereTree.depth = 2;
  settings.sphereTree.medialSamples = 2000;
  settings.sourceName = "icosphere";
  return settings;
}

// An off-centre, non-uniformly scaled icosphere: small (320 triangles) but not symmetric.
TriangleMesh testMesh() {
  TriangleMesh mesh = makeIcosphere(1.0, 2);
  for (Vec3& v : mesh.vertices) v = Vec3(2.0 * v.x() + 0.3, v.y() - 1.0, 0.5 * v.z() + 4.0);
  return mesh;
}

class BakeMesh : public ::testing::TestWithParam<SphereTreeMethod> {};

TEST_P(BakeMesh, BuildsTheRequestedLevelsAndRoundTripsBitExactly) {
  const TriangleMesh mesh = testMesh();
  const BakeSettings settings = smallSettings(GetParam());
  const BakeResult result = bakeMesh(mesh, settings);

  // The bake keeps the mesh as given and hashes it.
  EXPECT_EQ(result.contents.mesh.triangles, mesh.triangles);
  ASSERT_EQ(result.contents.mesh.vertices.size(), mesh.vertices.size());
  EXPECT_TRUE(std::equal(mesh.vertices.begin(), mesh.vertices.end(), result.contents.mesh.vertices.begin()));
  EXPECT_EQ(result.contents.meshHash, meshContentHash(mesh));
  EXPECT_EQ(result.contents.sourceName, "icosphere");
  EXPECT_EQ(result.contents.sphereTreeSettings.method, GetParam());

  // depth levels below the root, so depth + 1 levels, and a fit entry per level.
  const SphereTree& tree = result.contents.sphereTree;
  ASSERT_EQ(tree.levelCount(), settings.sphereTree.depth + 1);
  ASSERT_EQ(result.levelFit.size(), tree.levelCount());
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    EXPECT_EQ(result.levelFit[l].spheres, tree.levelEnd(l) - tree.levelBegin(l)) << "level " << l;
  }
  EXPECT_EQ(result.signMethod, SignMethod::kPseudonormal) << "a closed icosphere";
  EXPECT_GT(result.timings.buildSeconds, 0.0);

  // Brute-force oracle: every level covers every vertex. Tolerance: 1e-9 of the diagonal,
  // the margin the builders add to radii against rounding (sphere_tree_builder.h).
  const double tolerance = 1e-9 * mesh.bounds().diagonal();
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
      bool covered = false;
      for (std::uint32_t s = tree.levelBegin(l); s < tree.levelEnd(l) && !covered; ++s) {
        covered = (mesh.vertices[v] - tree.center(s)).norm() <= tree.radius[s] + tolerance;
      }
      ASSERT_TRUE(covered) << "vertex " << v << " outside every sphere of level " << l;
    }
  }

  const std::vector<std::byte> bytes = encodeBake(result.contents);
  const BakeContents decoded = decodeBake(bytes);
  expectSameContents(result.contents, decoded);
  EXPECT_EQ(encodeBake(decoded), bytes);
}

INSTANTIATE_TEST_SUITE_P(Methods, BakeMesh, ::testing::Values(SphereTreeMethod::kOctree, SphereTreeMethod::kMedial),
                         [](const ::testing::TestParamInfo<SphereTreeMethod>& p) { return std::string(sphereTreeMethodName(p.param)); });

TEST(BakeMeshSettings, OutOfRangeSettingsAreInvalidArguments) {
  BakeSettings settings = smallSettings(SphereTreeMethod::kOctree);
  settings.sphereTree.branching = 1;
  EXPECT_EQ(thrownCode([&] { bakeMesh(testMesh(), settings); }), ErrorCode::kInvalidArgument);
}

TEST(BakeMeshSettings, SkippingFitMeasurementLeavesItEmpty) {
  BakeSettings settings = smallSettings(SphereTreeMethod::kOctree);
  settings.measureFit = false;
  const BakeResult result = bakeMesh(testMesh(), settings);
  EXPECT_TRUE(result.levelFit.empty());
  EXPECT_EQ(result.timings.fitSeconds, 0.0);
}

// The damage tests of bake_corruption_test.cpp, on a file the real builders produced.
TEST(BakeCorruption, FlippedBytesAndTruncationsOfARealBakeAreRejected) {
  const BakeContents original = bakeMesh(testMesh(), smallSettings(SphereTreeMethod::kMedial)).contents;
  const std::vector<std::byte> file = encodeBake(original);
  // The default bake carries every optional section, so the damage reaches the CFMP and CTRE
  // payloads too.
  ASSERT_TRUE(original.closestFeatureMap.has_value());
  ASSERT_TRUE(original.contactTree.has_value());
  ASSERT_EQ(BakeFileReader(file).entries().size(), 4u);
  const std::size_t tableEnd = 48 + 32 * BakeFileReader(file).entries().size();
  std::vector<std::size_t> positions;
  for (std::size_t i = 0; i < tableEnd; ++i) positions.push_back(i);
  const std::size_t samples = test::sanitizerRun() ? 200 : 600;
  for (std::size_t k = 0; k < samples; ++k) positions.push_back(tableEnd + k * (file.size() - tableEnd) / samples);
  positions.push_back(file.size() - 1);
  for (std::size_t at : positions) {
    std::vector<std::byte> damaged = file;
    damaged[at] ^= std::byte{0x10};
    try {
      const BakeContents decoded = decodeBake(damaged);
      ADD_FAILURE() << "flip at byte " << at << " of " << file.size() << " was accepted";
    } catch (const Error&) {
    }
  }
  const std::size_t step = std::max<std::size_t>(1, file.size() / (test::sanitizerRun() ? 300 : 3000));
  for (std::size_t length = 0; length < file.size(); length += step) {
    const std::vector<std::byte> cut(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(length));
    const ErrorCode code = thrownCode([&] { decodeBake(cut); });
    EXPECT_TRUE(code == ErrorCode::kBakeTruncated || code == ErrorCode::kBakeCorrupt) << "length " << length;
  }
}

}  // namespace
}  // namespace clod
