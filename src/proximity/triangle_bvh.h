#pragma once
// Internal: a 4-wide bounding-volume hierarchy over triangles, shared by the closest-point and
// winding-number queries of MeshDistance. Flat node array, 32-bit indices, SoA float bounds so
// one node's four box tests are four-lane vector operations.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "clod/math.h"

namespace clod::detail {

/// One node: four child slots. Bounds are float, rounded outward from the double boxes so they
/// still contain every triangle exactly (queries stay exact; see triangle_bvh.cpp).
struct alignas(64) Bvh4Node {
  static constexpr std::uint32_t kEmpty = 0xffffffffu;
  float minX[4], minY[4], minZ[4];
  float maxX[4], maxY[4], maxZ[4];
  /// Inner slot (count == 0): index of the child node; leaf slot (count > 0): first primitive
  /// in TriangleBvh::order(); empty slot: kEmpty with count 0 and an empty (inverted) box.
  std::uint32_t child[4];
  std::uint32_t count[4];

  bool emptySlot(int s) const noexcept { return child[s] == kEmpty && count[s] == 0; }
  Aabb slotBox(int s) const { return Aabb{Vec3(minX[s], minY[s], minZ[s]), Vec3(maxX[s], maxY[s], maxZ[s])}; }
};
static_assert(sizeof(Bvh4Node) == 128);

struct BvhBuildSettings {
  std::uint32_t leafSize = 4;  ///< most primitives per leaf slot
};

/// Builds over primitive boxes; `order()[i]` is the primitive stored at position i, and every
/// leaf slot refers to a contiguous range of positions. Node 0 is the root; a child node always
/// comes after its parent (depth-first order).
class TriangleBvh {
public:
  TriangleBvh() = default;
  /// boxes[i] bounds primitive i; at least one primitive. O(n log n), parallel with TBB.
  TriangleBvh(std::span<const Aabb> boxes, const BvhBuildSettings& settings);

  std::span<const Bvh4Node> nodes() const { return nodes_; }
  std::span<const std::uint32_t> order() const { return order_; }
  /// Upper bound on the depth of the tree (root = 1), for sizing traversal stacks.
  std::uint32_t depth() const { return depth_; }

  /// Traversal stacks hold at most 3 entries per level plus one.
  static constexpr std::uint32_t kMaxDepth = 96;

private:
  std::vector<Bvh4Node> nodes_;
  std::vector<std::uint32_t> order_;
  std::uint32_t depth_ = 0;
};

}  // namespace clod::detail
