#include "clod/primitives.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_map>

#include "clod/error.h"

namespace clod {

namespace {

void requirePositive(double value, const char* name) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(ErrorCode::kInvalidArgument, std::string(name) + " " + std::to_string(value) + " is not a positive finite number");
}

}  // namespace

TriangleMesh makeBox(const Vec3& halfExtents) {
  requirePositive(halfExtents.x(), "box half extent x");
  requirePositive(halfExtents.y(), "box half extent y");
  requirePositive(halfExtents.z(), "box half extent z");
  TriangleMesh mesh;
  // Vertex index bits: 1 -> +x, 2 -> +y, 4 -> +z.
  for (std::uint32_t i = 0; i < 8; ++i)
    mesh.vertices.emplace_back((i & 1 ? 1.0 : -1.0) * halfExtents.x(), (i & 2 ? 1.0 : -1.0) * halfExtents.y(),
                               (i & 4 ? 1.0 : -1.0) * halfExtents.z());
  // Each face as a quad, counter-clockwise seen from outside.
  const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  return mesh;
}

TriangleMesh makeIcosphere(double radius, std::uint32_t subdivisions) {
  requirePositive(radius, "icosphere radius");
  // 20 * 4^10 = 20,971,520 triangles is already far beyond any use; more overflows soon after.
  if (subdivisions > 10)
    throw Error(ErrorCode::kInvalidArgument, "icosphere subdivisions " + std::to_string(subdivisions) + " > 10");
  TriangleMesh mesh;
  // Icosahedron: cyclic permutations of (0, +-1, +-phi).
  const double phi = std::numbers::phi;
  const double raw[12][3] = {{-1, phi, 0}, {1, phi, 0},  {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
                             {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1},  {phi, 0, 1},  {-phi, 0, -1}, {-phi, 0, 1}};
  for (const auto& p : raw) mesh.vertices.push_back(Vec3(p[0], p[1], p[2]).normalized() * radius);
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (std::uint32_t level = 0; level < subdivisions; ++level) {
    std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
    midpoints.reserve(mesh.triangles.size() * 2);
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const std::uint64_t key = a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
      auto [it, inserted] = midpoints.try_emplace(key, mesh.vertexCount());
      if (inserted) mesh.vertices.push_back((mesh.vertices[a] + mesh.vertices[b]).normalized() * radius);
      return it->second;
    };
    std::vector<Triangle> refined;
    refined.reserve(mesh.triangles.size() * 4);
    for (const Triangle& t : mesh.triangles) {
      const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      refined.push_back({t[0], ab, ca});
      refined.push_back({t[1], bc, ab});
      refined.push_back({t[2], ca, bc});
      refined.push_back({ab, bc, ca});
    }
    mesh.triangles = std::move(refined);
  }
  return mesh;
}

TriangleMesh makeBallHull(double radius, std::uint32_t subdivisions) {
  requirePositive(radius, "ball radius");
  // Built at radius 1 and scaled once: a huge radius (1e300) would overflow the planes' normals.
  TriangleMesh mesh = makeIcosphere(1.0, subdivisions);
  // The smallest distance of a face's plane from the centre: the faces around the icosahedron's
  // twelve corners are the most tilted ones.
  double nearest = 1.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    nearest = std::min(nearest, std::abs((b - a).cross(c - a).normalized().dot(a)));
  }
  // Rounding of the scaled vertices moves a plane by ~1e-16 of the radius: a hair's margin keeps
  // every plane at least `radius` away.
  const double scale = radius * ((1.0 + 1e-12) / nearest);
  for (Vec3& v : mesh.vertices) v *= scale;
  return mesh;
}

TriangleMesh makeCylinder(double radius, double halfHeight, std::uint32_t segments) {
  requirePositive(radius, "cylinder radius");
  requirePositive(halfHeight, "cylinder half height");
  if (segments < 3 || segments > (1u << 28))
    throw Error(ErrorCode::kInvalidArgument, "cylinder segments " + std::to_string(segments) + " not in [3, 2^28]");
  TriangleMesh mesh;
  // Vertices 2i on the bottom ring, 2i+1 on the top ring, then the two cap centres.
  for (std::uint32_t i = 0; i < segments; ++i) {
    const double angle = 2.0 * std::numbers::pi * double(i) / double(segments);
    const double x = radius * std::cos(angle), y = radius * std::sin(angle);
    mesh.vertices.emplace_back(x, y, -halfHeight);
    mesh.vertices.emplace_back(x, y, halfHeight);
  }
  const std::uint32_t bottom = 2 * segments, top = bottom + 1;
  mesh.vertices.emplace_back(0.0, 0.0, -halfHeight);
  mesh.vertices.emplace_back(0.0, 0.0, halfHeight);
  for (std::uint32_t i = 0; i < segments; ++i) {
    const std::uint32_t j = (i + 1) % segments;
    const std::uint32_t b0 = 2 * i, t0 = 2 * i + 1, b1 = 2 * j, t1 = 2 * j + 1;
    mesh.triangles.push_back({b0, b1, t1});
    mesh.triangles.push_back({b0, t1, t0});
    mesh.triangles.push_back({top, t0, t1});
    mesh.triangles.push_back({bottom, b1, b0});
  }
  return mesh;
}

}  // namespace clod
