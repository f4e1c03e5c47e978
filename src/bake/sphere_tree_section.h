#pragma once
// The 'STRE' section of a bake file: the sphere-tree and the settings it was built with.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "clod/sphere_tree.h"
#include "clod/sphere_tree_builder.h"
#include "section_codec.h"

namespace clod::detail {

/// Throws via `complain` unless the tree is structurally sound for a mesh with
/// `triangleCount` triangles (the invariants listed at decodeBake in bake.h) and the settings
/// name a known method.
void checkSphereTree(const SphereTree& tree, const SphereTreeSettings& settings, std::uint32_t triangleCount,
                     const Complaint& complain);

/// Encodes a tree that passed checkSphereTree.
std::vector<std::byte> encodeSphereTreeSection(const SphereTree& tree, const SphereTreeSettings& settings);

struct DecodedSphereTreeSection {
  SphereTree tree;
  SphereTreeSettings settings;
};

/// Decodes and checks a 'STRE' payload of version 1 against a mesh of `triangleCount`
/// triangles. Throws kBakeTruncated / kBakeCorrupt.
DecodedSphereTreeSection decodeSphereTreeSection(std::span<const std::byte> payload, std::uint32_t triangleCount);

}  // namespace clod::detail
