// The compact contact-tree encoding (codec version 6, docs/bake-format.md): the decoded tree is
// the built tree bit for bit, its field stays within eps_s of a brute-force distance over all
// triangles, and the stored values are the exact distances rounded by at most half a step.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <tbb/parallel_for.h>

#include "clod/contact_tree_codec.h"
#include "clod/error.h"
#include "contact_tree/lattice.h"
#include "tree_cache.h"

namespace clod {
namespace {

using test::sharedTree;

ContactTree roundTrip(const ContactTree& tree, std::size_t* bytes = nullptr) {
  ByteWriter writer;
  encodeContactTree(tree, writer);
  if (bytes) *bytes = writer.size();
  ByteReader reader(writer.bytes().data(), writer.size(), "test");
  ContactTree decoded = decodeContactTree(reader);
  EXPECT_TRUE(reader.atEnd());
  return decoded;
}

template <class T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Unsigned distance from p to the mesh by visiting every triangle: independent of the BVH and
// of the sign logic of MeshDistance, which built the tree.
double bruteForceDistance(const TriangleMesh& mesh, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t)
    best = std::min(best, closestPointOnTriangle(p, mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)).distanceSquared);
  return std::sqrt(best);
}

TEST(ContactTreeCompactCodec, DecodedTreeIsTheBuiltTreeBitForBit) {
  const auto& built = sharedTree("spot.obj");
  std::size_t bytes = 0;
  const ContactTree decoded = roundTrip(built.tree, &bytes);
  EXPECT_TRUE(sameBytes(decoded.levelOffsets, built.tree.levelOffsets));
  EXPECT_TRUE(sameBytes(decoded.errorCode, built.tree.errorCode));
  EXPECT_TRUE(sameBytes(decoded.lattice, built.tree.lattice));
  EXPECT_TRUE(sameBytes(decoded.halfSpaces, built.tree.halfSpaces));
  EXPECT_TRUE(sameBytes(decoded.nodeWords, built.tree.nodeWords));
  EXPECT_TRUE(sameBytes(decoded.flatSurface, built.tree.flatSurface));
  EXPECT_EQ(std::memcmp(decoded.rootCorners.data(), built.tree.rootCorners.data(), sizeof(decoded.rootCorners)), 0);
  // What the arrays would take as plain floats (codec version 2: 2 bits + a 16-bit code per
  // node, 19 floats per split node, 5 floats per half-space); the compact stream must be
  // several times smaller, or the rounding and prediction are not doing their job.
  const double plain = 2.25 * double(built.tree.nodeCount()) + 4.0 * double(built.tree.lattice.size()) + 20.0 * double(built.tree.halfSpaces.size());
  RecordProperty("bytes", std::to_string(bytes));
  RecordProperty("plainBytes", std::to_string(plain));
  EXPECT_LT(double(bytes), plain / 4.0) << bytes << " bytes vs " << plain << " as floats";
}

TEST(ContactTreeCompactCodec, DecodedFieldIsWithinEpsOfBruteForceDistanceInTheBand) {
  const auto& built = sharedTree("spot.obj");
  const ContactTree decoded = roundTrip(built.tree);
  const TriangleMesh& mesh = built.exact->mesh();
  const auto prefix = test::areaPrefix(mesh);
  const int count = test::sanitizerRun() ? 300 : 3000;
  std::mt19937_64 rng(2026);
  std::vector<Vec3> points(count);
  for (Vec3& p : points) p = test::randomBandPoint(mesh, prefix, decoded.bandAbs, rng);
  std::vector<double> reference(count);
  tbb::parallel_for(0, count, [&](int i) { reference[i] = bruteForceDistance(mesh, points[i]); });
  double maxError = 0.0;
  for (int i = 0; i < count; ++i) {
    // ||a| - |b|| <= |a - b|: the unsigned comparison is implied by the signed guarantee.
    const double error = std::abs(std::abs(decoded.distance(points[i])) - reference[i]);
    maxError = std::max(maxError, error);
  }
  RecordProperty("maxErrorRel", std::to_string(maxError / decoded.meshDiagonal));
  // eps_s holds in the band by construction (measured with the stored, rounded values); float
  // corners add at most 2^-23 of the diagonal (contact_tree_accuracy_test.cpp).
  EXPECT_LE(maxError, decoded.errorAbs + std::ldexp(decoded.meshDiagonal, -23)) << maxError / decoded.meshDiagonal << " diag";
}

TEST(ContactTreeCompactCodec, StoredLatticeValuesAreTheExactDistanceWithinHalfAStep) {
  const auto& built = sharedTree("spot.obj");
  const ContactTree& tree = built.tree;
  const double step = tree.valueStep();
  ASSERT_GT(step, 0.0);
  EXPECT_LE(step, tree.errorAbs / 8.0);
  EXPECT_GT(step, tree.errorAbs / 16.0);
  std::vector<ContactCell> stack{tree.rootCell()};
  std::size_t checked = 0;
  double worst = 0.0;
  while (!stack.empty() && checked < 20'000) {
    const ContactCell cell = stack.back();
    stack.pop_back();
    if (tree.isLeaf(cell.node)) continue;
    for (std::uint32_t o = 0; o < 8; ++o) {
      const ContactCell child = tree.childCell(cell, o);
      // Every corner of the child but the one it shares with its parent (c == o) is one of the
      // 19 values the parent stores.
      for (std::uint32_t c = 0; c < 8; ++c) {
        if (c == o) continue;
        const Vec3 p = tree.cellMin(child) + tree.cellSize(child.depth) * Vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        const double exact = built.exact->signedDistance(p);
        const double error = std::abs(child.corners[c] - exact);
        worst = std::max(worst, error / step);
        // Half a step of rounding plus the float rounding of the stored value.
        EXPECT_LE(error, 0.5 * step + std::ldexp(std::abs(exact), -23)) << p.transpose();
        ++checked;
      }
      stack.push_back(child);
    }
  }
  RecordProperty("worstInSteps", std::to_string(worst));
  EXPECT_GT(checked, 1000u);
}

// Version 6 codes a lattice point that two split neighbours share once (the second says "the
// same"), and a half-space normal a face neighbour has as a pick. Neighbours that disagree at a
// shared point must still come back bit for bit: every third split node of the middle depths
// gets its +x face centre and an edge midpoint moved by one value step (still on the codec's
// grid) where only plain leaves use them, so the neighbour on that side holds another value
// there.
TEST(ContactTreeCompactCodec, NeighboursThatDisagreeAtASharedPointRoundTripBitForBit) {
  const auto& built = sharedTree("spot.obj");
  ContactTree tree = built.tree;
  std::vector<ContactCell> stack{tree.rootCell()};
  std::size_t moved = 0, visited = 0;
  while (!stack.empty()) {
    const ContactCell cell = stack.back();
    stack.pop_back();
    if (tree.isLeaf(cell.node)) continue;
    for (std::uint32_t o = 0; o < 8; ++o) stack.push_back(tree.childCell(cell, o));
    if (cell.depth < 3 || cell.depth + 2 > tree.depthCount() || ++visited % 3 != 0) continue;
    const std::size_t block = (tree.firstChild(cell.node) - 1) / 8;
    const double step = detail::latticeStep(tree, cell.depth);
    for (const int l : {14, 5}) {  // (2, 1, 1): the +x face's centre; (2, 1, 0): an edge's midpoint
      // Only where the children at the point are leaves without a half-space: the rest store
      // their values relative to their corners, which would no longer be on the grid.
      bool plainLeaves = true;
      for (std::uint32_t o = 0; o < 8; ++o) {
        const bool touches = (o & 1) && (l == 14 || ((o >> 2) & 1) == 0);
        const ContactCell child = tree.childCell(cell, o);
        if (touches && (!tree.isLeaf(child.node) || tree.halfSpace(child.node))) plainLeaves = false;
      }
      if (!plainLeaves) continue;
      float& v = tree.lattice[block * kContactTreeLatticePerNode + detail::kLatticeSlot[l]];
      const double prediction = detail::latticePrediction(cell.corners, l);
      // Toward 0: no child's corners then prove it far from the surface when they did not.
      v = detail::storedValue(prediction, detail::residualUnits(v, prediction, step) + (v > 0.0f ? -1 : 1), step);
      ++moved;
    }
  }
  ASSERT_GT(moved, 300u);
  const ContactTree decoded = roundTrip(tree);
  EXPECT_TRUE(sameBytes(decoded.lattice, tree.lattice));
  EXPECT_TRUE(sameBytes(decoded.halfSpaces, tree.halfSpaces));
  EXPECT_TRUE(sameBytes(decoded.errorCode, tree.errorCode));
  EXPECT_TRUE(sameBytes(decoded.nodeWords, tree.nodeWords));
}

TEST(ContactTreeCompactCodec, EncoderRefusesValuesItCannotStoreExactly) {
  const auto& built = sharedTree("spot.obj");
  auto refused = [](const ContactTree& tree) {
    try {
      ByteWriter writer;
      encodeContactTree(tree, writer);
    } catch (const Error& e) {
      return e.code() == ErrorCode::kInvalidArgument;
    }
    return false;
  };
  ContactTree offGrid = built.tree;
  offGrid.lattice[5] = std::nextafter(offGrid.lattice[5], 1e30f);  // not prediction + k steps
  EXPECT_TRUE(refused(offGrid));
  ContactTree tilted = built.tree;
  ASSERT_FALSE(tilted.halfSpaces.empty());
  tilted.halfSpaces[0].normal[0] = std::nextafter(tilted.halfSpaces[0].normal[0], 2.0f);  // no octahedral code
  EXPECT_TRUE(refused(tilted));
}

TEST(ContactTreeCompactCodec, OlderVersionsAskForARebake) {
  const auto& built = sharedTree("spot.obj");
  ByteWriter writer;
  encodeContactTree(built.tree, writer);
  // 2: the float-array layout; 3: the first coding (no cap bit, no lattice contexts); 5: every
  // lattice value coded by every node that holds it.
  for (const int version : {2, 3, 5}) {
    std::vector<std::byte> bytes = writer.bytes();
    bytes[0] = std::byte(version);  // the codec's own u32 version, little-endian
    ByteReader reader(bytes.data(), bytes.size(), "old");
    try {
      (void)decodeContactTree(reader);
      ADD_FAILURE() << "a version-" << version << " payload was decoded";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kBakeVersion);
      EXPECT_NE(std::string(e.what()).find("re-bake"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace clod
