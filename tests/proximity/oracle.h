#pragma once
// Independent reference answers for the proximity tests. Nothing here calls clod's proximity
// code: closest points come from plane projection + barycentric sign tests + clamped segment
// projections (a different algorithm from the Voronoi-region walk under test), winding numbers
// from a plain sum of per-triangle solid angles over every triangle (no hierarchy), inside
// tests from ray parity.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "clod/math.h"
#include "clod/mesh.h"
#include "clod/proximity.h"
#include "support/test_scale.h"

namespace oracle {

using clod::FeatureType;
using clod::Vec3;

using clod::test::sanitizerRun;

struct Hit {
  Vec3 point;
  double distance;
  FeatureType type;
  int local;  // corner k, or side k from corner k to k+1
};

inline Hit closestOnSegment(const Vec3& p, const Vec3& s, const Vec3& e, int k) {
  const Vec3 d = e - s;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s).dot(d) / len2, 0.0, 1.0) : 0.0;
  if (t == 0.0) return {s, (p - s).norm(), FeatureType::kVertex, k};
  if (t == 1.0) return {e, (p - e).norm(), FeatureType::kVertex, (k + 1) % 3};
  const Vec3 q = s + t * d;
  return {q, (p - q).norm(), FeatureType::kEdge, k};
}

inline Hit closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 corners[3] = {a, b, c};
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  const double longest2 = std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
  // Below width/length ~1e-10 the plane normal is noise and so is the projection; the whole
  // triangle is then within 1e-10 * length of its sides, which the tests' 1e-9 * diagonal
  // tolerance covers, so the sides alone answer.
  if (n2 > 1e-20 * longest2 * longest2) {
    const Vec3 q = p - ((p - a).dot(n) / n2) * n;
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      const Vec3& s = corners[k];
      const Vec3& e = corners[(k + 1) % 3];
      if ((e - s).cross(q - s).dot(n) <= 0.0) inside = false;
    }
    if (inside) return {q, (p - q).norm(), FeatureType::kFace, 0};
  }
  Hit best = closestOnSegment(p, a, b, 0);
  for (int k = 1; k < 3; ++k) {
    Hit h = closestOnSegment(p, corners[k], corners[(k + 1) % 3], k);
    if (h.distance < best.distance) best = h;
  }
  return best;
}

/// Brute-force closest triangle over the whole mesh. Every triangle is visited; the exact
/// point-triangle test is skipped only for a triangle that provably cannot be closer: its
/// bounding sphere (centre c, radius r) is farther than U = min over all triangles of
/// |p - c| + r, an upper bound on the answer. Ties keep the lowest triangle index.
struct MeshHit {
  Hit hit;
  std::uint32_t triangle;
};
class BruteForce {
public:
  explicit BruteForce(const clod::TriangleMesh& mesh) : mesh_(mesh) {
    for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
      const Vec3 c = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
      double r = 0.0;
      for (int k = 0; k < 3; ++k) r = std::max(r, (mesh.corner(t, k) - c).norm());
      cx_.push_back(c.x()), cy_.push_back(c.y()), cz_.push_back(c.z());
      r_.push_back(r * (1 + 1e-12) + 1e-300);  // rounded up: the sphere must contain the triangle
    }
  }

  MeshHit closest(const Vec3& p) const {
    const std::size_t n = r_.size();
    thread_local std::vector<double> centreDistance;
    centreDistance.resize(n);
    double upper = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < n; ++t) {
      const double dx = p.x() - cx_[t], dy = p.y() - cy_[t], dz = p.z() - cz_[t];
      centreDistance[t] = std::sqrt(dx * dx + dy * dy + dz * dz);
      upper = std::min(upper, centreDistance[t] + r_[t]);
    }
    upper = upper * (1 + 1e-12) + 1e-300;
    MeshHit best{{p, std::numeric_limits<double>::infinity(), FeatureType::kFace, 0}, 0};
    for (std::uint32_t t = 0; t < n; ++t) {
      if (centreDistance[t] - r_[t] > upper) continue;
      const Hit h = closestOnTriangle(p, mesh_.corner(t, 0), mesh_.corner(t, 1), mesh_.corner(t, 2));
      if (h.distance < best.hit.distance) best = {h, t};
    }
    return best;
  }

private:
  const clod::TriangleMesh& mesh_;
  std::vector<double> cx_, cy_, cz_, r_;
};

/// Plain loop version (for small subsets).
inline MeshHit closestOnMesh(const clod::TriangleMesh& mesh, const Vec3& p) { return BruteForce(mesh).closest(p); }

/// Exact winding number: sum of signed solid angles / 4pi.
inline double windingNumber(const clod::TriangleMesh& mesh, const Vec3& q) {
  double sum = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 x = mesh.corner(t, 0) - q, y = mesh.corner(t, 1) - q, z = mesh.corner(t, 2) - q;
    const double lx = x.norm(), ly = y.norm(), lz = z.norm();
    sum += 2.0 * std::atan2(x.dot(y.cross(z)), lx * ly * lz + x.dot(y) * lz + y.dot(z) * lx + z.dot(x) * ly);
  }
  return sum / (4.0 * std::numbers::pi);
}

/// Ray-parity inside test for a closed mesh. Returns -1 when every tried ray grazed an edge
/// or was near-parallel to a triangle (caller skips the point).
inline int insideByRayParity(const clod::TriangleMesh& mesh, const Vec3& p, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss;
  for (int attempt = 0; attempt < 8; ++attempt) {
    const Vec3 dir = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    int crossings = 0;
    bool ambiguous = false;
    for (std::uint32_t t = 0; t < mesh.triangleCount() && !ambiguous; ++t) {
      // Moller & Trumbore (1997) ray/triangle intersection with barycentric margins.
      const Vec3& a = mesh.corner(t, 0);
      const Vec3 e1 = mesh.corner(t, 1) - a, e2 = mesh.corner(t, 2) - a;
      const Vec3 h = dir.cross(e2);
      const double det = e1.dot(h);
      const double scale = e1.norm() * e2.norm();
      if (std::abs(det) <= 1e-12 * scale) continue;  // parallel (or degenerate): cannot cross
      const Vec3 s = p - a;
      const double u = s.dot(h) / det;
      const Vec3 qv = s.cross(e1);
      const double v = dir.dot(qv) / det;
      const double dist = e2.dot(qv) / det;
      constexpr double kMargin = 1e-9;
      if (u < -kMargin || v < -kMargin || u + v > 1 + kMargin || dist < 0) continue;
      if (u < kMargin || v < kMargin || u + v > 1 - kMargin || std::abs(det) < 1e-6 * scale) {
        ambiguous = true;
        break;
      }
      ++crossings;
    }
    if (!ambiguous) return crossings % 2;
  }
  return -1;
}

/// Independent pseudonormals: face normals, edge = normalised sum of its faces' normals,
/// vertex = normalised sum of incident face normals weighted by the corner angle (acos).
struct Normals {
  std::vector<Vec3> face, vertex;
  std::map<std::pair<std::uint32_t, std::uint32_t>, Vec3> edge;  // key (min, max) vertex
};
inline Normals normalsOf(const clod::TriangleMesh& mesh) {
  Normals out;
  out.vertex.assign(mesh.vertexCount(), Vec3::Zero());
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 cross = mesh.triangleCross(t);
    const Vec3 n = cross.norm() > 0.0 ? Vec3(cross.normalized()) : Vec3::Zero();
    out.face.push_back(n);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v0 = mesh.triangles[t][k], v1 = mesh.triangles[t][(k + 1) % 3];
      out.edge.try_emplace({std::min(v0, v1), std::max(v0, v1)}, Vec3::Zero()).first->second += n;
      if (n.isZero()) continue;
      const Vec3 u = (mesh.corner(t, (k + 1) % 3) - mesh.corner(t, k)).normalized();
      const Vec3 w = (mesh.corner(t, (k + 2) % 3) - mesh.corner(t, k)).normalized();
      out.vertex[v0] += std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * n;
    }
  }
  for (Vec3& n : out.vertex) n = n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3::Zero();
  for (auto& [key, n] : out.edge) n = n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3::Zero();
  return out;
}

}  // namespace oracle
