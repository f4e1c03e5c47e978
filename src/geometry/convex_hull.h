#pragma once
// The vertices of a point set's convex hull (qhull), for the support sets of sphere patches
// (narrowphase/patch_hull.h) and contact-tree cells (clod/cell_support.h).

#include <cstdint>
#include <span>
#include <vector>

#include "clod/math.h"

namespace clod::detail {

/// Fills `out` with the indices into `points` of its convex hull's vertices, in qhull's order.
/// QJ joggles coplanar and cospherical input by ~1e-11 of its size, so a point on a flat hull
/// face may be left out: it is never more extreme than the face's corners. False (and `out`
/// unspecified) for fewer than 4 points, when qhull fails, or when the hull has more than
/// `maxVertices` vertices. qhull's messages are captured, never printed.
bool convexHullVertices(std::span<const Vec3> points, std::size_t maxVertices, std::vector<std::uint32_t>& out);

}  // namespace clod::detail
