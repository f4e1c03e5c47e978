#pragma once
// Internal: the exact closest distance between two placed triangle meshes (World::separation),
// by a best-first branch-and-bound descent of two 4-wide box hierarchies (the proximity layer's
// TriangleBvh, one per shape, built on first use), and the triangle-triangle distance it rests on.
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "clod/collision_body.h"
#include "clod/world.h"
#include "proximity/triangle_bvh.h"

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

/// Per-shape hierarchies and the descent's working memory (no allocation once grown).
class SeparationCache {
public:
  /// The hierarchy of `shape`'s triangles, built on first use (the cache keeps the shape alive, so
  /// its address cannot be reused by another shape while the entry exists).
  const TriangleBvh& bvh(const std::shared_ptr<const CollisionBody>& shape);
  /// Drops the entry of a shape no body uses any more.
  void forget(const CollisionBody* shape);

  struct Item {
    double lowerBound;
    std::uint32_t a, b;  // slot references (see separation.cpp)
  };
  std::vector<Item> heap;

private:
  std::map<const CollisionBody*, std::pair<std::shared_ptr<const CollisionBody>, TriangleBvh>> entries_;
};

/// World::separation for two shapes placed at poseA and poseB (mesh frame -> world).
Separation separationBetween(const std::shared_ptr<const CollisionBody>& shapeA, const Pose& poseA,
                             const std::shared_ptr<const CollisionBody>& shapeB, const Pose& poseB, double maxDistance,
                             SeparationCache& cache);

}  // namespace clod::detail
