#pragma once
// Edge connectivity of a triangle mesh: the unique undirected edges, which triangles use
// each edge, and which edges bound each triangle. Shared by validation (boundary and
// non-manifold counts), pseudonormals (per-edge normals) and closest-feature reporting
// (an "edge feature" index is an index into edges()).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "clod/mesh.h"

namespace clod {

/// Undirected edge with v0 < v1.
struct Edge {
  std::uint32_t v0;
  std::uint32_t v1;
};

class MeshTopology {
public:
  /// Builds the edge tables in O(T log T). The mesh's indices must be in range.
  explicit MeshTopology(const TriangleMesh& mesh);

  std::span<const Edge> edges() const { return edges_; }
  std::uint32_t edgeCount() const { return static_cast<std::uint32_t>(edges_.size()); }

  /// Edge index of the side of triangle t that runs from corner k to corner (k+1)%3.
  std::uint32_t triangleEdge(std::uint32_t t, int k) const { return triangleEdges_[t][k]; }

  /// Triangles that use edge e (1 for a boundary edge, 2 for a manifold interior edge,
  /// more for a non-manifold edge).
  std::span<const std::uint32_t> edgeTriangles(std::uint32_t e) const {
    return {edgeTriangleList_.data() + edgeTriangleOffset_[e],
            edgeTriangleOffset_[e + 1] - edgeTriangleOffset_[e]};
  }

  std::uint32_t boundaryEdgeCount() const { return boundaryEdges_; }
  std::uint32_t nonManifoldEdgeCount() const { return nonManifoldEdges_; }
  /// True when every edge is shared by exactly two triangles.
  bool closed() const { return boundaryEdges_ == 0 && nonManifoldEdges_ == 0; }

private:
  std::vector<Edge> edges_;
  std::vector<std::array<std::uint32_t, 3>> triangleEdges_;
  std::vector<std::uint32_t> edgeTriangleOffset_;
  std::vector<std::uint32_t> edgeTriangleList_;
  std::uint32_t boundaryEdges_ = 0;
  std::uint32_t nonManifoldEdges_ = 0;
};

}  // namespace clod
