#pragma once
// Triangulation of one polygonal face (OBJ, PLY, OFF, Collada faces with more than 3 corners),
// in O(n log n) time for n corners, so that a hostile file with one 100,000-corner face loads
// in milliseconds (Assimp's aiProcess_Triangulate clips ears: ~n^2.3, > 400 s for that face).
//
// The polygon is projected onto the plane perpendicular to its Newell normal (the best-fit
// plane; exact for planar faces, the usual choice for slightly warped ones), in which it winds
// counter-clockwise by construction. Then:
//  - strictly convex polygons: a fan from corner 0 (the same triangles as before, for quads);
//  - otherwise: a plane sweep splits it into y-monotone pieces (de Berg et al., Computational
//    Geometry, ch. 3), each triangulated by the linear stack walk down its two chains;
//  - polygons that are not simple in that plane (self-intersecting, zero area, non-finite, or
//    too warped for the projection) get a fan from corner 0: always n - 2 triangles, never a
//    crash or a loop, but not necessarily inside the polygon.

#include <cstdint>
#include <span>
#include <vector>

#include "clod/mesh.h"

namespace clod::detail {

/// How triangulatePolygon cut the polygon.
enum class PolygonCut : std::uint8_t {
  kTriangle,     ///< 3 corners: the face itself
  kConvexFan,    ///< strictly convex in its plane: fan from corner 0
  kMonotone,     ///< simple polygon: monotone pieces, every triangle inside the polygon
  kFanFallback,  ///< not a simple polygon in its best-fit plane: fan from corner 0
};

/// Appends exactly corners.size() - 2 triangles to `out`, as indices into `corners` (0 .. n-1),
/// each wound like the polygon (counter-clockwise about its Newell normal), so a consistently
/// oriented polygon mesh stays consistently oriented. Needs n >= 3 (fewer appends nothing).
/// O(n log n) time, O(n) memory, for any input (the fallback included).
PolygonCut triangulatePolygon(std::span<const Vec3> corners, std::vector<Triangle>& out);

/// The same for a face of a mesh: corners are indices into `vertices`; appends the triangles
/// (as indices into `vertices`) to `triangles`. A triangle goes through without allocating.
PolygonCut appendFaceTriangles(const std::vector<Vec3>& vertices, std::span<const std::uint32_t> corners,
                               std::vector<Triangle>& triangles);

}  // namespace clod::detail
