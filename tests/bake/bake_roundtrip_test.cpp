// Bake contents survive encode -> decode -> encode bit-exactly, through memory and through files.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <gtest/gtest.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "bake_test_support.h"

namespace clod {
namespace {

using test::expectSameContents;
using test::makeTestContents;
using test::thrownCode;

TEST(BakeRoundTrip, DecodedContentsEqualTheOriginalFieldByField) {
  const BakeContents original = makeTestContents();
  const BakeContents decoded = decodeBake(encodeBake(original));
  // The fixture's tree is not on the file's grid: its spheres come back grown, never shrunk.
  expectSameContents(original, decoded, test::SphereValues::kContained);
  // A decoded tree is on the grid: a second round trip is bit-exact.
  expectSameContents(decoded, decodeBake(encodeBake(decoded)));
}

TEST(BakeRoundTrip, ReEncodingADecodedFileGivesIdenticalBytes) {
  const std::vector<std::byte> bytes = encodeBake(makeTestContents());
  EXPECT_EQ(encodeBake(decodeBake(bytes)), bytes);
}

TEST(BakeRoundTrip, SpecialValuesSurviveBitExactly) {
  BakeContents contents = makeTestContents();
  contents.mesh.vertices[0].x() = -0.0;
  contents.mesh.vertices[1].y() = 5e-324;  // smallest subnormal
  contents.mesh.vertices[2].z() = 1.7976931348623157e308;
  contents.sphereTree.radius.back() = 0.0;
  contents.sourceName = std::string("n\0l\xff", 4);  // arbitrary bytes, not just text
  contents.sphereTreeSettings = {SphereTreeMethod::kMedial, 3, 9, 4321};
  contents.sphereTreeSettings.medialReduction = MedialReduction::kKMeans;
  const BakeContents decoded = decodeBake(encodeBake(contents));
  contents.meshHash = meshContentHash(contents.mesh);
  expectSameContents(contents, decoded, test::SphereValues::kContained);
}

TEST(BakeRoundTrip, EncodeIgnoresAStaleMeshHash) {
  BakeContents contents = makeTestContents();
  const std::uint64_t right = contents.meshHash;
  contents.meshHash = 12345;
  EXPECT_EQ(decodeBake(encodeBake(contents)).meshHash, right);
}

// The hash is defined in bake.h; recompute it here from that definition.
TEST(MeshContentHash, FollowsTheDocumentedDefinition) {
  const TriangleMesh mesh = makeTestContents().mesh;
  std::vector<std::byte> stream;
  auto append = [&](const void* data, std::size_t size) {
    const auto* p = static_cast<const std::byte*>(data);
    stream.insert(stream.end(), p, p + size);
  };
  const std::uint64_t counts[2] = {mesh.vertices.size(), mesh.triangles.size()};
  append(counts, sizeof(counts));
  for (const Vec3& v : mesh.vertices)
    for (int k = 0; k < 3; ++k) append(&v[k], 8);
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) append(&t[k], 4);
  EXPECT_EQ(meshContentHash(mesh), XXH3_64bits(stream.data(), stream.size()));
}

TEST(MeshContentHash, ChangesWithOneCoordinateBitOrOneIndex) {
  const TriangleMesh mesh = makeTestContents().mesh;
  TriangleMesh moved = mesh;
  moved.vertices[7].y() = std::nextafter(moved.vertices[7].y(), 100.0);
  TriangleMesh rewired = mesh;
  std::swap(rewired.triangles[3][0], rewired.triangles[3][1]);
  EXPECT_NE(meshContentHash(mesh), meshContentHash(moved));
  EXPECT_NE(meshContentHash(mesh), meshContentHash(rewired));
  EXPECT_EQ(meshContentHash(mesh), meshContentHash(TriangleMesh(mesh)));
}

TEST(BakeRoundTrip, UnknownSectionsAreSkipped) {
  const BakeContents original = makeTestContents();
  // Rebuild the file with an extra section in front, as a newer writer might.
  const std::vector<std::byte> plain = encodeBake(original);
  const BakeFileReader reader(plain);
  BakeFileWriter writer;
  writer.addSection(makeBakeSectionTag("ZZZZ"), 7, std::vector<std::byte>(123, std::byte{0x5a}));
  for (const BakeSectionEntry& e : reader.entries()) {
    const auto payload = reader.section(e.tag, e.version).payload;
    writer.addSection(e.tag, e.version, {payload.begin(), payload.end()});
  }
  expectSameContents(original, decodeBake(writer.encode()), test::SphereValues::kContained);
}

TEST(BakeRoundTrip, MissingRequiredSectionsAreReported) {
  const std::vector<std::byte> plain = encodeBake(makeTestContents());
  const BakeFileReader reader(plain);
  for (BakeSectionTag dropped : {kBakeMeshTag, kBakeSphereTreeTag}) {
    BakeFileWriter writer;
    for (const BakeSectionEntry& e : reader.entries()) {
      if (e.tag == dropped) continue;
      const auto payload = reader.section(e.tag, e.version).payload;
      writer.addSection(e.tag, e.version, {payload.begin(), payload.end()});
    }
    const auto bytes = writer.encode();
    EXPECT_EQ(thrownCode([&] { decodeBake(bytes); }), ErrorCode::kBakeMissingSection) << bakeSectionTagName(dropped);
  }
}

TEST(BakeRoundTrip, KnownSectionWithNewerVersionIsAVersionError) {
  const std::vector<std::byte> plain = encodeBake(makeTestContents());
  const BakeFileReader reader(plain);
  BakeFileWriter writer;
  for (const BakeSectionEntry& e : reader.entries()) {
    const auto payload = reader.section(e.tag, e.version).payload;
    writer.addSection(e.tag, e.tag == kBakeSphereTreeTag ? kBakeSphereTreeVersion + 1 : e.version, {payload.begin(), payload.end()});
  }
  const auto bytes = writer.encode();
  EXPECT_EQ(thrownCode([&] { decodeBake(bytes); }), ErrorCode::kBakeVersion);
}

class BakeFiles : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("clod_bake_test_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(BakeFiles, SaveThenLoadRoundTripsAndLeavesOnlyTheFile) {
  const BakeContents original = makeTestContents();
  const auto path = dir_ / "mesh.clod";
  const std::size_t written = saveBake(path, original);
  EXPECT_EQ(written, std::filesystem::file_size(path));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), std::filesystem::directory_iterator{}), 1);
  expectSameContents(original, loadBake(path), test::SphereValues::kContained);
}

TEST_F(BakeFiles, SaveIntoAMissingDirectoryFailsAndLeavesNothing) {
  const auto path = dir_ / "no-such-dir" / "mesh.clod";
  EXPECT_EQ(thrownCode([&] { saveBake(path, makeTestContents()); }), ErrorCode::kFileWriteFailed);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "no-such-dir"));
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

TEST_F(BakeFiles, FailedSaveKeepsTheExistingFileIntact) {
  const auto path = dir_ / "mesh.clod";
  saveBake(path, makeTestContents());
  const auto before = std::filesystem::file_size(path);
  BakeContents broken = makeTestContents();
  broken.sphereTree.radius[0] = -1.0;
  EXPECT_EQ(thrownCode([&] { saveBake(path, broken); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(std::filesystem::file_size(path), before);
  EXPECT_NO_THROW(loadBake(path));
}

TEST_F(BakeFiles, LoadReportsMissingEmptyAndDirectoryPaths) {
  EXPECT_EQ(thrownCode([&] { loadBake(dir_ / "absent.clod"); }), ErrorCode::kFileNotFound);
  std::ofstream(dir_ / "empty.clod").close();
  EXPECT_EQ(thrownCode([&] { loadBake(dir_ / "empty.clod"); }), ErrorCode::kEmptyFile);
  EXPECT_EQ(thrownCode([&] { loadBake(dir_); }), ErrorCode::kFileUnreadable);
}

TEST_F(BakeFiles, LoadErrorsNameThePath) {
  const auto path = dir_ / "cut.clod";
  const auto bytes = encodeBake(makeTestContents());
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), 100);
  try {
    loadBake(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBakeTruncated);
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace clod
