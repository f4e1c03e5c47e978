#pragma once
// The support points of a sphere's patch (the triangles a sphere-tree sphere is responsible for):
// a small set of its vertices whose maximum of n . v over them is the patch's support in any
// direction n, to within a stated slack. CollisionBody keeps one per curved sphere; the cfm model
// uses it as the patch's support function and as the vertices a curved patch rests on
// (docs/narrow-phase.md, "Curved patches").

#include <cstdint>
#include <span>
#include <vector>

#include "clod/mesh.h"

namespace clod::detail {

/// Patches of at most this many distinct vertices keep all of them (slack 0).
inline constexpr std::size_t kMaxPatchSupportVertices = 64;
/// Larger patches keep their convex hull's vertices if it has at most this many.
inline constexpr std::size_t kMaxHullSupportVertices = 1024;

/// Appends to `out` the support vertices (indices into mesh.vertices, ascending) of the patch made
/// of `triangles` and returns the slack: the most by which max over them of n . v can fall short
/// of the patch's support in any direction n. Small patches keep every vertex, larger ones their
/// convex hull's vertices (qhull), and those whose hull has more than kMaxHullSupportVertices the
/// extreme vertex of each of 1,024 spherical Fibonacci directions (an inner approximation of the
/// hull). The slack is twice the largest shortfall measured over 1,024 directions (0 up to
/// rounding and qhull's joggle for the hull).
double appendPatchSupportVertices(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                  std::vector<std::uint32_t>& out);

}  // namespace clod::detail
