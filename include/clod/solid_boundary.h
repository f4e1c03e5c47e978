// The surface that bounds the solid a triangle soup encloses.
//
// A soup made of overlapping parts (a CAD export, a scan glued from pieces, a game mesh of
// intersecting closed shells) has faces inside its solid: walls with the solid on both sides.
// Their distance is no distance to the solid's surface; a field built over them has a kink
// (-|d|) along every wall that no interpolation follows, and where closed parts overlap the
// pseudonormal sign is wrong (a point inside A just behind B's wall is "outside B"). The solid
// -- the points of generalized winding number >= 1/2 -- is bounded by the rest.
#pragma once

#include <cstdint>

#include "clod/mesh.h"
#include "clod/proximity.h"

namespace clod {

/// What solidBoundary() kept.
struct SolidBoundary {
  TriangleMesh mesh;                  ///< the boundary's triangles (whole faces and pieces)
  std::uint32_t droppedTriangles = 0; ///< faces wholly inside the solid
  std::uint32_t splitTriangles = 0;   ///< faces the boundary crosses, kept in pieces
  /// False when every face bounds the solid whole (mesh is then a copy of the input).
  bool changed() const { return droppedTriangles + splitTriangles > 0; }
};

/// The part of distance.mesh() that bounds its solid. A point of a face is inside the solid's
/// walls when the winding number just in front of it and just behind it are both >= 1/2. Each
/// face is sampled (centroid and three points towards its corners) on midpoint subdivisions no
/// coarser than `sampleSpacing`; pieces whose samples all agree are kept or dropped, pieces
/// whose samples disagree are split until their edges are shorter than `resolution` and then
/// kept. A face that bounds the solid everywhere it was sampled is kept whole. So a wall piece
/// is left only within `resolution` of where the boundary crosses a face, and a crossing that
/// falls between samples `sampleSpacing` apart can be missed. Degenerate faces are kept. Bounded
/// work whatever the soup: the spacing grows so that the coarse samples are at most ~2^17, and a
/// face's mixed pieces are split at most max(16, 2^16 / T) times (T triangles), then kept.
/// Preconditions: 0 < resolution <= sampleSpacing (kInvalidArgument otherwise). Parallel.
SolidBoundary solidBoundary(const MeshDistance& distance, double resolution, double sampleSpacing);

}  // namespace clod
