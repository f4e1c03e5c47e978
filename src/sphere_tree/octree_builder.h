#pragma once
// Hubbard's basic sphere-tree: spheres around occupied octree cells, each shrunk to the
// smallest sphere of the surface inside its cell.

#include "clod/sphere_tree.h"
#include "clod/sphere_tree_builder.h"

namespace clod::detail {

/// Cells split into a grid of nx * ny * nz children with nx*ny*nz <= branching, refining the
/// axis with the longest child extent first: 2x2x2 for branching 8 (the octree), 2x2x1 for 4,
/// 2x1x1 for 2, 3x3x3 for 27. Empty child cells get no sphere.
SphereTree buildOctreeSphereTree(const TriangleMesh& mesh, const SphereTreeSettings& settings);

}  // namespace clod::detail
