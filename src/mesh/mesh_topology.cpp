#include "clod/mesh_topology.h"

#include <algorithm>

namespace clod {

MeshTopology::MeshTopology(const TriangleMesh& mesh) {
  const std::uint32_t triangleCount = mesh.triangleCount();
  // One half-edge record per triangle side, sorted by its undirected key so equal edges are adjacent.
  struct HalfEdge {
    std::uint64_t key;
    std::uint32_t triangle;
    std::uint32_t side;
  };
  std::vector<HalfEdge> halfEdges;
  halfEdges.reserve(std::size_t(triangleCount) * 3);
  for (std::uint32_t t = 0; t < triangleCount; ++t) {
    for (std::uint32_t k = 0; k < 3; ++k) {
      std::uint32_t a = mesh.triangles[t][k];
      std::uint32_t b = mesh.triangles[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      halfEdges.push_back({(std::uint64_t(a) << 32) | b, t, k});
    }
  }
  std::sort(halfEdges.begin(), halfEdges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });

  triangleEdges_.resize(triangleCount);
  edgeTriangleList_.reserve(halfEdges.size());
  for (std::size_t i = 0; i < halfEdges.size();) {
    std::size_t j = i;
    const std::uint32_t edgeIndex = static_cast<std::uint32_t>(edges_.size());
    edgeTriangleOffset_.push_back(static_cast<std::uint32_t>(edgeTriangleList_.size()));
    for (; j < halfEdges.size() && halfEdges[j].key == halfEdges[i].key; ++j) {
      triangleEdges_[halfEdges[j].triangle][halfEdges[j].side] = edgeIndex;
      edgeTriangleList_.push_back(halfEdges[j].triangle);
    }
    edges_.push_back({std::uint32_t(halfEdges[i].key >> 32), std::uint32_t(halfEdges[i].key)});
    const std::size_t uses = j - i;
    if (uses == 1) ++boundaryEdges_;
    if (uses > 2) ++nonManifoldEdges_;
    i = j;
  }
  edgeTriangleOffset_.push_back(static_cast<std::uint32_t>(edgeTriangleList_.size()));
}

}  // namespace clod
