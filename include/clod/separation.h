#pragma once
// The exact closest distance between two placed triangle meshes: World::separation, and the
// speculative contact of QuerySettings::marginAbs (query.h).
#include <cstdint>
#include <limits>

#include "clod/math.h"

namespace clod {

/// The exact closest distance between two bodies' surfaces (World::separation).
struct Separation {
  /// Closest distance between the two triangle meshes as placed now (>= 0, length units), exact
  /// in double precision (the minimum over all triangle pairs, found by a branch-and-bound descent
  /// of two box hierarchies); 0 when the surfaces touch or cross. When it exceeds the query's
  /// maxDistance the descent stops early: `distance` is then only a lower bound (> maxDistance),
  /// `withinMax` is false and the points and triangles are not set.
  double distance = std::numeric_limits<double>::infinity();
  bool withinMax = false;
  /// The volumes overlap: the surfaces cross (distance 0), or one closed body lies wholly inside
  /// the other (distance > 0 is then the gap between the inner and the outer surface).
  bool overlapping = false;
  Vec3 pointA = Vec3::Zero();   ///< closest point on A's surface (world frame)
  Vec3 pointB = Vec3::Zero();   ///< closest point on B's surface (world frame)
  std::uint32_t triangleA = 0;  ///< the triangles of A's and B's meshes the points lie on
  std::uint32_t triangleB = 0;
};

}  // namespace clod
