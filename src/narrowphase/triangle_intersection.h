#pragma once
// Triangle-triangle intersection for the exact contact model (internal to the narrow phase).
//
// The structure follows Moeller, "A Fast Triangle-Triangle Intersection Test", JGT 2(2) 1997:
// reject when one triangle lies strictly on one side of the other's plane, otherwise intersect
// the two segments (each triangle cut by the other's plane) on the planes' common line. Plane
// distances within epsAbs of zero are snapped to zero, which makes touching contacts and the
// coplanar case (all three snapped) decisions instead of rounding accidents. Coplanar triangles
// are handled by clipping one against the other's three edge half-planes (Sutherland-Hodgman),
// giving their overlap polygon.

#include <array>
#include <cstdint>

#include "clod/math.h"

namespace clod::narrowphase {

struct TriangleIntersection {
  /// Points describing the intersection: the two end points of the segment (equal if the
  /// triangles touch in one point), or the corners of the coplanar overlap polygon (up to 6).
  std::array<Vec3, 9> points;
  std::uint32_t count = 0;
  bool coplanar = false;
  /// Not coplanar, and one triangle has no corner strictly on each side of the other's plane: they
  /// meet where an edge or a corner of one lies in the other's plane, without crossing it (a face
  /// resting edge-on against another). No volume lies between them there.
  bool touching = false;
  /// Penetration of A's corners below B's plane: max(0, max_i -nB . (a_i - b_0)), and the
  /// same for B's corners below A's plane (unit outward face normals nA, nB).
  double penetrationBelowB = 0.0;
  double penetrationBelowA = 0.0;
  Vec3 normalA = Vec3::Zero();  ///< unit face normal of A
  Vec3 normalB = Vec3::Zero();  ///< unit face normal of B
};

/// True if triangles (a0, a1, a2) and (b0, b1, b2) intersect (touching counts); fills `out`.
/// Degenerate (zero-area) triangles never intersect. epsAbs >= 0 is the plane-distance
/// tolerance in length units.
bool intersectTriangles(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                        const Vec3& b2, double epsAbs, TriangleIntersection& out) noexcept;

}  // namespace clod::narrowphase
