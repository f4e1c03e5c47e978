// Damaged bake files: flipped bytes, truncations, and payloads that pass their checksums but
// break the semantic invariants. Each must give a clod::Error, never a crash or wrong contents.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include "bake/mesh_section.h"
#include "bake/sphere_tree_section.h"
#include "bake_test_support.h"

namespace clod {
namespace {

using test::expectSameContents;
using test::makeTestContents;
using test::thrownCode;

// Decodes `bytes`; either it throws clod::Error, or it must decode to what `original` encodes to
// (a change that does not alter the content). Returns true if it threw.
bool rejectsOrPreserves(const std::vector<std::byte>& bytes, const BakeContents& original, const std::string& what) {
  try {
    const BakeContents decoded = decodeBake(bytes);
    SCOPED_TRACE(what + " decoded without error");
    expectSameContents(original, decoded, test::SphereValues::kContained);
    return false;
  } catch (const Error&) {
    return true;
  }
}

// Positions to damage: every byte of the header and table, and every byte of the payloads
// for a small file (or an even spread of a few hundred for a large one).
std::vector<std::size_t> damagePositions(const std::vector<std::byte>& file, std::size_t payloadSamples) {
  const std::size_t tableEnd = 48 + 32 * BakeFileReader(file).entries().size();
  std::set<std::size_t> positions;
  for (std::size_t i = 0; i < tableEnd; ++i) positions.insert(i);
  const std::size_t rest = file.size() - tableEnd;
  const std::size_t step = std::max<std::size_t>(1, rest / payloadSamples);
  for (std::size_t i = tableEnd; i < file.size(); i += step) positions.insert(i);
  positions.insert(file.size() - 1);
  return {positions.begin(), positions.end()};
}

TEST(BakeCorruption, EveryFlippedByteIsRejected) {
  const BakeContents original = makeTestContents();
  const std::vector<std::byte> file = encodeBake(original);
  const std::size_t samples = test::sanitizerRun() ? 300 : file.size();
  const auto positions = damagePositions(file, samples);
  ASSERT_GE(positions.size(), std::min<std::size_t>(300, file.size()));
  std::size_t rejected = 0;
  for (std::size_t at : positions) {
    for (unsigned mask : {0x01u, 0x80u, 0xffu}) {
      std::vector<std::byte> damaged = file;
      damaged[at] ^= std::byte(mask);
      rejected += rejectsOrPreserves(damaged, original, "byte " + std::to_string(at) + " ^ " + std::to_string(mask));
    }
  }
  // Every byte is covered by a checksum or must be zero padding, so nothing slips through.
  EXPECT_EQ(rejected, positions.size() * 3);
}

TEST(BakeCorruption, EveryTruncationIsTruncatedOrCorrupt) {
  const BakeContents original = makeTestContents();
  const std::vector<std::byte> file = encodeBake(original);
  const std::size_t step = test::sanitizerRun() ? 7 : 1;
  for (std::size_t length = 0; length < file.size(); length += step) {
    const std::vector<std::byte> cut(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(length));
    const ErrorCode code = thrownCode([&] { decodeBake(cut); });
    EXPECT_TRUE(code == ErrorCode::kBakeTruncated || code == ErrorCode::kBakeCorrupt) << "length " << length;
    if (length >= 8) {
      EXPECT_EQ(code, ErrorCode::kBakeTruncated) << "length " << length << ": a cut file is reported as cut";
    }
  }
}

// Builds a file whose checksums are valid but whose sphere-tree payload is the given one.
std::vector<std::byte> fileWithSphereTree(const BakeContents& contents, const SphereTree& tree) {
  BakeFileWriter writer;
  writer.addSection(kBakeMeshTag, kBakeMeshVersion,
                    detail::encodeMeshSection(contents.mesh, meshContentHash(contents.mesh), contents.sourceName));
  writer.addSection(kBakeSphereTreeTag, kBakeSphereTreeVersion,
                    detail::encodeSphereTreeSection(tree, contents.sphereTreeSettings));
  return writer.encode();
}

void expectCorruptMentioning(const std::vector<std::byte>& bytes, const std::string& field) {
  try {
    decodeBake(bytes);
    ADD_FAILURE() << field << ": accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBakeCorrupt) << e.what();
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << "message does not name " << field << ": " << e.what();
  }
}

TEST(BakeCorruption, BrokenSphereTreeInvariantsAreCorruptionNamingTheField) {
  const BakeContents contents = makeTestContents();
  const SphereTree& good = contents.sphereTree;
  const std::uint32_t last = good.sphereCount() - 1;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* field;
    void (*edit)(SphereTree&, std::uint32_t, double);
  };
  const Case cases[] = {
      {"radius", [](SphereTree& t, std::uint32_t, double) { t.radius[2] = -0.5; }},
      {"radius", [](SphereTree& t, std::uint32_t, double n) { t.radius[2] = n; }},
      {"centre", [](SphereTree& t, std::uint32_t, double) { t.centerY[3] = std::numeric_limits<double>::infinity(); }},
      {"centerZ", [](SphereTree& t, std::uint32_t, double) { t.centerZ.pop_back(); }},
      {"levelOffsets", [](SphereTree& t, std::uint32_t, double) { t.levelOffsets.back() += 1; }},
      {"levelOffsets", [](SphereTree& t, std::uint32_t, double) { t.levelOffsets[1] = 2; }},
      {"levelOffsets", [](SphereTree& t, std::uint32_t, double) { t.levelOffsets[2] = t.levelOffsets[1]; }},
      {"triangleOffsets", [](SphereTree& t, std::uint32_t, double) { std::swap(t.triangleOffsets[2], t.triangleOffsets[3]); }},
      {"triangleOffsets", [](SphereTree& t, std::uint32_t, double) { t.triangleOffsets.back() -= 1; }},
      {"triangleList", [](SphereTree& t, std::uint32_t, double) { t.triangleList[5] = 80; }},
      {"child", [](SphereTree& t, std::uint32_t last_, double) { t.firstChild[1] = last_; }},
      {"child", [](SphereTree& t, std::uint32_t, double) { t.childCount[1] += 1; }},
      {"parent", [](SphereTree& t, std::uint32_t last_, double) { t.parent[last_] = 0; }},
      {"parent", [](SphereTree& t, std::uint32_t, double) { t.parent[0] = 0; }},
      {"deepest level", [](SphereTree& t, std::uint32_t last_, double) { t.childCount[last_] = 1; t.firstChild[last_] = last_; }},
      {"no spheres", [](SphereTree& t, std::uint32_t, double) { t = SphereTree{}; }},
  };
  for (const Case& c : cases) {
    SphereTree broken = good;
    c.edit(broken, last, nan);
    SCOPED_TRACE(c.field);
    expectCorruptMentioning(fileWithSphereTree(contents, broken), c.field);
  }
  // The unchanged tree passes, so the cases above fail for their edit alone.
  EXPECT_NO_THROW(decodeBake(fileWithSphereTree(contents, good)));
}

TEST(BakeCorruption, UnknownSphereTreeMethodOrMedialReductionIsCorruption) {
  const BakeContents contents = makeTestContents();
  auto fileWithSettings = [&](const SphereTreeSettings& settings) {
    BakeFileWriter writer;
    writer.addSection(kBakeMeshTag, kBakeMeshVersion, detail::encodeMeshSection(contents.mesh, meshContentHash(contents.mesh), ""));
    writer.addSection(kBakeSphereTreeTag, kBakeSphereTreeVersion, detail::encodeSphereTreeSection(contents.sphereTree, settings));
    return writer.encode();
  };
  SphereTreeSettings badMethod = contents.sphereTreeSettings;
  badMethod.method = static_cast<SphereTreeMethod>(7);
  expectCorruptMentioning(fileWithSettings(badMethod), "method");
  SphereTreeSettings badReduction = contents.sphereTreeSettings;
  badReduction.medialReduction = static_cast<MedialReduction>(3);
  expectCorruptMentioning(fileWithSettings(badReduction), "medial reduction");
}

TEST(BakeCorruption, BrokenMeshInvariantsAreCorruptionNamingTheCulprit) {
  const BakeContents contents = makeTestContents();
  auto fileWithMesh = [&](const TriangleMesh& mesh, std::uint64_t hash) {
    BakeFileWriter writer;
    writer.addSection(kBakeMeshTag, kBakeMeshVersion, detail::encodeMeshSection(mesh, hash, ""));
    writer.addSection(kBakeSphereTreeTag, kBakeSphereTreeVersion,
                      detail::encodeSphereTreeSection(contents.sphereTree, contents.sphereTreeSettings));
    return writer.encode();
  };
  TriangleMesh badIndex = contents.mesh;
  badIndex.triangles[4][2] = 9001;
  expectCorruptMentioning(fileWithMesh(badIndex, meshContentHash(badIndex)), "triangle 4: vertex index 9001");
  TriangleMesh nanVertex = contents.mesh;
  nanVertex.vertices[6].x() = std::numeric_limits<double>::quiet_NaN();
  expectCorruptMentioning(fileWithMesh(nanVertex, meshContentHash(nanVertex)), "vertex 6");
  expectCorruptMentioning(fileWithMesh(contents.mesh, meshContentHash(contents.mesh) + 1), "hash");
  // Fewer triangles than the sphere-tree refers to.
  TriangleMesh fewer = contents.mesh;
  fewer.triangles.resize(40);
  expectCorruptMentioning(fileWithMesh(fewer, meshContentHash(fewer)), "triangleList");
}

TEST(BakeCorruption, EncodeRefusesContentsItCouldNotDecode) {
  BakeContents contents = makeTestContents();
  contents.sphereTree.parent[4] = 99;
  EXPECT_EQ(thrownCode([&] { encodeBake(contents); }), ErrorCode::kInvalidArgument);
  contents = makeTestContents();
  contents.mesh.triangles[0][0] = contents.mesh.vertexCount();
  EXPECT_EQ(thrownCode([&] { encodeBake(contents); }), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace clod
