#pragma once
// Reducing a node's medial spheres to `branching` children by merge and burst, after Bradshaw &
// O'Sullivan, "Adaptive medial-axis approximation for sphere-tree construction", ACM TOG 23(1),
// 2004 (we have no copy of the paper; this follows the description of the method in
// ../shared/REFERENCES.md and the wider sphere-tree literature, in our own words).
//
// The algorithm, per node of the tree (top-down, one node at a time):
//  1. Start: every piece of the node's surface belongs to the inner medial pole of the surface
//     sample nearest to it, so the node starts with one sphere per distinct medial sphere it
//     touches ("many spheres"). A sphere is responsible for the surface points of its pieces.
//     Deep in the tree a node touches only a few medial spheres (the medial axis is sampled once,
//     for the whole mesh); when fewer than 2 * branching exist, every piece starts as its own
//     sphere instead (deviation: Bradshaw samples each region's medial axis anew, adaptively).
//  2. Merge: two neighbouring spheres (their surface pieces share a mesh vertex) are replaced by
//     one sphere that covers both spheres' surface points (not the spheres themselves). The pair
//     whose merged sphere has the least estimated fit goes first (the absolute fit, not the
//     added fit(merged) - max(fit(a), fit(b)): on the shared meshes the added error let one
//     sphere absorb its neighbours at little added cost and left a level's worst sphere twice
//     as loose). Pairs sit in a priority queue; a pair whose spheres changed since it was queued
//     is re-evaluated when it comes up and queued again (lazy updates; the old estimate is
//     nearly always a lower bound, as merging only grows spheres).
//  3. Burst: a sphere is removed and each of its pieces handed to the neighbour whose sphere it
//     sticks out of least; those neighbours grow. Its cost is the largest estimated fit among the
//     grown neighbours. Bursts and merges share the queue, so a burst happens only when it costs less
//     than every merge; a burst whose neighbourhood changed is re-evaluated when it comes up.
//  4. Repeat 2-3 until `branching` spheres remain. Separate surface components are linked to
//     their two nearest spheres at the start (and any leftovers when the queue runs dry).
//  5. Expand (done by the caller): each remaining sphere is re-fitted to all of its pieces
//     exactly, the centre chosen to minimise the estimated overshoot, so coverage is exact.
// During 2-3 a sphere is summarised by a bounded point set: its extreme surface points in 14
// fixed directions (which keep its smallest enclosing sphere nearly exact, and merge exactly by
// taking the more extreme point per direction) plus up to 16 area-spread interior surface
// points; its fit is the estimated overshoot against that set, with the centre chosen among the
// smallest enclosing sphere's centre, the area-weighted medial centre (mean of its pieces' inner
// poles) and their midpoint. Each evaluation is then O(1), and reducing n spheres costs
// O(n * degree * log n).
// Deviations from the paper, beyond step 1: the fit that steers merge and burst is estimated at
// 16 directions against the summary points (Bradshaw evaluates against the full sample set), the
// "neighbour" relation comes from mesh adjacency rather than from the medial axis' own
// connectivity, and a sphere's centre is searched on a segment instead of optimised freely.

#include <cstdint>
#include <span>
#include <vector>

#include "clod/mesh.h"
#include "surface_piece.h"

namespace clod::detail {

/// Triangles around each vertex, CSR (offsets.size() == vertexCount + 1).
struct VertexTriangles {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> triangles;
  explicit VertexTriangles(const TriangleMesh& mesh);
  std::span<const std::uint32_t> around(std::uint32_t v) const {
    return {triangles.data() + offsets[v], offsets[v + 1] - offsets[v]};
  }
};

/// Groups `pieces` into at most `k` clusters by the merge/burst reduction above. Returns a
/// cluster label per piece, labels in [0, clusterCount) with every label used; clusterCount is
/// min(k, number of pieces) unless disconnected leftovers cannot be linked (never observed).
/// Pieces need their `pole` and `poleOffset` set. Deterministic; allocates per call.
std::vector<std::uint32_t> reduceByMergeAndBurst(const TriangleMesh& mesh, const VertexTriangles& adjacency,
                                                 std::span<const SurfacePiece> pieces, std::uint32_t k);

}  // namespace clod::detail
