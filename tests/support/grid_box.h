#pragma once
// A test mesh: a box whose faces are split into grids of squares.
#include <array>
#include <map>

#include "clod/mesh.h"

namespace clod::test {

// A box whose faces are each split into n x n squares (two triangles each), welded. Still a
// convex polyhedron: its root patch lists the 8 corners, and two of them are answered by the
// separating-axis test (CollisionBody::patchIsWholeConvexBody). With topDent > 0 the top face's
// grid point (1, 1) is pushed that fraction of the half height into the box (n >= 2): no longer
// convex, so the exact model tests its triangles and the contact tree samples its fields, while
// the bottom face -- what rests on a floor -- stays flat.
inline TriangleMesh makeGridBox(const Vec3& half, int n, double topDent = 0.0) {
  TriangleMesh mesh;
  std::map<std::array<long long, 3>, std::uint32_t> index;  // welded grid points, in units of 1/n
  auto vertex = [&](const std::array<int, 3>& g) {
    const std::array<long long, 3> key{g[0], g[1], g[2]};
    auto [it, inserted] = index.try_emplace(key, mesh.vertexCount());
    if (inserted) mesh.vertices.push_back(Vec3(half.x() * (2.0 * g[0] / n - 1.0), half.y() * (2.0 * g[1] / n - 1.0),
                                               half.z() * (2.0 * g[2] / n - 1.0)));
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          auto at = [&](int di, int dj) {
            std::array<int, 3> g{};
            g[axis] = side * n;
            g[u] = i + di;
            g[v] = j + dj;
            return vertex(g);
          };
          const std::uint32_t a = at(0, 0), b = at(1, 0), c = at(1, 1), d = at(0, 1);
          // (u, v, axis) is right-handed: counter-clockwise seen from +axis on the far side.
          if (side == 1) {
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
          } else {
            mesh.triangles.push_back({a, c, b});
            mesh.triangles.push_back({a, d, c});
          }
        }
      }
    }
  }
  if (topDent > 0.0) mesh.vertices[vertex({1, 1, n})].z() -= topDent * half.z();
  return mesh;
}

}  // namespace clod::test
