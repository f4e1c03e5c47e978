#include "triangle_intersection.h"

#include <algorithm>
#include <cmath>

namespace clod::narrowphase {
namespace {

double snap(double d, double eps) { return std::abs(d) <= eps ? 0.0 : d; }

// Points where triangle t meets the plane whose signed corner distances are d (already snapped):
// corners on the plane, and edges whose ends lie strictly on opposite sides. At most 2 points
// unless all three corners are on the plane (the coplanar case, handled elsewhere).
int cutByPlane(const Vec3* t, const double* d, Vec3* out) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (d[i] == 0.0) out[n++] = t[i];
    if ((d[i] < 0.0 && d[j] > 0.0) || (d[i] > 0.0 && d[j] < 0.0)) {
      const double s = d[i] / (d[i] - d[j]);
      out[n++] = t[i] + s * (t[j] - t[i]);
    }
    if (n == 2) break;
  }
  return n;
}

// Overlap polygon of coplanar triangles: A clipped by the three inward edge half-planes of B.
// The half-planes are built from B's own normal, so it works whatever A's orientation is.
bool clipCoplanar(const Vec3* a, const Vec3* b, const Vec3& normalB, double eps, TriangleIntersection& out) {
  std::array<Vec3, 9> poly{a[0], a[1], a[2]};
  std::array<Vec3, 9> next{};
  std::uint32_t count = 3;
  for (int k = 0; k < 3 && count > 0; ++k) {
    const Vec3 edge = b[(k + 1) % 3] - b[k];
    const Vec3 inward = normalB.cross(edge);
    const double len = inward.norm();
    if (len == 0.0) return false;
    const Vec3 m = inward / len;
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
      const Vec3& p = poly[i];
      const Vec3& q = poly[(i + 1) % count];
      const double dp = m.dot(p - b[k]);
      const double dq = m.dot(q - b[k]);
      const bool pin = dp >= -eps;
      const bool qin = dq >= -eps;
      if (pin) next[n++] = p;
      if (pin != qin && n < next.size()) {
        const double s = dp / (dp - dq);
        next[n++] = p + s * (q - p);
      }
    }
    poly = next;
    count = n;
  }
  if (count == 0) return false;
  out.points = poly;
  out.count = count;
  return true;
}

}  // namespace

bool intersectTriangles(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                        const Vec3& b2, double epsAbs, TriangleIntersection& out) noexcept {
  out.count = 0;
  out.coplanar = false;
  out.touching = false;
  const Vec3 a[3] = {a0, a1, a2};
  const Vec3 b[3] = {b0, b1, b2};

  Vec3 nB = (b1 - b0).cross(b2 - b0);
  const double lenB = nB.norm();
  if (!(lenB > 0.0)) return false;
  nB /= lenB;
  double dA[3];
  for (int i = 0; i < 3; ++i) dA[i] = snap(nB.dot(a[i] - b0), epsAbs);
  if ((dA[0] > 0.0 && dA[1] > 0.0 && dA[2] > 0.0) || (dA[0] < 0.0 && dA[1] < 0.0 && dA[2] < 0.0)) return false;

  Vec3 nA = (a1 - a0).cross(a2 - a0);
  const double lenA = nA.norm();
  if (!(lenA > 0.0)) return false;
  nA /= lenA;
  double dB[3];
  for (int i = 0; i < 3; ++i) dB[i] = snap(nA.dot(b[i] - a0), epsAbs);
  if ((dB[0] > 0.0 && dB[1] > 0.0 && dB[2] > 0.0) || (dB[0] < 0.0 && dB[1] < 0.0 && dB[2] < 0.0)) return false;

  out.normalA = nA;
  out.normalB = nB;
  out.penetrationBelowB = std::max({0.0, -dA[0], -dA[1], -dA[2]});
  out.penetrationBelowA = std::max({0.0, -dB[0], -dB[1], -dB[2]});

  if (dA[0] == 0.0 && dA[1] == 0.0 && dA[2] == 0.0) {
    out.coplanar = true;
    return clipCoplanar(a, b, nB, epsAbs, out);
  }
  auto straddles = [](const double* d) {
    return std::min({d[0], d[1], d[2]}) < 0.0 && std::max({d[0], d[1], d[2]}) > 0.0;
  };
  out.touching = !straddles(dA) || !straddles(dB);

  Vec3 segA[3];
  Vec3 segB[3];
  const int nSegA = cutByPlane(a, dA, segA);
  const int nSegB = cutByPlane(b, dB, segB);
  if (nSegA == 0 || nSegB == 0) return false;
  if (nSegA == 1) segA[1] = segA[0];
  if (nSegB == 1) segB[1] = segB[0];

  // Both segments lie on the planes' common line (up to rounding); compare them along it.
  Vec3 dir = nA.cross(nB);
  if (dir.squaredNorm() < 1e-24) {
    // Planes parallel within rounding but not coplanar after snapping: use A's segment direction.
    dir = segA[1] - segA[0];
    if (dir.squaredNorm() == 0.0) dir = segB[1] - segB[0];
    if (dir.squaredNorm() == 0.0) dir = Vec3::UnitX();
  }
  double tA0 = dir.dot(segA[0]), tA1 = dir.dot(segA[1]);
  double tB0 = dir.dot(segB[0]), tB1 = dir.dot(segB[1]);
  if (tA0 > tA1) {
    std::swap(tA0, tA1);
    std::swap(segA[0], segA[1]);
  }
  if (tB0 > tB1) {
    std::swap(tB0, tB1);
    std::swap(segB[0], segB[1]);
  }
  const double tolerance = epsAbs * dir.norm();
  if (tA1 < tB0 - tolerance || tB1 < tA0 - tolerance) return false;
  out.points[0] = tA0 >= tB0 ? segA[0] : segB[0];
  out.points[1] = tA1 <= tB1 ? segA[1] : segB[1];
  out.count = 2;
  // Segments that overlap in one point only: the triangles meet there without crossing along a
  // segment (a box's side face and a perpendicular face of a step, both ending at the step's top
  // edge, met at one point; read as crossing, the pair got an intersection volume of its own,
  // and a box standing exactly on the step got a sideways contact 0.36 m deep).
  if (std::min(tA1, tB1) - std::max(tA0, tB0) <= tolerance) out.touching = true;
  return true;
}

}  // namespace clod::narrowphase
