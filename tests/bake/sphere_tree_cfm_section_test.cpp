// The compact 'STRE' (version 2) and 'CFMP' (version 2) sections on trees and maps from the
// library's builders. Oracles: the tree and map that were encoded -- a decoded sphere must still
// contain every surface point its original contained (brute force over every triangle of the
// mesh), and the decoded map's normals must equal the built ones (the codec adds no angle).
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "bake/cfm_section.h"
#include "bake/mesh_section.h"
#include "bake/sphere_tree_section.h"
#include "bake_test_support.h"
#include "clod/proximity.h"
#include "clod/normal_encoding.h"
#include "clod/sphere_tree_builder.h"

namespace clod {
namespace {

using test::thrownCode;

// An off-centre, non-uniformly scaled icosphere (320 triangles) joined by an off-origin box:
// curved and flat parts, coordinates not on any power-of-two grid.
TriangleMesh testMesh() {
  TriangleMesh mesh = makeIcosphere(1.0, 2);
  for (Vec3& v : mesh.vertices) v = Vec3(2.0 * v.x() + 0.3, v.y() - 1.0, 0.5 * v.z() + 4.0);
  TriangleMesh box = makeBox(Vec3(0.7, 0.45, 0.3));
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const Vec3& v : box.vertices) mesh.vertices.push_back(v + Vec3(3.1, -0.4, 4.2));
  for (Triangle t : box.triangles) {
    for (auto& index : t) index += base;
    mesh.triangles.push_back(t);
  }
  return mesh;
}

struct Built {
  TriangleMesh mesh = testMesh();
  MeshDistance distance{mesh};
  SphereTree tree;
  Built(SphereTreeMethod method) {
    SphereTreeSettings settings;
    settings.method = method;
    settings.branching = 8;
    settings.depth = 3;
    settings.medialSamples = 2000;
    tree = buildSphereTree(distance, settings);
  }
};

SphereTree roundTrip(const SphereTree& tree, std::uint32_t triangleCount) {
  const std::vector<std::byte> bytes = detail::encodeSphereTreeSection(tree, {});
  return detail::decodeSphereTreeSection(bytes, triangleCount, kBakeSphereTreeVersion).tree;
}

class CompactSphereTree : public ::testing::TestWithParam<SphereTreeMethod> {};

TEST_P(CompactSphereTree, DecodedSphereContainsEverySurfacePointItsOriginalContained) {
  const Built built(GetParam());
  const SphereTree decoded = roundTrip(built.tree, built.mesh.triangleCount());
  test::expectDecodedSpheresContainOriginals(built.tree, decoded);
  // Brute force: points on a barycentric grid of every triangle (corners, edges, interior),
  // against every sphere. No tolerance: containment is exact by construction (the codec rounds
  // the radius up past |c' - c| + r), so one point lost is a failure.
  constexpr int kSteps = 6;
  std::size_t pointsInside = 0;
  for (std::uint32_t s = 0; s < built.tree.sphereCount(); ++s) {
    const Vec3 c = built.tree.center(s), cDecoded = decoded.center(s);
    const double r = built.tree.radius[s], rDecoded = decoded.radius[s];
    for (std::uint32_t t = 0; t < built.mesh.triangleCount(); ++t) {
      const Vec3 a = built.mesh.corner(t, 0), b = built.mesh.corner(t, 1), d = built.mesh.corner(t, 2);
      for (int i = 0; i <= kSteps; ++i) {
        for (int j = 0; i + j <= kSteps; ++j) {
          const Vec3 x = a + (b - a) * (double(i) / kSteps) + (d - a) * (double(j) / kSteps);
          if ((x - c).norm() > r) continue;
          ++pointsInside;
          ASSERT_LE((x - cDecoded).norm(), rDecoded) << "sphere " << s << ", triangle " << t << " point (" << i << ", " << j << ")";
        }
      }
    }
  }
  EXPECT_GT(pointsInside, built.mesh.triangleCount()) << "the spheres contained almost nothing: the test checked little";
  // Idempotent: the decoded tree is on the grid, so it encodes to the same bytes.
  EXPECT_EQ(detail::encodeSphereTreeSection(decoded, {}), detail::encodeSphereTreeSection(built.tree, {}));
}

TEST_P(CompactSphereTree, StructureSurvivesExactlyAndTheSectionIsSmall) {
  const Built built(GetParam());
  const SphereTree decoded = roundTrip(built.tree, built.mesh.triangleCount());
  EXPECT_EQ(decoded.parent, built.tree.parent);
  EXPECT_EQ(decoded.firstChild, built.tree.firstChild);
  EXPECT_EQ(decoded.childCount, built.tree.childCount);
  EXPECT_EQ(decoded.triangleOffsets, built.tree.triangleOffsets);
  EXPECT_EQ(decoded.triangleList, built.tree.triangleList);
  EXPECT_EQ(decoded.levelOffsets, built.tree.levelOffsets);
  // Version 1 took 48 bytes per sphere and 4 per triangle reference; the coded section must
  // take less than a third of that (measured ~6-8x less on the shared meshes, bake.md).
  const std::size_t plain = 48 * built.tree.sphereCount() + 4 * built.tree.triangleList.size();
  EXPECT_LT(detail::encodeSphereTreeSection(built.tree, {}).size(), plain / 3);
}

INSTANTIATE_TEST_SUITE_P(Methods, CompactSphereTree, ::testing::Values(SphereTreeMethod::kOctree, SphereTreeMethod::kMedial),
                         [](const auto& param) { return std::string(param.param == SphereTreeMethod::kOctree ? "Octree" : "Medial"); });

class CompactCfm : public ::testing::TestWithParam<NormalCodec> {};

TEST_P(CompactCfm, DecodedNormalsEqualTheBuiltOnes) {
  const Built built(SphereTreeMethod::kMedial);
  ClosestFeatureMapSettings settings;
  settings.codec = GetParam();
  const ClosestFeatureMap map = buildClosestFeatureMap(built.distance, built.tree, settings);
  const ClosestFeatureMap decoded =
      detail::decodeCfmSection(detail::encodeCfmSection(map), built.tree, kBakeCfmVersion);
  const ClosestFeatureMapData& a = map.data();
  const ClosestFeatureMapData& b = decoded.data();
  EXPECT_EQ(a.levelStacks, b.levelStacks);
  EXPECT_EQ(a.sphereOffset, b.sphereOffset);
  EXPECT_EQ(a.sphereSingle, b.sphereSingle);
  ASSERT_EQ(a.codes16.size() + a.codes32.size(), b.codes16.size() + b.codes32.size());
  // The section is lossless, so the stated angle it adds is 0: every stored normal decodes to
  // the same direction as the built one (compared as directions, not only as codes).
  for (std::uint32_t s = 0; s < built.tree.sphereCount(); ++s) {
    for (std::uint32_t k = 0; k < map.storedNormalCount(s); ++k) {
      ASSERT_EQ(map.storedNormal(s, k), decoded.storedNormal(s, k)) << "sphere " << s << " sample " << k;
    }
  }
  ASSERT_EQ(a.averageNormals.size(), b.averageNormals.size());
  for (std::size_t i = 0; i < a.averageNormals.size(); ++i) {
    ASSERT_EQ(std::memcmp(&a.averageNormals[i], &b.averageNormals[i], sizeof(float)), 0) << "average normal component " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Codecs, CompactCfm, ::testing::Values(NormalCodec::kOctahedral16, NormalCodec::kOctahedral32),
                         [](const auto& param) { return std::string(normalCodecName(param.param)); });

// Bakes written before the compact sections: version 1 of STRE or CFMP says "re-bake".
TEST(CompactSections, VersionOnePayloadsAreRefusedWithReBake) {
  const BakeContents contents = test::makeTestContents();
  const std::vector<std::byte> plain = encodeBake(contents);
  const BakeFileReader reader(plain);
  BakeFileWriter writer;
  for (const BakeSectionEntry& e : reader.entries()) {
    const auto payload = reader.section(e.tag, e.version).payload;
    writer.addSection(e.tag, e.tag == kBakeSphereTreeTag ? 1 : e.version, {payload.begin(), payload.end()});
  }
  const std::vector<std::byte> old = writer.encode();
  try {
    decodeBake(old);
    ADD_FAILURE() << "a version-1 STRE section was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBakeVersion);
    EXPECT_NE(std::string(e.what()).find("re-bake"), std::string::npos) << e.what();
  }
  const Built built(SphereTreeMethod::kOctree);
  const ClosestFeatureMap map = buildClosestFeatureMap(built.distance, built.tree, {});
  EXPECT_EQ(thrownCode([&] { detail::decodeCfmSection(detail::encodeCfmSection(map), built.tree, 1); }), ErrorCode::kBakeVersion);
}

}  // namespace
}  // namespace clod
