#pragma once
// Test meshes: a floor made of one open quad, or of a grid of them, what a user's ground mesh
// often is.
#include "clod/mesh.h"

namespace clod::test {

// The rectangle [-hx, hx] x [-hy, hy] at height z as two triangles facing +z (counter-clockwise
// seen from above): an open sheet, 4 vertices.
inline TriangleMesh makeFloorQuad(double hx, double hy, double z = 0.0) {
  TriangleMesh quad;
  quad.vertices = {Vec3(-hx, -hy, z), Vec3(hx, -hy, z), Vec3(-hx, hy, z), Vec3(hx, hy, z)};
  quad.triangles = {{0, 1, 3}, {0, 3, 2}};
  return quad;
}

// The same rectangle as an n x n grid of quads (2 n^2 triangles, facing +z): a tessellated floor,
// whose pieces fall into different sphere-tree leaves.
inline TriangleMesh makeFloorGrid(double hx, double hy, int n, double z = 0.0) {
  TriangleMesh grid;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) grid.vertices.emplace_back(-hx + 2.0 * hx * i / n, -hy + 2.0 * hy * j / n, z);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (n + 1) + i), b = a + 1, c = a + static_cast<std::uint32_t>(n) + 1, d = c + 1;
      grid.triangles.push_back({a, b, d});
      grid.triangles.push_back({a, d, c});
    }
  return grid;
}

}  // namespace clod::test
