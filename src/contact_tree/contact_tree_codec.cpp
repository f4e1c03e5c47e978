#include "clod/contact_tree_codec.h"

#include <cmath>
#include <string>

#include "clod/error.h"

namespace clod {

static_assert(sizeof(ContactHalfSpace) == 20, "half-spaces are encoded as 5 packed floats");

void encodeContactTree(const ContactTree& tree, ByteWriter& out) {
  out.write<std::uint32_t>(kContactTreeCodecVersion);
  for (int a = 0; a < 3; ++a) out.write<double>(tree.origin[a]);
  out.write<double>(tree.rootSize);
  out.write<double>(tree.meshDiagonal);
  out.write<double>(tree.errorAbs);
  out.write<double>(tree.bandAbs);
  out.write<std::uint32_t>(tree.maxDepth);
  for (float v : tree.rootCorners) out.write<float>(v);
  out.writeArray(tree.firstChild);
  out.writeArray(tree.errorBound);
  out.writeArray(tree.halfSpaceIndex);
  out.writeArray(tree.levelOffsets);
  out.writeArray(tree.lattice);
  out.writeArray(tree.halfSpaces);
}

ContactTree decodeContactTree(ByteReader& in) {
  auto fail = [&](const std::string& what) { in.fail("contact tree: " + what); };
  const auto version = in.read<std::uint32_t>();
  if (version != kContactTreeCodecVersion) {
    throw Error(ErrorCode::kBakeVersion, in.context() + ": contact tree: version " + std::to_string(version) +
                                             " is not the supported version " + std::to_string(kContactTreeCodecVersion));
  }
  ContactTree tree;
  for (int a = 0; a < 3; ++a) tree.origin[a] = in.read<double>();
  tree.rootSize = in.read<double>();
  tree.meshDiagonal = in.read<double>();
  tree.errorAbs = in.read<double>();
  tree.bandAbs = in.read<double>();
  tree.maxDepth = in.read<std::uint32_t>();
  for (float& v : tree.rootCorners) v = in.read<float>();
  tree.firstChild = in.readArray<std::uint32_t>();
  tree.errorBound = in.readArray<float>();
  tree.halfSpaceIndex = in.readArray<std::uint32_t>();
  tree.levelOffsets = in.readArray<std::uint32_t>();
  tree.lattice = in.readArray<float>();
  tree.halfSpaces = in.readArray<ContactHalfSpace>();

  if (!tree.origin.allFinite()) fail("origin is not finite");
  if (!(std::isfinite(tree.rootSize) && tree.rootSize > 0.0)) fail("rootSize " + std::to_string(tree.rootSize) + " is not finite and > 0");
  if (!(std::isfinite(tree.meshDiagonal) && tree.meshDiagonal >= 0.0)) fail("meshDiagonal is not finite and >= 0");
  if (!(std::isfinite(tree.errorAbs) && tree.errorAbs > 0.0)) fail("errorAbs is not finite and > 0");
  if (!(std::isfinite(tree.bandAbs) && tree.bandAbs >= 0.0)) fail("bandAbs is not finite and >= 0");
  if (tree.maxDepth < 1 || tree.maxDepth > 20) fail("maxDepth " + std::to_string(tree.maxDepth) + " is outside 1..20");
  for (int c = 0; c < 8; ++c)
    if (!std::isfinite(tree.rootCorners[c])) fail("rootCorners[" + std::to_string(c) + "] is not finite");

  const std::size_t n = tree.firstChild.size();
  if (n == 0) fail("no nodes");
  if (n > 0xfffffff0u) fail("node count " + std::to_string(n) + " exceeds 32-bit indices");
  if (tree.errorBound.size() != n) fail("errorBound has " + std::to_string(tree.errorBound.size()) + " entries for " + std::to_string(n) + " nodes");
  if (tree.halfSpaceIndex.size() != n) fail("halfSpaceIndex has " + std::to_string(tree.halfSpaceIndex.size()) + " entries for " + std::to_string(n) + " nodes");

  // Breadth-first layout: the k-th interior node (in node order) has its children at 1 + 8k,
  // which is what lets a query find its lattice block as (firstChild - 1) / 8.
  const auto& levels = tree.levelOffsets;
  if (levels.size() < 2 || levels.size() > tree.maxDepth + 2) fail("levelOffsets has " + std::to_string(levels.size()) + " entries for maxDepth " + std::to_string(tree.maxDepth));
  if (levels.front() != 0 || levels[1] != 1 || levels.back() != n) fail("levelOffsets must start 0, 1 and end at the node count");
  std::uint64_t interior = 0;
  std::uint32_t nextHalfSpace = 0;
  for (std::size_t d = 0; d + 1 < levels.size(); ++d) {
    if (levels[d + 1] <= levels[d]) fail("levelOffsets[" + std::to_string(d + 1) + "] does not increase");
    const std::uint64_t interiorBefore = interior;
    for (std::uint32_t i = levels[d]; i < levels[d + 1]; ++i) {
      if (tree.firstChild[i] != 0) {
        const std::uint64_t expected = 1 + 8 * interior;
        if (tree.firstChild[i] != expected)
          fail("firstChild[" + std::to_string(i) + "] = " + std::to_string(tree.firstChild[i]) + " breaks the breadth-first layout, expected " + std::to_string(expected));
        ++interior;
      }
      const float e = tree.errorBound[i];
      if (!(std::isfinite(e) && e >= 0.0f)) fail("errorBound[" + std::to_string(i) + "] is not finite and >= 0");
      const std::uint32_t h = tree.halfSpaceIndex[i];
      if (h != kNoHalfSpace) {
        if (h != nextHalfSpace) fail("halfSpaceIndex[" + std::to_string(i) + "] = " + std::to_string(h) + ", expected " + std::to_string(nextHalfSpace));
        ++nextHalfSpace;
      }
    }
    const std::uint64_t nextLevelSize = d + 2 < levels.size() ? levels[d + 2] - levels[d + 1] : 0;
    if (8 * (interior - interiorBefore) != nextLevelSize)
      fail("level " + std::to_string(d + 1) + " has " + std::to_string(nextLevelSize) + " nodes but level " + std::to_string(d) + " has " + std::to_string(interior - interiorBefore) + " interior nodes");
  }
  if (tree.lattice.size() != interior * kContactTreeLatticePerNode)
    fail("lattice has " + std::to_string(tree.lattice.size()) + " values for " + std::to_string(interior) + " interior nodes");
  for (std::size_t i = 0; i < tree.lattice.size(); ++i)
    if (!std::isfinite(tree.lattice[i])) fail("lattice[" + std::to_string(i) + "] is not finite");
  if (tree.halfSpaces.size() != nextHalfSpace)
    fail("halfSpaces has " + std::to_string(tree.halfSpaces.size()) + " entries, nodes reference " + std::to_string(nextHalfSpace));
  for (std::size_t i = 0; i < tree.halfSpaces.size(); ++i) {
    const ContactHalfSpace& hs = tree.halfSpaces[i];
    const double len = std::sqrt(double(hs.normal[0]) * hs.normal[0] + double(hs.normal[1]) * hs.normal[1] + double(hs.normal[2]) * hs.normal[2]);
    if (!(std::abs(len - 1.0) < 1e-3) || !std::isfinite(hs.offset) || !(std::isfinite(hs.fitError) && hs.fitError >= 0.0f))
      fail("halfSpaces[" + std::to_string(i) + "] is not a unit normal with finite offset and fit error");
  }
  tree.buildLookupGrid();
  return tree;
}

}  // namespace clod
