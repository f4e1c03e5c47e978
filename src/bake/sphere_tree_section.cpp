#include "sphere_tree_section.h"

#include <cmath>
#include <string>

namespace clod::detail {

namespace {

std::string str(std::uint64_t value) { return std::to_string(value); }

// Per-sphere arrays in file order; the decoder reads them back in the same order.
template <class Tree, class Visitor>
void forEachSphereArray(Tree& tree, Visitor&& visit) {
  visit("centerX", tree.centerX);
  visit("centerY", tree.centerY);
  visit("centerZ", tree.centerZ);
  visit("radius", tree.radius);
  visit("parent", tree.parent);
  visit("firstChild", tree.firstChild);
  visit("childCount", tree.childCount);
  visit("triangleOffsets", tree.triangleOffsets);
  visit("triangleList", tree.triangleList);
  visit("levelOffsets", tree.levelOffsets);
}

}  // namespace

void checkSphereTree(const SphereTree& tree, const SphereTreeSettings& settings, std::uint32_t triangleCount,
                     const Complaint& complain) {
  if (settings.method != SphereTreeMethod::kOctree && settings.method != SphereTreeMethod::kMedial) {
    complain("unknown sphere-tree method " + str(static_cast<std::uint32_t>(settings.method)));
  }
  if (settings.medialReduction != MedialReduction::kBest && settings.medialReduction != MedialReduction::kMergeBurst &&
      settings.medialReduction != MedialReduction::kKMeans) {
    complain("unknown medial reduction " + str(static_cast<std::uint32_t>(settings.medialReduction)));
  }
  const std::size_t n = tree.radius.size();
  if (n == 0) complain("the sphere-tree has no spheres");
  if (n >= kNoSphere) complain("sphere count " + str(n) + " does not fit 32 bits");
  auto checkSize = [&](const char* name, std::size_t size, std::size_t expected) {
    if (size != expected) complain(std::string(name) + " has " + str(size) + " entries, expected " + str(expected));
  };
  checkSize("centerX", tree.centerX.size(), n);
  checkSize("centerY", tree.centerY.size(), n);
  checkSize("centerZ", tree.centerZ.size(), n);
  checkSize("parent", tree.parent.size(), n);
  checkSize("firstChild", tree.firstChild.size(), n);
  checkSize("childCount", tree.childCount.size(), n);
  checkSize("triangleOffsets", tree.triangleOffsets.size(), n + 1);
  if (tree.triangleList.size() >= 0xffffffffull) complain("triangleList size " + str(tree.triangleList.size()) + " does not fit 32 bits");

  const auto& levels = tree.levelOffsets;
  if (levels.size() < 2) complain("levelOffsets has " + str(levels.size()) + " entries, needs at least 2 (a root level)");
  if (levels[0] != 0) complain("levelOffsets[0] is " + str(levels[0]) + ", not 0");
  if (levels[1] != 1) complain("levelOffsets[1] is " + str(levels[1]) + ": level 0 must hold exactly one root sphere");
  for (std::size_t l = 1; l < levels.size(); ++l) {
    if (levels[l] <= levels[l - 1]) {
      complain("levelOffsets not strictly increasing at level " + str(l - 1) + " (" + str(levels[l - 1]) + " then " + str(levels[l]) + ")");
    }
  }
  if (levels.back() != n) complain("levelOffsets ends at " + str(levels.back()) + ", not at the sphere count " + str(n));

  if (tree.triangleOffsets[0] != 0) complain("triangleOffsets[0] is " + str(tree.triangleOffsets[0]) + ", not 0");
  for (std::size_t i = 0; i < n; ++i) {
    if (tree.triangleOffsets[i + 1] < tree.triangleOffsets[i]) {
      complain("triangleOffsets decreases at sphere " + str(i) + " (" + str(tree.triangleOffsets[i]) + " then " +
               str(tree.triangleOffsets[i + 1]) + ")");
    }
  }
  if (tree.triangleOffsets[n] != tree.triangleList.size()) {
    complain("triangleOffsets ends at " + str(tree.triangleOffsets[n]) + ", not at the triangleList size " + str(tree.triangleList.size()));
  }
  for (std::size_t k = 0; k < tree.triangleList.size(); ++k) {
    if (tree.triangleList[k] >= triangleCount) {
      complain("triangleList[" + str(k) + "] = " + str(tree.triangleList[k]) + " >= mesh triangle count " + str(triangleCount));
    }
  }

  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(tree.centerX[i]) || !std::isfinite(tree.centerY[i]) || !std::isfinite(tree.centerZ[i])) {
      complain("sphere " + str(i) + " has a non-finite centre");
    }
    if (!std::isfinite(tree.radius[i]) || !(tree.radius[i] >= 0.0)) {
      complain("sphere " + str(i) + " has radius " + std::to_string(tree.radius[i]) + " (must be finite and >= 0)");
    }
  }

  // Parent and child links: every child range lies in the next level, every sphere's parent
  // lies in the previous level and its child range contains the sphere. Both directions are
  // checked, so traversal code may follow either without bounds checks.
  const std::size_t levelCount = levels.size() - 1;
  for (std::size_t l = 0; l < levelCount; ++l) {
    for (std::size_t i = levels[l]; i < levels[l + 1]; ++i) {
      const std::uint32_t p = tree.parent[i];
      if (l == 0) {
        if (p != kNoSphere) complain("root sphere 0 has parent " + str(p) + ", expected none");
      } else {
        if (p < levels[l - 1] || p >= levels[l]) {
          complain("sphere " + str(i) + " on level " + str(l) + " has parent " + str(p) + " outside level " + str(l - 1));
        }
        const std::uint64_t first = tree.firstChild[p];
        if (tree.childCount[p] == 0 || i < first || i >= first + tree.childCount[p]) {
          complain("sphere " + str(i) + " is not among the children of its parent " + str(p));
        }
      }
      const std::uint64_t count = tree.childCount[i];
      if (count == 0) continue;
      if (l + 1 == levelCount) complain("sphere " + str(i) + " on the deepest level has " + str(count) + " children");
      const std::uint64_t first = tree.firstChild[i];
      if (first < levels[l + 1] || first + count > levels[l + 2]) {
        complain("sphere " + str(i) + " has children [" + str(first) + ", " + str(first + count) + ") outside level " + str(l + 1));
      }
      for (std::uint64_t c = first; c < first + count; ++c) {
        if (tree.parent[c] != i) complain("sphere " + str(c) + " is a child of sphere " + str(i) + " but names parent " + str(tree.parent[c]));
      }
    }
  }
}

std::vector<std::byte> encodeSphereTreeSection(const SphereTree& tree, const SphereTreeSettings& settings) {
  ByteWriter writer;
  writer.write<std::uint8_t>(static_cast<std::uint8_t>(settings.method));
  // Was a reserved 0 byte before the reduction was stored; 0 is kBest, the default of those builds.
  writer.write<std::uint8_t>(static_cast<std::uint8_t>(settings.medialReduction));
  writer.write<std::uint16_t>(0);
  writer.write<std::uint32_t>(settings.branching);
  writer.write<std::uint32_t>(settings.depth);
  writer.write<std::uint32_t>(settings.medialSamples);
  forEachSphereArray(tree, [&](const char*, const auto& values) { writeAlignedArray(writer, values); });
  return writer.take();
}

DecodedSphereTreeSection decodeSphereTreeSection(std::span<const std::byte> payload, std::uint32_t triangleCount) {
  ByteReader reader(payload.data(), payload.size(), "bake section 'STRE'");
  DecodedSphereTreeSection decoded;
  decoded.settings.method = static_cast<SphereTreeMethod>(reader.read<std::uint8_t>());
  decoded.settings.medialReduction = static_cast<MedialReduction>(reader.read<std::uint8_t>());
  if (reader.read<std::uint16_t>() != 0) reader.fail("reserved bytes after the medial reduction are not 0");
  decoded.settings.branching = reader.read<std::uint32_t>();
  decoded.settings.depth = reader.read<std::uint32_t>();
  decoded.settings.medialSamples = reader.read<std::uint32_t>();
  forEachSphereArray(decoded.tree, [&](const char*, auto& values) {
    values = readAlignedArray<typename std::decay_t<decltype(values)>::value_type>(reader);
  });
  if (!reader.atEnd()) reader.fail(std::to_string(reader.remaining()) + " unexpected bytes after levelOffsets");
  checkSphereTree(decoded.tree, decoded.settings, triangleCount, Complaint{ErrorCode::kBakeCorrupt, reader.context()});
  return decoded;
}

}  // namespace clod::detail
