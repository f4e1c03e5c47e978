#include "face_overlap.h"

#include <algorithm>
#include <cmath>

namespace clod::detail {
namespace {

struct Vec2d {
  double x, y;
};

double cross(const Vec2d& o, const Vec2d& a, const Vec2d& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Fixed-capacity polygon: hulls have at most 32 corners, a clip of two such at most 64.
struct Polygon {
  std::array<Vec2d, kMaxFaceOverlapPoints + 1> p{};
  std::size_t size = 0;
  void push(const Vec2d& v) {
    if (size < p.size()) p[size++] = v;
  }
};

// Convex hull, counter-clockwise, collinear and coincident corners dropped (Andrew's monotone
// chain). `eps` is the area scale below which three points count as collinear.
void convexHull(std::span<Vec2d> pts, double eps, Polygon& hull) {
  std::sort(pts.begin(), pts.end(), [](const Vec2d& a, const Vec2d& b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  std::array<Vec2d, 2 * kMaxFaceOverlapPoints> h{};
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= eps) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross(h[k - 2], h[k - 1], pts[i]) <= eps) --k;
    h[k++] = pts[i];
  }
  hull.size = 0;
  const std::size_t n = k > 1 ? k - 1 : k;  // the last point repeats the first
  for (std::size_t i = 0; i < n; ++i) hull.push(h[i]);
  // Two coincident points are one.
  if (hull.size == 2 && std::abs(hull.p[0].x - hull.p[1].x) + std::abs(hull.p[0].y - hull.p[1].y) <= eps) hull.size = 1;
}

// Keeps the part of `poly` left of every edge of the convex counter-clockwise `clipper`
// (Sutherland-Hodgman).
void clipPolygon(Polygon& poly, const Polygon& clipper) {
  Polygon in;
  for (std::size_t e = 0; e < clipper.size && poly.size > 0; ++e) {
    const Vec2d& a = clipper.p[e];
    const Vec2d& b = clipper.p[(e + 1) % clipper.size];
    in = poly;
    poly.size = 0;
    for (std::size_t i = 0; i < in.size; ++i) {
      const Vec2d& p = in.p[i];
      const Vec2d& q = in.p[(i + 1) % in.size];
      const double dp = cross(a, b, p);
      const double dq = cross(a, b, q);
      if (dp >= 0.0) poly.push(p);
      if ((dp >= 0.0) != (dq >= 0.0)) {
        const double t = dp / (dp - dq);
        poly.push({p.x + t * (q.x - p.x), p.y + t * (q.y - p.y)});
      }
    }
  }
}

// Clips the segment s0-s1 to the convex counter-clockwise `clipper` (Cyrus-Beck); false when
// nothing is left.
bool clipSegment(Vec2d& s0, Vec2d& s1, const Polygon& clipper) {
  double t0 = 0.0, t1 = 1.0;
  for (std::size_t e = 0; e < clipper.size; ++e) {
    const Vec2d& a = clipper.p[e];
    const Vec2d& b = clipper.p[(e + 1) % clipper.size];
    const double d0 = cross(a, b, s0);
    const double d1 = cross(a, b, s1);
    if (d0 < 0.0 && d1 < 0.0) return false;
    if (d0 < 0.0) t0 = std::max(t0, d0 / (d0 - d1));
    if (d1 < 0.0) t1 = std::min(t1, d0 / (d0 - d1));
  }
  if (t0 > t1) return false;
  const Vec2d a = s0, d{s1.x - s0.x, s1.y - s0.y};
  s0 = {a.x + t0 * d.x, a.y + t0 * d.y};
  s1 = {a.x + t1 * d.x, a.y + t1 * d.y};
  return true;
}

}  // namespace

std::size_t faceOverlapPoints(const Vec3& n, const FacePlane& planeB, std::span<const Vec3> cornersB,
                              const FacePlane& planeA, std::span<const Vec3> cornersA,
                              std::array<FacePoint, kMaxFaceOverlapPoints>& out) {
  if (cornersA.empty() || cornersB.empty() || cornersA.size() > 32 || cornersB.size() > 32) return 0;
  const Vec3 t1 = n.unitOrthogonal();
  const Vec3 t2 = n.cross(t1);
  std::array<Vec2d, 32> projected{};
  double scale = 0.0;
  auto hullOf = [&](std::span<const Vec3> corners, Polygon& hull) {
    for (std::size_t i = 0; i < corners.size(); ++i) {
      projected[i] = {t1.dot(corners[i]), t2.dot(corners[i])};
      scale = std::max({scale, std::abs(projected[i].x), std::abs(projected[i].y)});
    }
    // Collinear within 1e-9 of the footprint's squared size: rounding, not a real corner.
    convexHull(std::span<Vec2d>(projected.data(), corners.size()), 1e-18 * scale * scale, hull);
  };
  Polygon hullA, hullB;
  hullOf(cornersA, hullA);
  hullOf(cornersB, hullB);
  if (hullA.size < 2 || hullB.size < 2) return 0;

  Polygon region;
  if (hullA.size >= 3 && hullB.size >= 3) {
    region = hullA;
    clipPolygon(region, hullB);
  } else if (hullA.size >= 3 || hullB.size >= 3) {
    const Polygon& segment = hullA.size == 2 ? hullA : hullB;
    Vec2d s0 = segment.p[0], s1 = segment.p[1];
    if (!clipSegment(s0, s1, hullA.size == 2 ? hullB : hullA)) return 0;
    region.push(s0);
    region.push(s1);
  }
  if (region.size < 2) return 0;

  const double cosB = planeB.normal.dot(n);
  const double cosA = planeA.normal.dot(n);
  std::size_t count = 0;
  for (std::size_t i = 0; i < region.size && count < out.size(); ++i) {
    const Vec3 base = region.p[i].x * t1 + region.p[i].y * t2;
    // Heights along n of the two planes above `base`.
    const double heightB = (planeB.offset - planeB.normal.dot(base)) / cosB;
    const double heightA = (planeA.offset - planeA.normal.dot(base)) / cosA;
    out[count++] = {base + 0.5 * (heightA + heightB) * n, heightB - heightA};
  }
  return count;
}

}  // namespace clod::detail
