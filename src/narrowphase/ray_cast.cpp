// The first triangle a ray meets (ray_cast.h).
#include "ray_cast.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "proximity/triangle_bvh.h"

namespace clod::detail {
namespace {

// Entry parameter of the ray into one slot's box, or +inf when it misses within (tMin, tMax).
// The box is float, rounded outward, so it still contains its triangles; the slab test runs in
// double on it.
double slotEntry(const Bvh4Node& node, int s, const Vec3& origin, const Vec3& inverse, double tMin, double tMax) {
  const double lo[3] = {node.minX[s], node.minY[s], node.minZ[s]};
  const double hi[3] = {node.maxX[s], node.maxY[s], node.maxZ[s]};
  double enter = tMin, leave = tMax;
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(inverse[d])) {  // parallel to this slab: inside it or never
      if (origin[d] < lo[d] || origin[d] > hi[d]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = (lo[d] - origin[d]) * inverse[d], t1 = (hi[d] - origin[d]) * inverse[d];
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
  }
  return enter <= leave ? enter : std::numeric_limits<double>::infinity();
}

// Ray-triangle crossing by the scalar triple products (Moeller and Trumbore 1997): t along the
// ray, or false when the ray misses the triangle or lies in its plane. The border counts as
// inside, so a ray through a shared edge hits one of the two triangles at least.
bool crossTriangle(const Vec3& origin, const Vec3& dir, const Vec3& a, const Vec3& b, const Vec3& c, double& t) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = dir.cross(e2);
  const double det = e1.dot(p);
  if (det == 0.0 || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  const Vec3 s = origin - a;
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Vec3 q = s.cross(e1);
  const double v = dir.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  t = e2.dot(q) * inv;
  return true;
}

}  // namespace

RayHit firstHit(const CollisionBody& body, const Vec3& origin, const Vec3& dir, double tMin, double tMax) {
  const TriangleBvh& bvh = body.triangleBvh();
  const TriangleMesh& mesh = body.mesh();
  const Vec3 inverse(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  RayHit best;
  std::array<std::uint32_t, 3 * TriangleBvh::kMaxDepth + 1> stack{};
  std::uint32_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Bvh4Node& node = bvh.nodes()[stack[--top]];
    for (int s = 0; s < 4; ++s) {
      if (node.emptySlot(s)) continue;
      if (!(slotEntry(node, s, origin, inverse, tMin, std::min(tMax, best.t)) < best.t)) continue;
      if (node.count[s] == 0) {
        stack[top++] = node.child[s];
        continue;
      }
      for (std::uint32_t i = node.child[s]; i < node.child[s] + node.count[s]; ++i) {
        const std::uint32_t tri = bvh.order()[i];
        double t = 0.0;
        if (!crossTriangle(origin, dir, mesh.corner(tri, 0), mesh.corner(tri, 1), mesh.corner(tri, 2), t)) continue;
        if (t <= tMin || t >= tMax || t >= best.t) continue;
        best = {true, t, tri, mesh.triangleNormal(tri).dot(dir) > 0.0};
      }
    }
  }
  return best;
}

double distanceToLeave(const CollisionBody& body, const Vec3& origin, const Vec3& dir, double tMin, RayHit& exit) {
  exit = firstHit(body, origin, dir, tMin);
  return exit.hit && exit.leaving ? exit.t : 0.0;
}

}  // namespace clod::detail
