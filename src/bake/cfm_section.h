#pragma once
// The 'CFMP' section of a bake file: the closest feature maps of the bake's sphere-tree
// (closest_feature_map.h). Optional: bakes without it load with no maps.
//
// Payload, version 2 (little-endian): u8 scheme, u8 codec, u16 reserved (0), i32 rootStacks,
//   i32 minStacks, u32 reserved (0), then u64 count + bytes of one range-coded stream holding
//   levelStacks, sphereSingle, sphereOffset, codes16, codes32 and averageNormals losslessly
//   (cfm_section.cpp, docs/bake-format.md). Version 1 (plain arrays) is refused: re-bake.

#include <cstddef>
#include <span>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/sphere_tree.h"

namespace clod::detail {

/// Encodes a map (which ClosestFeatureMap::fromData has already checked).
std::vector<std::byte> encodeCfmSection(const ClosestFeatureMap& map);

/// Decodes a 'CFMP' payload of section version `version` for `tree` and checks it
/// (ClosestFeatureMap::fromData). Throws kBakeVersion for version 1 (re-bake), kBakeTruncated /
/// kBakeCorrupt naming the section and field.
ClosestFeatureMap decodeCfmSection(std::span<const std::byte> payload, const SphereTree& tree, std::uint32_t version);

}  // namespace clod::detail
