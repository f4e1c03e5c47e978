#pragma once
// The triangle mesh every stage of clod consumes.
//
// Conventions: triangles are counter-clockwise seen from outside, so the face normal
// (b - a) x (c - a) points outward on a correctly oriented closed mesh. Indices are 32-bit.

#include <array>
#include <cstdint>
#include <vector>

#include "clod/math.h"

namespace clod {

using Triangle = std::array<std::uint32_t, 3>;

/// An indexed triangle mesh. Plain data: load it (mesh_io.h), check it (mesh_validation.h),
/// then hand it to builders. Builders take it by const reference and never keep a pointer.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;

  std::uint32_t vertexCount() const { return static_cast<std::uint32_t>(vertices.size()); }
  std::uint32_t triangleCount() const { return static_cast<std::uint32_t>(triangles.size()); }

  /// Corner k (0..2) of triangle t.
  const Vec3& corner(std::uint32_t t, int k) const { return vertices[triangles[t][k]]; }
  /// Unnormalised normal (b - a) x (c - a); its length is twice the area.
  Vec3 triangleCross(std::uint32_t t) const {
    const Vec3& a = corner(t, 0);
    return (corner(t, 1) - a).cross(corner(t, 2) - a);
  }
  /// Unit face normal, or zero for a degenerate triangle.
  Vec3 triangleNormal(std::uint32_t t) const {
    Vec3 n = triangleCross(t);
    double len = n.norm();
    return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
  }
  double triangleArea(std::uint32_t t) const { return 0.5 * triangleCross(t).norm(); }

  Aabb bounds() const {
    Aabb box;
    for (const Vec3& v : vertices) box.extend(v);
    return box;
  }
};

}  // namespace clod
