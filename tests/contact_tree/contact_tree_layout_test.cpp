// The compact node encoding (bitmaps with rank counts, 16-bit error codes) against brute-force
// oracles: children and half-space indices counted node by node, error codes against the
// float value they must bound.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "clod/bit_count.h"
#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

namespace clod {
namespace {

// The rank queries' population count against counting the bits one by one.
TEST(ContactTreeRank, PopcountCountsEveryBit) {
  auto oneByOne = [](std::uint64_t x) {
    std::uint32_t n = 0;
    for (int b = 0; b < 64; ++b) n += (x >> b) & 1u;
    return n;
  };
  std::vector<std::uint64_t> words = {0, ~std::uint64_t{0}, 1, std::uint64_t{1} << 63, 0x5555555555555555ull,
                                      0xaaaaaaaaaaaaaaaaull, 0x8000000000000001ull};
  std::mt19937_64 rng(5);
  for (int i = 0; i < 10000; ++i) words.push_back(rng() & rng());  // sparser words too
  for (int i = 0; i < 10000; ++i) words.push_back(rng());
  for (std::uint64_t w : words) ASSERT_EQ(detail::popcount64(w), oneByOne(w)) << std::hex << w;
}

TEST(ContactTreeErrorCode, DecodedBoundIsNeverBelowTheRatioAndAtMostOneMantissaStepAbove) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> exponent(-40.0, 10.0);
  for (int bits : {ContactTree::kErrorMantissaBits, 7}) {
    for (int i = 0; i < 100000; ++i) {
      const double ratio = std::exp2(exponent(rng));
      const std::uint16_t code = ContactTree::encodeErrorRatio(ratio, bits);
      const double decoded = ContactTree::decodeErrorRatio(code);
      ASSERT_GE(decoded, ratio) << ratio;
      // With m explicit mantissa bits the next code up is at most 2^-m larger.
      ASSERT_LE(decoded, ratio * (1.0 + std::ldexp(1.0, -bits))) << ratio << " with " << bits << " bits";
      if (bits == ContactTree::kErrorMantissaBits) {
        ASSERT_TRUE(ContactTree::isCoarseErrorCode(code)) << std::hex << code;
      }
    }
  }
}

TEST(ContactTreeErrorCode, ZeroOneAndHugeRatiosAreExactOrFinite) {
  for (int bits : {ContactTree::kErrorMantissaBits, 7}) {
    EXPECT_EQ(ContactTree::decodeErrorRatio(ContactTree::encodeErrorRatio(0.0, bits)), 0.0f);
    EXPECT_EQ(ContactTree::decodeErrorRatio(ContactTree::encodeErrorRatio(1.0, bits)), 1.0f);
    EXPECT_EQ(ContactTree::decodeErrorRatio(ContactTree::encodeErrorRatio(0.5, bits)), 0.5f);
    const float huge = ContactTree::decodeErrorRatio(ContactTree::encodeErrorRatio(1e300, bits));
    EXPECT_TRUE(std::isfinite(huge) && huge > 1e38f) << bits;
  }
  EXPECT_EQ(ContactTree::encodeErrorRatio(1e300), ContactTree::kMaxErrorCode);
}

// A box tree with a few thousand nodes spread over several 64-node words.
const ContactTree& smallTree() {
  static const ContactTree tree = [] {
    ContactTreeSettings settings;
    settings.errorRel = 5e-3;
    settings.maxDepth = 7;
    return buildContactTree(MeshDistance(makeBox(Vec3(1.0, 0.6, 0.35))), settings);
  }();
  return tree;
}

TEST(ContactTreeLayout, ChildrenAndHalfSpacesMatchANodeByNodeCount) {
  const ContactTree& tree = smallTree();
  ASSERT_GT(tree.nodeCount(), 1000u);
  std::uint32_t interiorSoFar = 0, surfaceSoFar = 0;
  for (std::uint32_t node = 0; node < tree.nodeCount(); ++node) {
    const bool split = (tree.nodeWords[node / 64].interior >> (node % 64)) & 1u;
    const bool surface = (tree.nodeWords[node / 64].surface >> (node % 64)) & 1u;
    ASSERT_EQ(tree.isLeaf(node), !split) << node;
    ASSERT_EQ(tree.firstChild(node), split ? 1 + 8 * interiorSoFar : 0u) << node;
    ASSERT_EQ(tree.halfSpaceIndex(node), surface ? surfaceSoFar : kNoHalfSpace) << node;
    interiorSoFar += split;
    surfaceSoFar += surface;
  }
  EXPECT_EQ(tree.lattice.size(), std::size_t{interiorSoFar} * kContactTreeLatticePerNode);
  EXPECT_EQ(tree.halfSpaces.size(), surfaceSoFar);
  // Breadth-first: the last interior node's children are the last eight nodes.
  EXPECT_EQ(1 + 8 * interiorSoFar, tree.nodeCount());
}

TEST(ContactTreeLayout, ChildCellsTileTheirParentAndInheritTheSharedCorner) {
  const ContactTree& tree = smallTree();
  std::vector<ContactCell> stack{tree.rootCell()};
  std::size_t visited = 0;
  while (!stack.empty()) {
    const ContactCell cell = stack.back();
    stack.pop_back();
    ++visited;
    // Every stored bound is a bound of a cell of this size: at most half its diagonal plus
    // half a value step for the rounded corners, i.e. the far-leaf bound (the box is closed,
    // so no cell is discontinuous), and that is at most 1/16 of eps above D/2.
    const double lipschitz = 0.5 * std::sqrt(3.0) * tree.cellSize(cell.depth) + 0.5 * tree.valueStep();
    ASSERT_LE(tree.errorBound(cell.node, cell.depth), lipschitz * (1.0 + 1.0 / 128)) << cell.node;
    if (tree.isLeaf(cell.node)) continue;
    for (std::uint32_t o = 0; o < 8; ++o) {
      const ContactCell child = tree.childCell(cell, o);
      ASSERT_EQ(child.node, tree.firstChild(cell.node) + o);
      ASSERT_EQ(child.corners[o], cell.corners[o]);
      stack.push_back(child);
    }
  }
  EXPECT_EQ(visited, tree.nodeCount());
}

TEST(ContactTreeLayout, NodesCostAtLeastNineAndAHalfBytesLessThanWithIndexArrays) {
  // The previous encoding (codec version 1) held per node a u32 child index, an f32 error bound
  // and a u32 half-space index (12 B); the bitmaps cost 24 B per 64 nodes and the error code
  // 2 B, so at least 12 - 2 - 0.375 = 9.625 B per node must be saved, everything else equal.
  const ContactTree& tree = smallTree();
  const double n = tree.nodeCount();
  const double version1 = 12.0 * n + sizeof(float) * double(tree.lattice.size()) +
                          sizeof(ContactHalfSpace) * double(tree.halfSpaces.size()) +
                          sizeof(std::uint32_t) * double(tree.levelOffsets.size()) + sizeof(tree.rootCorners) +
                          sizeof(std::uint32_t) * double(tree.gridNode.size()) + sizeof(float) * double(tree.gridCorners.size()) +
                          sizeof(std::uint64_t) * double(tree.flatSurface.size());  // derived, as the grid
  EXPECT_LE(double(tree.memoryBytes()), version1 - 9.5 * n);
}

}  // namespace
}  // namespace clod
