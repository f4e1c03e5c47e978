#pragma once
// A test mesh: a floor made of one open quad, what a user's ground mesh often is.
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

}  // namespace clod::test
