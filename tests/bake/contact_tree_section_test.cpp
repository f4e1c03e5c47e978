// The 'CTRE' section: bakeMesh builds the contact tree, the bake stores it bit-exactly, and
// damaged or mismatched CTRE payloads are rejected. The field itself is checked against the
// analytic signed distance of a box, so the test does not trust the builder's own answers.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "bake/mesh_section.h"
#include "bake/sphere_tree_section.h"
#include "bake_test_support.h"
#include "clod/byte_stream.h"
#include "clod/contact_tree_codec.h"

namespace clod {
namespace {

using test::expectSameContents;
using test::thrownCode;

const Vec3 kBoxHalf(1.0, 0.6, 0.35);
const Vec3 kBoxCenter(0.4, -2.0, 3.25);

// An off-origin box: its exact signed distance is known in closed form (below).
TriangleMesh boxMesh() {
  TriangleMesh mesh = makeBox(kBoxHalf);
  for (Vec3& v : mesh.vertices) v += kBoxCenter;
  return mesh;
}

// Signed distance of the axis-aligned box, negative inside: outside, the length of the
// positive part of q = |p - c| - h; inside, the largest (least negative) component of q.
double exactBoxDistance(const Vec3& p) {
  const Vec3 q = (p - kBoxCenter).cwiseAbs() - kBoxHalf;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

BakeSettings smallSettings() {
  BakeSettings settings;
  settings.sphereTree.branching = 8;
  settings.sphereTree.depth = 2;
  settings.measureFit = false;
  settings.sourceName = "box";
  return settings;
}

std::vector<std::byte> treeBytes(const ContactTree& tree) {
  ByteWriter writer;
  encodeContactTree(tree, writer);
  return writer.take();
}

// A file with MESH, STRE and the given CTRE payload, resealed (valid checksums), so only the
// semantic checks of the CTRE decoder can object.
std::vector<std::byte> fileWithTreePayload(const BakeContents& contents, std::vector<std::byte> payload,
                                           std::uint32_t version = kBakeContactTreeVersion) {
  BakeFileWriter writer;
  writer.addSection(kBakeMeshTag, kBakeMeshVersion,
                    detail::encodeMeshSection(contents.mesh, meshContentHash(contents.mesh), contents.sourceName));
  writer.addSection(kBakeSphereTreeTag, kBakeSphereTreeVersion,
                    detail::encodeSphereTreeSection(contents.sphereTree, contents.sphereTreeSettings));
  writer.addSection(kBakeContactTreeTag, version, std::move(payload));
  return writer.encode();
}

std::string thrownMessage(const std::vector<std::byte>& bytes) {
  try {
    decodeBake(bytes);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

class BakeContactTree : public ::testing::Test {
protected:
  static void SetUpTestSuite() { baked_ = new BakeResult(bakeMesh(boxMesh(), smallSettings())); }
  static void TearDownTestSuite() {
    delete baked_;
    baked_ = nullptr;
  }
  static BakeResult* baked_;
};
BakeResult* BakeContactTree::baked_ = nullptr;

TEST_F(BakeContactTree, DefaultBakeBuildsTheTreeWithTheBuildersDefaults) {
  ASSERT_TRUE(baked_->contents.contactTree.has_value());
  const ContactTree& tree = *baked_->contents.contactTree;
  const double diagonal = boxMesh().bounds().diagonal();
  EXPECT_EQ(tree.errorAbs, ContactTreeSettings{}.errorRel * diagonal);
  EXPECT_EQ(tree.maxDepth, ContactTreeSettings{}.maxDepth);
  EXPECT_EQ(tree.meshDiagonal, diagonal);
  EXPECT_EQ(baked_->contactTreeStats.nodes, tree.nodeCount());
  EXPECT_GT(baked_->timings.contactTreeSeconds, 0.0);
  EXPECT_GE(baked_->timings.buildSeconds, baked_->timings.contactTreeSeconds + baked_->timings.cfmSeconds);
}

TEST_F(BakeContactTree, RoundTripIsBitExactAndThePayloadIsTheCodecsEncoding) {
  const std::vector<std::byte> bytes = encodeBake(baked_->contents);
  const BakeFileReader file(bytes);
  const std::optional<BakeSection> section = file.findSection(kBakeContactTreeTag, kBakeContactTreeVersion);
  ASSERT_TRUE(section.has_value());
  const std::vector<std::byte> expected = treeBytes(*baked_->contents.contactTree);
  ASSERT_EQ(section->payload.size(), expected.size());
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), section->payload.begin()));

  const BakeContents decoded = decodeBake(bytes);
  expectSameContents(baked_->contents, decoded);
  EXPECT_EQ(encodeBake(decoded), bytes);
}

// Analytic oracle: at random points within the tree's band around the box surface, the baked
// field must agree with the exact box distance to within the stopping cell's error bound (the
// bound the tree documents) plus float rounding: corner values are stored as f32, so each carries
// up to 2^-24 relative error of a value <= rootSize; 1e-6 * diagonal covers that with margin.
TEST_F(BakeContactTree, LoadedFieldMatchesTheAnalyticBoxDistance) {
  const BakeContents loaded = decodeBake(encodeBake(baked_->contents));
  const ContactTree& tree = *loaded.contactTree;
  const double diagonal = boxMesh().bounds().diagonal();
  const double rounding = 1e-6 * diagonal;
  std::mt19937_64 rng(20261121);
  const Vec3 lo = kBoxCenter - kBoxHalf - Vec3::Constant(tree.bandAbs);
  const Vec3 hi = kBoxCenter + kBoxHalf + Vec3::Constant(tree.bandAbs);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int wanted = test::sanitizerRun() ? 500 : 5000;
  int tested = 0;
  while (tested < wanted) {
    const Vec3 p(lo.x() + unit(rng) * (hi.x() - lo.x()), lo.y() + unit(rng) * (hi.y() - lo.y()),
                 lo.z() + unit(rng) * (hi.z() - lo.z()));
    const double exact = exactBoxDistance(p);
    if (std::abs(exact) > tree.bandAbs) continue;
    ++tested;
    const ContactFieldSample s = tree.sample(p);
    ASSERT_TRUE(s.insideRoot);
    ASSERT_LE(std::abs(s.distance - exact), s.errorBound + rounding)
        << "at (" << p.x() << ", " << p.y() << ", " << p.z() << "), depth " << s.depth;
    // Coarser answers stay within their own (larger) bounds.
    const ContactFieldSample coarse = tree.sample(p, 2);
    ASSERT_LE(coarse.depth, 2u);
    ASSERT_LE(std::abs(coarse.distance - exact), coarse.errorBound + rounding);
  }
}

TEST(BakeContactTreeSettings, SwitchedOffLeavesNoTreeAndNoSection) {
  BakeSettings settings = smallSettings();
  settings.buildContactTree = false;
  const BakeResult result = bakeMesh(boxMesh(), settings);
  EXPECT_FALSE(result.contents.contactTree.has_value());
  EXPECT_EQ(result.timings.contactTreeSeconds, 0.0);
  EXPECT_EQ(result.contactTreeStats.nodes, 0u);
  const std::vector<std::byte> bytes = encodeBake(result.contents);
  EXPECT_FALSE(BakeFileReader(bytes).findSection(kBakeContactTreeTag, kBakeContactTreeVersion).has_value());
  EXPECT_FALSE(decodeBake(bytes).contactTree.has_value());
}

TEST(BakeContactTreeSettings, SettingsReachTheBuilderAndBadOnesAreInvalidArguments) {
  BakeSettings settings = smallSettings();
  settings.buildClosestFeatureMap = false;
  settings.contactTree.errorRel = 1e-2;
  settings.contactTree.maxDepth = 4;
  const BakeResult result = bakeMesh(boxMesh(), settings);
  ASSERT_TRUE(result.contents.contactTree.has_value());
  EXPECT_EQ(result.contents.contactTree->errorAbs, 1e-2 * boxMesh().bounds().diagonal());
  EXPECT_EQ(result.contents.contactTree->maxDepth, 4u);
  EXPECT_LE(result.contents.contactTree->depthCount(), 5u);

  settings.contactTree.errorRel = 0.0;
  EXPECT_EQ(thrownCode([&] { bakeMesh(boxMesh(), settings); }), ErrorCode::kInvalidArgument);
  settings.contactTree.errorRel = 1e-2;
  settings.contactTree.maxDepth = 0;
  EXPECT_EQ(thrownCode([&] { bakeMesh(boxMesh(), settings); }), ErrorCode::kInvalidArgument);
}

// A tree built for a slightly larger box: valid on its own, wrong for this mesh.
ContactTree treeOfAnotherMesh() {
  TriangleMesh other = makeBox(kBoxHalf * 1.01);
  for (Vec3& v : other.vertices) v += kBoxCenter;
  ContactTreeSettings settings;
  settings.errorRel = 1e-2;
  settings.maxDepth = 4;
  return buildContactTree(MeshDistance(other), settings);
}

TEST_F(BakeContactTree, EncodeRefusesATreeOfAnotherMeshOrWithBrokenInvariants) {
  BakeContents contents = baked_->contents;
  contents.contactTree = treeOfAnotherMesh();
  EXPECT_EQ(thrownCode([&] { encodeBake(contents); }), ErrorCode::kInvalidArgument);

  contents.contactTree = baked_->contents.contactTree;
  ASSERT_GT(contents.contactTree->nodeCount(), 9u);
  contents.contactTree->nodeWords[0].interior &= ~std::uint64_t{1};  // a leaf root with 8 children
  EXPECT_EQ(thrownCode([&] { encodeBake(contents); }), ErrorCode::kInvalidArgument);

  contents.contactTree = baked_->contents.contactTree;
  contents.contactTree->lattice.pop_back();
  EXPECT_EQ(thrownCode([&] { encodeBake(contents); }), ErrorCode::kInvalidArgument);
}

TEST_F(BakeContactTree, FileWithATreeOfAnotherMeshIsCorruptionNamingTheSection) {
  const std::vector<std::byte> file = fileWithTreePayload(baked_->contents, treeBytes(treeOfAnotherMesh()));
  EXPECT_EQ(thrownCode([&] { decodeBake(file); }), ErrorCode::kBakeCorrupt);
  const std::string message = thrownMessage(file);
  EXPECT_NE(message.find("CTRE"), std::string::npos) << message;
  EXPECT_NE(message.find("meshDiagonal"), std::string::npos) << message;
}

TEST_F(BakeContactTree, TrailingOrMissingPayloadBytesAndNewerVersionsAreRejected) {
  std::vector<std::byte> payload = treeBytes(*baked_->contents.contactTree);
  // As written, the hand-assembled file decodes (the test's construction is sound).
  ASSERT_TRUE(decodeBake(fileWithTreePayload(baked_->contents, payload)).contactTree.has_value());

  std::vector<std::byte> longer = payload;
  longer.resize(longer.size() + 8, std::byte{0});
  EXPECT_EQ(thrownCode([&] { decodeBake(fileWithTreePayload(baked_->contents, longer)); }), ErrorCode::kBakeCorrupt);

  std::vector<std::byte> shorter(payload.begin(), payload.end() - 4);
  EXPECT_EQ(thrownCode([&] { decodeBake(fileWithTreePayload(baked_->contents, shorter)); }), ErrorCode::kBakeTruncated);

  EXPECT_EQ(thrownCode([&] { decodeBake(fileWithTreePayload(baked_->contents, payload, kBakeContactTreeVersion + 1)); }),
            ErrorCode::kBakeVersion);
  std::vector<std::byte> innerNewer = payload;
  innerNewer[0] = std::byte{kContactTreeCodecVersion + 1};  // the codec's own u32 version, little-endian
  EXPECT_EQ(thrownCode([&] { decodeBake(fileWithTreePayload(baked_->contents, innerNewer)); }), ErrorCode::kBakeVersion);
  // Files from before the compact encoding (codec version 2: float arrays; version 1: 32-bit
  // child indices) and from its earlier codings (versions 3 and 4: error codes with 7 mantissa
  // bits, finer half-spaces) must not be misread as the current layout: they are refused by
  // version, with a message saying so and asking for a re-bake.
  for (std::uint8_t old : {std::uint8_t{1}, std::uint8_t{2}, std::uint8_t{3}, std::uint8_t{4}}) {
    std::vector<std::byte> innerOld = payload;
    innerOld[0] = std::byte{old};
    const std::vector<std::byte> oldFile = fileWithTreePayload(baked_->contents, innerOld);
    EXPECT_EQ(thrownCode([&] { decodeBake(oldFile); }), ErrorCode::kBakeVersion);
    const std::string message = thrownMessage(oldFile);
    EXPECT_NE(message.find("version " + std::to_string(old) + " is not the supported version " + std::to_string(kContactTreeCodecVersion)), std::string::npos) << message;
    EXPECT_NE(message.find("re-bake"), std::string::npos) << message;
  }
}

// Bytes flipped inside the payload with valid checksums (a hostile or buggy writer): every
// result is either an error or a tree whose queries are memory-safe and finite (ASan checks the
// former). Many flips (a lattice value's low bit) legitimately give a different valid tree.
TEST_F(BakeContactTree, ResealedPayloadFlipsAreRejectedOrGiveASafeTree) {
  const std::vector<std::byte> payload = treeBytes(*baked_->contents.contactTree);
  // Every header byte (the first 100) then an even spread over the rest; under the sanitizers,
  // where a decode of this tree costs ~0.6 s (45 ms in Release), every third header byte and 40
  // spread flips. The fuzz target fuzz_bake_load covers random damage beyond these.
  const bool sanitized = test::sanitizerRun();
  const std::size_t headerStride = sanitized ? 3 : 1, spread = sanitized ? 40 : 250;
  const std::size_t headerFlips = (100 + headerStride - 1) / headerStride, samples = headerFlips + spread;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  // Fields no valid variation of which exists for this mesh (codec layout, contact_tree_codec.h):
  // version [0,4), meshDiagonal [36,44) (tied to the mesh), maxDepth [60,64) (0x40 takes it
  // past 20), node count, depth count and the coded stream's length [96,112) (no longer what
  // the stream holds).
  auto mustReject = [](std::size_t at) {
    return at < 4 || (at >= 36 && at < 44) || (at >= 60 && at < 64) || (at >= 96 && at < 112);
  };
  for (std::size_t k = 0; k < samples; ++k) {
    const std::size_t at = k < headerFlips ? k * headerStride : 100 + (k - headerFlips) * (payload.size() - 100) / spread;
    std::vector<std::byte> damaged = payload;
    damaged[at] ^= std::byte{0x40};
    try {
      const BakeContents decoded = decodeBake(fileWithTreePayload(baked_->contents, damaged));
      const ContactTree& tree = *decoded.contactTree;
      for (int q = 0; q < 20; ++q) {
        const Vec3 p = kBoxCenter + 1.5 * Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(kBoxHalf);
        const ContactFieldSample s = tree.sample(p);
        ASSERT_TRUE(std::isfinite(s.distance) && s.gradient.allFinite() && std::isfinite(s.errorBound))
            << "flip at payload byte " << at;
      }
      EXPECT_FALSE(mustReject(at)) << "flip at payload byte " << at << " was accepted";
    } catch (const Error&) {
    }
  }
}

}  // namespace
}  // namespace clod
