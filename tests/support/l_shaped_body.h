#pragma once
// A test mesh: a closed, non-convex L-shaped body with few face normals.
#include <array>
#include <cstdint>

#include "clod/mesh.h"

namespace clod::test {

// A 4 x 4 x 0.5 floor (top face at z = 0) with a 1 m thick, 2 m high wall along its +x end (inner
// face at x = 1): the L profile {(-2, -0.5), (2, -0.5), (2, 2), (1, 2), (1, 0), (-2, 0)} in (x, z)
// extruded over y in [-2, 2]. 12 vertices, 20 triangles, six face normals: one faceted patch
// that is not convex (its convex hull holds the pocket above the floor and beside the wall),
// counter-clockwise seen from outside.
inline TriangleMesh makeLShapedBody() {
  const double profile[6][2] = {{-2, -0.5}, {2, -0.5}, {2, 2}, {1, 2}, {1, 0}, {-2, 0}};
  TriangleMesh mesh;
  for (double y : {-2.0, 2.0})
    for (const auto& p : profile) mesh.vertices.emplace_back(p[0], y, p[1]);
  // The profile is counter-clockwise seen from -y: the y = -2 cap keeps its order, the y = 2 cap
  // reverses it. Each cap is the floor's quad and the wall's quad.
  for (const auto& t : {std::array<std::uint32_t, 3>{0, 1, 4}, {0, 4, 5}, {1, 2, 3}, {1, 3, 4}}) {
    mesh.triangles.push_back({t[0], t[1], t[2]});
    mesh.triangles.push_back({t[2] + 6, t[1] + 6, t[0] + 6});
  }
  for (std::uint32_t i = 0; i < 6; ++i) {
    const std::uint32_t j = (i + 1) % 6;
    mesh.triangles.push_back({i, i + 6, j + 6});
    mesh.triangles.push_back({i, j + 6, j});
  }
  return mesh;
}

}  // namespace clod::test
