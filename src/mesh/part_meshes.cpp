#include "clod/part_meshes.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <string>

#include "clod/error.h"
#include "generator_arguments.h"
#include "clod/primitives.h"

namespace clod {

namespace {

using detail::requireCount;
using detail::requirePositive;

// Two triangles of the planar quad a b c d (counter-clockwise seen from outside).
void addQuad(TriangleMesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  mesh.triangles.push_back({a, b, c});
  mesh.triangles.push_back({a, c, d});
}

}  // namespace

TriangleMesh makeTorus(double majorRadius, double minorRadius, std::uint32_t majorSegments,
                       std::uint32_t minorSegments) {
  requirePositive(majorRadius, "torus major radius");
  requirePositive(minorRadius, "torus minor radius");
  if (!(minorRadius < majorRadius))
    throw Error(ErrorCode::kInvalidArgument, "torus minor radius " + std::to_string(minorRadius) +
                                                 " is not below the major radius " + std::to_string(majorRadius));
  requireCount(majorSegments, 3, 65536, "torus major segments");
  requireCount(minorSegments, 3, 65536, "torus minor segments");
  TriangleMesh mesh;
  const std::uint32_t n = majorSegments, m = minorSegments;
  mesh.vertices.reserve(std::size_t(n) * m);
  for (std::uint32_t i = 0; i < n; ++i) {
    const double theta = 2.0 * std::numbers::pi * double(i) / double(n);
    for (std::uint32_t j = 0; j < m; ++j) {
      const double phi = 2.0 * std::numbers::pi * double(j) / double(m);
      const double rho = majorRadius + minorRadius * std::cos(phi);
      mesh.vertices.emplace_back(rho * std::cos(theta), rho * std::sin(theta), minorRadius * std::sin(phi));
    }
  }
  mesh.triangles.reserve(2 * std::size_t(n) * m);
  // Along i is +theta, along j (at the outer equator) is +z; theta x z points outward.
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t i1 = (i + 1) % n;
    for (std::uint32_t j = 0; j < m; ++j) {
      const std::uint32_t j1 = (j + 1) % m;
      addQuad(mesh, i * m + j, i1 * m + j, i1 * m + j1, i * m + j1);
    }
  }
  return mesh;
}

TriangleMesh makeBowl(double outerRadius, double thickness, std::uint32_t segments, std::uint32_t rings) {
  requirePositive(outerRadius, "bowl outer radius");
  requirePositive(thickness, "bowl thickness");
  if (!(thickness < outerRadius))
    throw Error(ErrorCode::kInvalidArgument, "bowl thickness " + std::to_string(thickness) +
                                                 " is not below the outer radius " + std::to_string(outerRadius));
  requireCount(segments, 3, 65536, "bowl segments");
  requireCount(rings, 2, 4096, "bowl rings");
  TriangleMesh mesh;
  const std::uint32_t s = segments;
  const std::uint32_t perShell = s * rings + 1;  // rings x segments, then the pole
  for (const double radius : {outerRadius, outerRadius - thickness}) {
    for (std::uint32_t k = 0; k < rings; ++k) {
      const double alpha = 0.5 * std::numbers::pi * double(k) / double(rings);  // below the rim
      for (std::uint32_t i = 0; i < s; ++i) {
        const double theta = 2.0 * std::numbers::pi * double(i) / double(s);
        mesh.vertices.emplace_back(radius * std::cos(alpha) * std::cos(theta),
                                   radius * std::cos(alpha) * std::sin(theta), -radius * std::sin(alpha));
      }
    }
    mesh.vertices.emplace_back(0.0, 0.0, -radius);
  }
  auto outer = [&](std::uint32_t k, std::uint32_t i) { return k * s + i % s; };
  auto inner = [&](std::uint32_t k, std::uint32_t i) { return perShell + k * s + i % s; };
  const std::uint32_t outerPole = perShell - 1, innerPole = 2 * perShell - 1;
  for (std::uint32_t i = 0; i < s; ++i) {
    // Outer shell: down the sphere (k) then around (+theta) is outward; the inner shell faces
    // the cavity, so its quads turn the other way.
    for (std::uint32_t k = 0; k + 1 < rings; ++k) {
      addQuad(mesh, outer(k, i), outer(k + 1, i), outer(k + 1, i + 1), outer(k, i + 1));
      addQuad(mesh, inner(k, i), inner(k, i + 1), inner(k + 1, i + 1), inner(k + 1, i));
    }
    mesh.triangles.push_back({outer(rings - 1, i), outerPole, outer(rings - 1, i + 1)});
    mesh.triangles.push_back({inner(rings - 1, i), inner(rings - 1, i + 1), innerPole});
    // Rim: the flat annulus at z = 0, facing up.
    addQuad(mesh, outer(0, i), outer(0, i + 1), inner(0, i + 1), inner(0, i));
  }
  return mesh;
}

TriangleMesh makeHoledBlock(const Vec3& halfExtents, double holeRadius, std::uint32_t segments) {
  requirePositive(halfExtents.x(), "holed block half extent x");
  requirePositive(halfExtents.y(), "holed block half extent y");
  requirePositive(halfExtents.z(), "holed block half extent z");
  requirePositive(holeRadius, "holed block hole radius");
  if (!(holeRadius < std::min(halfExtents.x(), halfExtents.y())))
    throw Error(ErrorCode::kInvalidArgument, "holed block hole radius " + std::to_string(holeRadius) +
                                                 " does not fit in half extents " + std::to_string(halfExtents.x()) +
                                                 " x " + std::to_string(halfExtents.y()));
  requireCount(segments, 8, 65536, "holed block segments");
  if (segments % 8 != 0)
    throw Error(ErrorCode::kInvalidArgument,
                "holed block segments " + std::to_string(segments) + " is not a multiple of 8");
  const std::uint32_t n = segments;
  const double hx = halfExtents.x(), hy = halfExtents.y(), hz = halfExtents.z();
  TriangleMesh mesh;
  mesh.vertices.resize(4 * std::size_t(n));
  // 0..n: hole top, n..2n: hole bottom, 2n..3n: box rim top, 3n..4n: box rim bottom. The rim point
  // of hole vertex i is where the ray through it leaves the unit square, scaled by (hx, hy): at
  // multiples of 45 degrees that is a corner, so every rim quad lies in one side face.
  for (std::uint32_t i = 0; i < n; ++i) {
    const double theta = 2.0 * std::numbers::pi * double(i) / double(n);
    const double c = std::cos(theta), s = std::sin(theta);
    const double toSquare = 1.0 / std::max(std::abs(c), std::abs(s));
    const double x = hx * c * toSquare, y = hy * s * toSquare;
    mesh.vertices[i] = Vec3(holeRadius * c, holeRadius * s, hz);
    mesh.vertices[n + i] = Vec3(holeRadius * c, holeRadius * s, -hz);
    mesh.vertices[2 * n + i] = Vec3(x, y, hz);
    mesh.vertices[3 * n + i] = Vec3(x, y, -hz);
  }
  mesh.triangles.reserve(8 * std::size_t(n));
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    addQuad(mesh, i, 2 * n + i, 2 * n + j, j);                  // top annulus, +z
    addQuad(mesh, n + i, n + j, 3 * n + j, 3 * n + i);          // bottom annulus, -z
    addQuad(mesh, 3 * n + i, 3 * n + j, 2 * n + j, 2 * n + i);  // box sides, outward
    addQuad(mesh, n + i, i, j, n + j);                          // hole wall, toward the axis
  }
  return mesh;
}

std::vector<NamedMesh> demoPartMeshes() {
  std::vector<NamedMesh> parts;
  parts.push_back({"ring", makeTorus(0.025, 0.005, 48, 12)});
  parts.push_back({"ring_peg", makeCylinder(0.012, 0.05, 32)});
  parts.push_back({"bowl", makeBowl(0.09, 0.006, 48, 12)});
  parts.push_back({"holed_block", makeHoledBlock(Vec3(0.03, 0.03, 0.02), 0.0105, 64)});
  parts.push_back({"hole_peg", makeCylinder(0.010, 0.03, 32)});
  return parts;
}

std::string encodeObj(const TriangleMesh& mesh, std::string_view comment) {
  std::string out;
  out.reserve(40 * mesh.vertices.size() + 24 * mesh.triangles.size() + comment.size() + 16);
  std::size_t start = 0;
  while (start < comment.size()) {
    const std::size_t end = std::min(comment.find('\n', start), comment.size());
    out += "# ";
    out += comment.substr(start, end - start);
    out += '\n';
    start = end + 1;
  }
  char buffer[32];
  auto number = [&](auto value) {
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, end);
  };
  for (const Vec3& v : mesh.vertices) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      number(v[k]);  // shortest round-trip form
    }
    out += '\n';
  }
  for (const Triangle& t : mesh.triangles) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      number(std::uint64_t(t[k]) + 1);
    }
    out += '\n';
  }
  return out;
}

}  // namespace clod
