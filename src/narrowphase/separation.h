#pragma once
// Internal: the exact closest distance between two placed triangle meshes (World::separation,
// QuerySettings::marginAbs), by a best-first branch-and-bound descent of two 4-wide box
// hierarchies (CollisionBody::triangleBvh), and the triangle-triangle distance it rests on.
#include <cstdint>
#include <vector>

#include "clod/collision_body.h"
#include "clod/separation.h"

namespace clod::detail {

/// Closest points between triangles (a0, a1, a2) and (b0, b1, b2), any frame: their squared
/// distance (0 when they touch or cross) and a point of each realising it. Exact up to rounding:
/// the minimum over the six vertex-triangle (closestPointOnTriangle) and nine edge-edge distances,
/// or 0 when an edge of one crosses the other (the only other way two triangles can be closest).
/// Degenerate triangles are handled as segments or points.
struct TriangleDistance {
  double distanceSquared = 0.0;
  Vec3 pointA = Vec3::Zero();
  Vec3 pointB = Vec3::Zero();
};
TriangleDistance triangleDistance(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                                  const Vec3& b2) noexcept;

/// The descent's working memory: a heap of node pairs (no allocation once grown).
struct SeparationItem {
  double lowerBound;
  std::uint32_t a, b;  // slot references (see separation.cpp)
};
using SeparationHeap = std::vector<SeparationItem>;

/// World::separation for two shapes placed at poseA and poseB (mesh frame -> world).
Separation separationBetween(const CollisionBody& shapeA, const Pose& poseA, const CollisionBody& shapeB,
                             const Pose& poseB, double maxDistance, SeparationHeap& heap);

}  // namespace clod::detail
