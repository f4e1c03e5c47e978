#pragma once
// The 'CFMP' section of a bake file: the closest feature maps of the bake's sphere-tree
// (closest_feature_map.h). Optional: bakes without it load with no maps.
//
// Payload, version 1 (little-endian; arrays are u64 count + elements, padded with zeros to 8):
//   u8 scheme, u8 codec, u16 reserved (0), i32 rootStacks, i32 minStacks, u32 reserved (0),
//   levelStacks (u32[]), sphereOffset (u32[]), sphereSingle (u8[]), codes16 (u16[]),
//   codes32 (u32[]), averageNormals (f32[], x y z per sphere).

#include <cstddef>
#include <span>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/sphere_tree.h"

namespace clod::detail {

/// Encodes a map (which ClosestFeatureMap::fromData has already checked).
std::vector<std::byte> encodeCfmSection(const ClosestFeatureMap& map);

/// Decodes a 'CFMP' payload of version 1 for `tree` and checks it (ClosestFeatureMap::fromData).
/// Throws kBakeTruncated / kBakeCorrupt naming the section and field.
ClosestFeatureMap decodeCfmSection(std::span<const std::byte> payload, const SphereTree& tree);

}  // namespace clod::detail
