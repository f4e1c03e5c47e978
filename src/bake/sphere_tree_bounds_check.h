#pragma once
// The geometric check of a sphere-tree against its mesh: the spheres must bound the surface.
// The structural checks (checkSphereTree) cannot see a sphere moved away from the mesh, and a
// tree that misses the surface makes the sphere-based models report "no collision" silently.

#include "clod/mesh.h"
#include "clod/sphere_tree.h"
#include "section_codec.h"

namespace clod::detail {

/// Absolute tolerance of checkSphereTreeBoundsMesh, relative to the mesh's bounding-box
/// diagonal. Builders grow every radius by 1e-9 of the diagonal (kCoverageSlackRel) to absorb
/// their own rounding, and the STRE codec only grows balls (a decoded ball contains the
/// original), so a valid tree needs no slack but the rounding of the check's own |v - c|, a
/// few ulps of the coordinates. 1e-6 leaves a thousandfold margin over the builders' allowance
/// and lets through only errors far below any contact model's error bound.
inline constexpr double kSphereBoundsToleranceRel = 1e-6;

/// Throws via `complain` unless (1) the root sphere contains every corner of every triangle and
/// (2) on every level, each corner of each triangle a sphere lists lies in at least one of the
/// level's spheres listing that triangle (a sphere bounds only its clipped part of a triangle,
/// so containment holds for the level's spheres together, not for each sphere), and every
/// triangle is listed on every level (each level covers the whole surface). The tree must have
/// passed checkSphereTree for a mesh with mesh.triangleCount() triangles. Names the sphere (the
/// nearest listing one), its level, the triangle and the vertex. O(levels * triangles +
/// 3 * total list length), i.e. linear in the lists (every level lists every triangle), and 16
/// bytes per triangle.
void checkSphereTreeBoundsMesh(const SphereTree& tree, const TriangleMesh& mesh, const Complaint& complain);

}  // namespace clod::detail
