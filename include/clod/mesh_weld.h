#pragma once
// Welding: merging vertices that lie (nearly) on top of each other, so that triangles which
// share a corner in space also share a vertex index. File formats that store one vertex per
// face corner (STL, OBJ read through Assimp, glTF seams) need this before any topology
// (boundary edges, components, orientation) means anything.

#include <cstdint>
#include <vector>

#include "clod/mesh.h"

namespace clod {

/// What weldVertices did.
struct WeldResult {
  /// For every input vertex, the index of the output vertex it became.
  std::vector<std::uint32_t> remap;
  /// Input vertex count minus output vertex count.
  std::uint32_t mergedCount = 0;
  /// Triangles that ended up with two or three equal corner indices after welding (kept, not
  /// removed: they are degenerate and validateMesh counts them).
  std::uint32_t collapsedTriangles = 0;
};

/// Merges vertices closer than `toleranceAbs` (Euclidean distance, mesh units), in place.
///
/// Rule (greedy, in input order): vertex i becomes a new output vertex unless an earlier
/// output vertex lies within `toleranceAbs` of it (distance <= toleranceAbs), in which case it
/// maps to the earliest (lowest-index) such one. Output vertices keep the position of the input vertex that
/// created them (no averaging), so positions never move and the result is deterministic. After
/// the call, every pair of output vertices is more than `toleranceAbs` apart and every input
/// vertex lies within `toleranceAbs` of the output vertex it maps to. With toleranceAbs == 0 only
/// bit-identical positions merge. Output vertices are in order of first appearance; unreferenced
/// vertices are kept. Triangle indices are rewritten; no triangle is removed.
///
/// Preconditions (CLOD_ASSERT): toleranceAbs >= 0, every coordinate finite, every triangle
/// index < vertexCount().
/// Complexity: O(V) expected time (uniform grid with cell size = toleranceAbs, hashed), O(V) memory.
WeldResult weldVertices(TriangleMesh& mesh, double toleranceAbs);

}  // namespace clod
