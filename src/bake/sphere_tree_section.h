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

/// Sphere values are coded on a grid of step 2^(ilogb(parent radius) - kSphereGridBits), i.e.
/// at most 2^-kSphereGridBits of the parent's radius: a decoded radius exceeds the original by
/// at most (1 + sqrt(3)/2) steps < 0.00092 of the parent's radius (sphere_tree_section.cpp).
inline constexpr int kSphereGridBits = 11;

/// Encodes a tree that passed checkSphereTree (payload version 2, kBakeSphereTreeVersion).
/// Lossy but conservative: every decoded sphere contains its original ball; and idempotent:
/// encoding a decoded tree gives the same bytes.
std::vector<std::byte> encodeSphereTreeSection(const SphereTree& tree, const SphereTreeSettings& settings);

/// The tree decodeSphereTreeSection(encodeSphereTreeSection(tree)) returns, without the bytes:
/// bakeMesh applies it before building anything on the tree, so a bake in memory equals the
/// bake loaded from its file.
SphereTree quantisedSphereTree(const SphereTree& tree);

struct DecodedSphereTreeSection {
  SphereTree tree;
  SphereTreeSettings settings;
};

/// Decodes and checks a 'STRE' payload of section version `version` against a mesh of
/// `triangleCount` triangles. Throws kBakeVersion for version 1 (uncompressed: re-bake),
/// kBakeTruncated / kBakeCorrupt.
DecodedSphereTreeSection decodeSphereTreeSection(std::span<const std::byte> payload, std::uint32_t triangleCount,
                                                 std::uint32_t version);

}  // namespace clod::detail
