#pragma once
// Helpers shared by the mesh layer's tests: brute-force oracles written independently of
// src/mesh (maps and sets, quadratic loops), and paths to the test data.

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "clod/mesh.h"
#include "clod/mesh_validation.h"
#include "support/test_scale.h"

namespace clod::test {

inline std::string goodFile(const std::string& name) { return std::string(CLOD_TEST_DATA_DIR) + "/good/" + name; }
inline std::string badFile(const std::string& name) { return std::string(CLOD_TEST_DATA_DIR) + "/bad/" + name; }
inline std::string sharedMesh(const std::string& name) { return std::string(CLOD_SHARED_MESH_DIR) + "/" + name; }

/// Brute-force edge use counts: undirected edge (min, max) -> number of triangle sides on it.
inline std::map<std::pair<std::uint32_t, std::uint32_t>, int> countEdgeUses(const TriangleMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = t[k], b = t[(k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  return uses;
}

/// Brute-force connected components of the vertices used by triangles (flood fill).
inline std::uint32_t countComponentsByFloodFill(const TriangleMesh& mesh) {
  std::map<std::uint32_t, std::set<std::uint32_t>> neighbours;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) neighbours[t[k]].insert(t[j]);
  std::set<std::uint32_t> seen;
  std::uint32_t components = 0;
  for (const auto& [start, unused] : neighbours) {
    if (seen.count(start)) continue;
    ++components;
    std::vector<std::uint32_t> stack{start};
    seen.insert(start);
    while (!stack.empty()) {
      std::uint32_t v = stack.back();
      stack.pop_back();
      for (std::uint32_t w : neighbours[v])
        if (seen.insert(w).second) stack.push_back(w);
    }
  }
  return components;
}

/// A generated part mesh checked by brute force: closed and consistently oriented (every
/// undirected edge used by two triangles, every directed edge once), Euler characteristic
/// 2 - 2 genus, no zero-area triangle, one component (flood fill and validateMesh), manifold,
/// outward; returns the signed volume validateMesh reports.
inline double expectClosedOrientedGenus(const TriangleMesh& mesh, int genus) {
  const auto uses = countEdgeUses(mesh);
  for (const auto& [edge, count] : uses) EXPECT_EQ(count, 2) << "edge " << edge.first << "-" << edge.second;
  std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(directed.insert({t[k], t[(k + 1) % 3]}).second) << "directed edge used twice";
  EXPECT_EQ(std::int64_t(mesh.vertexCount()) - std::int64_t(uses.size()) + std::int64_t(mesh.triangleCount()),
            2 - 2 * genus);
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) EXPECT_GT(mesh.triangleArea(t), 0.0) << "triangle " << t;
  const MeshReport report = validateMesh(mesh);
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.consistentlyOriented);
  EXPECT_EQ(report.components, 1u);
  EXPECT_EQ(report.degenerateTriangles, 0u);
  EXPECT_EQ(report.nonManifoldVertices, 0u);
  EXPECT_EQ(countComponentsByFloodFill(mesh), 1u);
  EXPECT_GT(report.signedVolume.value_or(0.0), 0.0);
  return report.signedVolume.value_or(0.0);
}

}  // namespace clod::test
