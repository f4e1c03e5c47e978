#pragma once
// Internal: outward normals of every feature of a mesh, for closest-feature reporting and for
// the sign of the distance (Baerentzen & Aanaes, "Signed distance computation using the angle
// weighted pseudonormal", IEEE TVCG 11(3), 2005).

#include <vector>

#include "clod/mesh.h"
#include "clod/mesh_topology.h"

namespace clod::detail {

struct Pseudonormals {
  std::vector<Vec3> face;    ///< unit face normal per triangle; zero for a degenerate triangle
  std::vector<Vec3> edge;    ///< per MeshTopology edge: normalised sum of its triangles' normals
  std::vector<Vec3> vertex;  ///< per vertex: normalised angle-weighted sum of incident face normals
};

/// O(T). Degenerate triangles get zero weight; a feature whose weights cancel or vanish gets a
/// zero normal, which callers must treat as "no direction" (never NaN).
Pseudonormals computePseudonormals(const TriangleMesh& mesh, const MeshTopology& topology);

}  // namespace clod::detail
