#pragma once
// Sphere-trees: a hierarchy of bounding spheres per mesh, stored breadth-first in flat
// structure-of-arrays form. Level 0 is the root (one sphere); level l's spheres are the index
// range [levelOffsets[l], levelOffsets[l+1]). "Resolve at level l" is a contiguous range.
//
// Every level covers the whole surface: each point of the mesh lies inside at least one
// sphere of every level. A sphere's children are contiguous in the next level, and every sphere
// above the deepest level has at least one child (so "every level covers" holds at any cut).
//
// Built by buildSphereTree() (sphere_tree_builder.h). Units are the mesh's; indices are 32-bit.
// Memory: 8 doubles-worth per sphere plus 4 bytes per (sphere, responsible triangle) pair.

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
  /// sphere i owns triangleList[triangleOffsets[i] .. triangleOffsets[i+1]). Each list is sorted
  /// and free of duplicates; a parent's list is the union of its children's; a leaf's list is
  /// the triangles it bounds. The sphere bounds the part of each listed triangle assigned to it,
  /// not necessarily the whole triangle (builders clip large triangles), and the lists of one
  /// level together name every triangle of the mesh. Closest-feature maps search these lists.
  std::vector<std::uint32_t> triangleOffsets;
  std::vector<std::uint32_t> triangleList;

  /// levelOffsets.size() == levelCount() + 1.
  std::vector<std::uint32_t> levelOffsets;

  /// Number of spheres on all levels together.
  std::uint32_t sphereCount() const { return static_cast<std::uint32_t>(radius.size()); }
  /// Number of levels (root included); 0 for an empty tree.
  std::uint32_t levelCount() const {
    return levelOffsets.empty() ? 0 : static_cast<std::uint32_t>(levelOffsets.size() - 1);
  }
  /// First sphere index of `level` (level < levelCount()).
  std::uint32_t levelBegin(std::uint32_t level) const { return levelOffsets[level]; }
  /// One past the last sphere index of `level`.
  std::uint32_t levelEnd(std::uint32_t level) const { return levelOffsets[level + 1]; }
  /// Centre of sphere i.
  Vec3 center(std::uint32_t i) const { return {centerX[i], centerY[i], centerZ[i]}; }
  /// Triangles sphere i is responsible for (see triangleList).
  std::span<const std::uint32_t> triangles(std::uint32_t i) const {
    return {triangleList.data() + triangleOffsets[i], triangleOffsets[i + 1] - triangleOffsets[i]};
  }
};

}  // namespace clod
