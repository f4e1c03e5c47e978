#include "pseudonormals.h"

#include <cmath>

namespace clod::detail {
namespace {

Vec3 normalizedOrZero(const Vec3& v) {
  const double len = v.norm();
  return len > 0.0 ? Vec3(v / len) : Vec3::Zero();
}

}  // namespace

Pseudonormals computePseudonormals(const TriangleMesh& mesh, const MeshTopology& topology) {
  Pseudonormals out;
  const std::uint32_t triangleCount = mesh.triangleCount();
  out.face.resize(triangleCount);
  out.vertex.assign(mesh.vertexCount(), Vec3::Zero());
  for (std::uint32_t t = 0; t < triangleCount; ++t) {
    const Vec3 n = mesh.triangleNormal(t);
    out.face[t] = n;
    if (n.isZero()) continue;  // degenerate: zero weight everywhere
    for (int k = 0; k < 3; ++k) {
      const Vec3& corner = mesh.corner(t, k);
      const Vec3 u = mesh.corner(t, (k + 1) % 3) - corner;
      const Vec3 v = mesh.corner(t, (k + 2) % 3) - corner;
      // atan2 of |u x v| and u.v is accurate for every angle, unlike acos of the normalised dot.
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v));
      out.vertex[mesh.triangles[t][k]] += angle * n;
    }
  }
  for (Vec3& n : out.vertex) n = normalizedOrZero(n);

  out.edge.resize(topology.edgeCount());
  for (std::uint32_t e = 0; e < topology.edgeCount(); ++e) {
    Vec3 sum = Vec3::Zero();
    for (std::uint32_t t : topology.edgeTriangles(e)) sum += out.face[t];
    out.edge[e] = normalizedOrZero(sum);
  }
  return out;
}

}  // namespace clod::detail
