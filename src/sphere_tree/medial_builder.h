#pragma once
// Medial-axis sphere-tree builder (after Hubbard 1996 and Bradshaw & O'Sullivan 2004).

#include "clod/sphere_tree.h"
#include "clod/sphere_tree_builder.h"

namespace clod::detail {

/// Top-down: every node's surface pieces are clustered around the medial axis (each piece is
/// represented by a point pulled from the surface towards its inner medial pole, so both sides
/// of a thin part fall into one cluster), then each cluster gets the sphere of lowest estimated
/// fit among candidates (smallest enclosing sphere; sphere centred on the cluster's medial
/// points, expanded to cover; their midpoint), grown to contain every piece of its cluster.
SphereTree buildMedialSphereTree(const TriangleMesh& mesh, const SphereTreeSettings& settings);

}  // namespace clod::detail
