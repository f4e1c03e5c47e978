#include "clod/contact_tree_codec.h"

#include <bit>
#include <cmath>
#include <vector>
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
  out.writeArray(tree.levelOffsets);
  std::vector<std::uint64_t> interior(tree.nodeWords.size()), surface(tree.nodeWords.size());
  for (std::size_t w = 0; w < tree.nodeWords.size(); ++w) {
    interior[w] = tree.nodeWords[w].interior;
    surface[w] = tree.nodeWords[w].surface;
  }
  out.writeArray(interior);
  out.writeArray(surface);
  out.writeArray(tree.errorCode);
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
  tree.levelOffsets = in.readArray<std::uint32_t>();
  const auto interiorBits = in.readArray<std::uint64_t>();
  const auto surfaceBits = in.readArray<std::uint64_t>();
  tree.errorCode = in.readArray<std::uint16_t>();
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

  const auto& levels = tree.levelOffsets;
  if (levels.size() < 2 || levels.size() > tree.maxDepth + 2) fail("levelOffsets has " + std::to_string(levels.size()) + " entries for maxDepth " + std::to_string(tree.maxDepth));
  if (levels.front() != 0 || levels[1] != 1) fail("levelOffsets must start 0, 1");
  const std::uint64_t n = levels.back();
  if (n > 0xfffffff0u) fail("node count " + std::to_string(n) + " exceeds 32-bit indices");
  const std::uint64_t words = (n + 63) / 64;
  if (interiorBits.size() != words) fail("interior bitmap has " + std::to_string(interiorBits.size()) + " words for " + std::to_string(n) + " nodes");
  if (surfaceBits.size() != words) fail("surface bitmap has " + std::to_string(surfaceBits.size()) + " words for " + std::to_string(n) + " nodes");
  if (n % 64 != 0 && ((interiorBits.back() | surfaceBits.back()) >> (n % 64)) != 0) fail("bitmaps have bits set past the last node");
  if (tree.errorCode.size() != n) fail("errorCode has " + std::to_string(tree.errorCode.size()) + " entries for " + std::to_string(n) + " nodes");
  for (std::size_t i = 0; i < tree.errorCode.size(); ++i)
    if (tree.errorCode[i] > 0x7f7f) fail("errorCode[" + std::to_string(i) + "] is not a finite bound >= 0");

  tree.nodeWords.resize(words);
  std::uint64_t interior = 0, surfaceCount = 0;
  for (std::size_t w = 0; w < words; ++w) {
    tree.nodeWords[w] = ContactTreeNodeWord{interiorBits[w], surfaceBits[w], static_cast<std::uint32_t>(interior),
                                            static_cast<std::uint32_t>(surfaceCount)};
    interior += static_cast<std::uint64_t>(std::popcount(interiorBits[w]));
    surfaceCount += static_cast<std::uint64_t>(std::popcount(surfaceBits[w]));
  }
  // Breadth-first layout: level d + 1 holds exactly the children of level d's interior nodes
  // (8 each), which is what lets a query find children and lattice blocks by rank.
  for (std::size_t d = 0; d + 1 < levels.size(); ++d) {
    if (levels[d + 1] <= levels[d]) fail("levelOffsets[" + std::to_string(d + 1) + "] does not increase");
    std::uint64_t split = 0;
    for (std::uint32_t i = levels[d]; i < levels[d + 1]; ++i) split += (interiorBits[i >> 6] >> (i & 63)) & 1u;
    const std::uint64_t nextLevelSize = d + 2 < levels.size() ? levels[d + 2] - levels[d + 1] : 0;
    if (8 * split != nextLevelSize)
      fail("level " + std::to_string(d + 1) + " has " + std::to_string(nextLevelSize) + " nodes but level " + std::to_string(d) + " has " + std::to_string(split) + " interior nodes");
  }
  if (tree.lattice.size() != interior * kContactTreeLatticePerNode)
    fail("lattice has " + std::to_string(tree.lattice.size()) + " values for " + std::to_string(interior) + " interior nodes");
  for (std::size_t i = 0; i < tree.lattice.size(); ++i)
    if (!std::isfinite(tree.lattice[i])) fail("lattice[" + std::to_string(i) + "] is not finite");
  if (tree.halfSpaces.size() != surfaceCount)
    fail("halfSpaces has " + std::to_string(tree.halfSpaces.size()) + " entries, the surface bitmap marks " + std::to_string(surfaceCount));
  for (std::size_t i = 0; i < tree.halfSpaces.size(); ++i) {
    const ContactHalfSpace& hs = tree.halfSpaces[i];
    const double len = std::sqrt(double(hs.normal[0]) * hs.normal[0] + double(hs.normal[1]) * hs.normal[1] + double(hs.normal[2]) * hs.normal[2]);
    if (!(std::abs(len - 1.0) < 1e-3) || !std::isfinite(hs.offset) || !(std::isfinite(hs.fitError) && hs.fitError >= 0.0f))
      fail("halfSpaces[" + std::to_string(i) + "] is not a unit normal with finite offset and fit error");
  }
  tree.buildLookupGrid();
  tree.deriveFlatSurfaces();
  return tree;
}

}  // namespace clod
