#pragma once
// Internal: the first triangle of a body that a ray meets, on the body's triangle hierarchy
// (CollisionBody::triangleBvh), and the penetration of two bodies along a line built on it --
// what the exact model's per-point depth measures (docs/narrow-phase.md, "Error bounds").
#include <cstdint>
#include <limits>

#include "clod/collision_body.h"
#include "clod/math.h"

namespace clod::detail {

/// The nearest crossing of the ray origin + t dir (body frame, dir of any non-zero length) with
/// one of the body's triangles for t in (tMin, tMax): t, the triangle, and whether the ray leaves
/// the body there (it runs along the triangle's outward normal). Degenerate triangles and rays in
/// a triangle's plane never hit. O(log T) typical; no allocation.
struct RayHit {
  bool hit = false;
  double t = std::numeric_limits<double>::infinity();
  std::uint32_t triangle = 0;
  bool leaving = false;
};
RayHit firstHit(const CollisionBody& body, const Vec3& origin, const Vec3& dir, double tMin,
                double tMax = std::numeric_limits<double>::infinity());

/// How far a point at `origin` (body frame) travels along `dir` (unit) before it leaves the
/// body: the nearest crossing beyond `tMin`, when the ray leaves the body there (the point was
/// inside, or on the surface with the body behind it along dir); 0 otherwise -- the point was
/// outside, or on the surface facing dir. Closed bodies; `exit` gets the crossing.
double distanceToLeave(const CollisionBody& body, const Vec3& origin, const Vec3& dir, double tMin, RayHit& exit);

}  // namespace clod::detail
