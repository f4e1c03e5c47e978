#pragma once
// Sphere-trees: a hierarchy of bounding spheres per mesh, stored breadth-first in flat
// structure-of-arrays form. Level 0 is the root (one sphere); level l's spheres are the index
// range [levelOffsets[l], levelOffsets[l+1]). "Resolve at level l" is a contiguous range.
//
// Every level covers the whole surface: each point of the mesh lies inside at least one
// sphere of every level. A sphere's children are contiguous in the next level.

#include <cstdint>
#include <span>
#include <vector>

#include "clod/math.h"

namespace clod {

inline constexpr std::uint32_t kNoSphere = 0xffffffffu;

/// Plain data of a built sphere-tree. Builders fill it; the bake file stores it as is.
struct SphereTree {
  // Per sphere (SoA, breadth-first order).
  std::vector<double> centerX, centerY, centerZ, radius;
  std::vector<std::uint32_t> parent;       ///< kNoSphere for the root
  std::vector<std::uint32_t> firstChild;   ///< index of the first child (valid if childCount > 0)
  std::vector<std::uint32_t> childCount;   ///< 0 for spheres on the deepest level

  /// Triangles each sphere is responsible for (the part of the surface it must bound), CSR:
  /// sphere i owns triangleList[triangleOffsets[i] .. triangleOffsets[i+1]).
  std::vector<std::uint32_t> triangleOffsets;
  std::vector<std::uint32_t> triangleList;

  /// levelOffsets.size() == levelCount() + 1.
  std::vector<std::uint32_t> levelOffsets;

  std::uint32_t sphereCount() const { return static_cast<std::uint32_t>(radius.size()); }
  std::uint32_t levelCount() const {
    return levelOffsets.empty() ? 0 : static_cast<std::uint32_t>(levelOffsets.size() - 1);
  }
  std::uint32_t levelBegin(std::uint32_t level) const { return levelOffsets[level]; }
  std::uint32_t levelEnd(std::uint32_t level) const { return levelOffsets[level + 1]; }
  Vec3 center(std::uint32_t i) const { return {centerX[i], centerY[i], centerZ[i]}; }
  std::span<const std::uint32_t> triangles(std::uint32_t i) const {
    return {triangleList.data() + triangleOffsets[i], triangleOffsets[i + 1] - triangleOffsets[i]};
  }
};

}  // namespace clod
