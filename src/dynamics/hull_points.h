#pragma once
// A body's hull -- its root patch's extreme vertices (CollisionBody::spherePatchVertices, else
// sphereSupportVertices, whose support is the hull's to within their slack) -- as flat coordinate
// arrays in mesh coordinates, for the world's per-substep scans: the hull's box under a pose and
// its support points (holds at the bodies' boxes, docs/dynamics.md). The shape lists the hull as
// indices into its mesh; gathering through them cost ~10 % of a 200-body bin's CPU time.

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "clod/collision_body.h"
#include "clod/math.h"

namespace clod::detail {

class HullPoints {
 public:
  explicit HullPoints(const CollisionBody& shape);

  /// Whether the shape has no hull (an open or empty mesh without support vertices).
  bool empty() const { return x_.empty(); }
  /// How far the hull's points may lie inside the true hull (CollisionBody::sphereSupportSlack).
  double slack() const { return slack_; }

  /// The box of the hull's points under p -> m p + t, grown by the slack; nullopt when empty.
  std::optional<Aabb> boxUnder(const Mat3& m, const Vec3& t) const;

  /// The hull's points farthest along each of the first `count` (<= 5) directions (mesh
  /// coordinates), in mesh coordinates, without the slack. Requires !empty().
  std::array<Vec3, 5> farthestAlong(const std::array<Vec3, 5>& directions, std::size_t count) const;

 private:
  std::vector<double> x_, y_, z_;
  double slack_ = 0.0;
};

}  // namespace clod::detail
