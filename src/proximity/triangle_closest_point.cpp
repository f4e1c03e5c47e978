#include "clod/proximity.h"

#include <algorithm>

#include "triangle_closest_point.h"

namespace clod {

const char* featureTypeName(FeatureType type) noexcept {
  switch (type) {
    case FeatureType::kVertex: return "vertex";
    case FeatureType::kEdge: return "edge";
    case FeatureType::kFace: return "face";
  }
  return "unknown";
}

const char* signMethodName(SignMethod method) noexcept {
  switch (method) {
    case SignMethod::kPseudonormal: return "pseudonormal";
    case SignMethod::kWindingNumber: return "winding_number";
  }
  return "unknown";
}

namespace {

// Closest point on the triangle's three sides, for triangles whose Voronoi regions do not
// partition space (zero or numerically vanishing area). A degenerate triangle is a segment or
// a point, and that set is exactly the union of its sides.
TrianglePoint closestPointOnSides(const Vec3& p, const Vec3* corners) noexcept {
  TrianglePoint best{corners[0], (p - corners[0]).squaredNorm(), FeatureType::kVertex, 0};
  for (std::uint8_t k = 0; k < 3; ++k) {
    const Vec3& s = corners[k];
    const Vec3 d = corners[(k + 1) % 3] - s;
    const double len2 = d.squaredNorm();
    double t = len2 > 0.0 ? (p - s).dot(d) / len2 : 0.0;
    TrianglePoint candidate;
    if (t <= 0.0) {
      candidate = {s, 0.0, FeatureType::kVertex, k};
    } else if (t >= 1.0) {
      candidate = {corners[(k + 1) % 3], 0.0, FeatureType::kVertex, std::uint8_t((k + 1) % 3)};
    } else {
      candidate = {s + t * d, 0.0, FeatureType::kEdge, k};
    }
    candidate.distanceSquared = (p - candidate.point).squaredNorm();
    if (candidate.distanceSquared < best.distanceSquared) best = candidate;
  }
  return best;
}

}  // namespace

namespace detail {

bool isThinTriangle(const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  const Vec3 ab = b - a, ac = c - a, bc = c - b;
  const double longest2 = std::max({ab.squaredNorm(), ac.squaredNorm(), bc.squaredNorm()});
  // |ab x ac|^2 / L^4 is about (width / length)^2. Below (1e-4)^2 the region determinants of
  // the Voronoi walk lose all their digits to cancellation (relative error ~ 1e-16 * L / width
  // grows past 1e-12), so such triangles go through the sides-plus-projection path.
  return ab.cross(ac).squaredNorm() <= 1e-8 * longest2 * longest2;
}

TrianglePoint closestPointOnThinTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  const Vec3 corners[3] = {a, b, c};
  TrianglePoint best = closestPointOnSides(p, corners);
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0.0) {
    // A projection strictly inside the triangle beats every side point.
    const Vec3 q = p - ((p - a).dot(n) / n2) * n;
    bool inside = true;
    for (int k = 0; k < 3 && inside; ++k) {
      inside = (corners[(k + 1) % 3] - corners[k]).cross(q - corners[k]).dot(n) > 0.0;
    }
    const double d2 = (p - q).squaredNorm();
    if (inside && d2 < best.distanceSquared) best = {q, d2, FeatureType::kFace, 0};
  }
  return best;
}

// Voronoi-region classification after Ericson, Real-Time Collision Detection (2005), 5.1.5.
// The d1..d6 are dot products of the edge vectors with the corner-to-p vectors; va, vb, vc are
// the (scaled) barycentric coordinates of p's projection, written as 2x2 determinants of them.
// Every division is guarded: when a guard fails the triangle is (numerically) degenerate and
// the sides give the answer.
TrianglePoint closestPointOnRegularTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, ap.squaredNorm(), FeatureType::kVertex, 0};

  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, bp.squaredNorm(), FeatureType::kVertex, 1};

  const Vec3 corners[3] = {a, b, c};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double den = d1 - d3;
    if (!(den > 0.0)) return closestPointOnSides(p, corners);
    const Vec3 q = a + (d1 / den) * ab;
    return {q, (p - q).squaredNorm(), FeatureType::kEdge, 0};
  }

  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, cp.squaredNorm(), FeatureType::kVertex, 2};

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double den = d2 - d6;
    if (!(den > 0.0)) return closestPointOnSides(p, corners);
    const Vec3 q = a + (d2 / den) * ac;
    return {q, (p - q).squaredNorm(), FeatureType::kEdge, 2};  // side c -> a
  }

  const double va = d3 * d6 - d5 * d4;
  const double e43 = d4 - d3;
  const double e56 = d5 - d6;
  if (va <= 0.0 && e43 >= 0.0 && e56 >= 0.0) {
    const double den = e43 + e56;
    if (!(den > 0.0)) return closestPointOnSides(p, corners);
    const Vec3 q = b + (e43 / den) * (c - b);
    return {q, (p - q).squaredNorm(), FeatureType::kEdge, 1};
  }

  // Face region. For a proper triangle va, vb, vc are all positive here; if rounding on a
  // needle or flat triangle says otherwise, the regions did not partition space.
  const double sum = va + vb + vc;
  if (!(va >= 0.0 && vb >= 0.0 && vc >= 0.0 && sum > 0.0)) return closestPointOnSides(p, corners);
  const double v = vb / sum;
  const double w = vc / sum;
  const Vec3 q = a + v * ab + w * ac;
  return {q, (p - q).squaredNorm(), FeatureType::kFace, 0};
}

}  // namespace detail

TrianglePoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  return detail::isThinTriangle(a, b, c) ? detail::closestPointOnThinTriangle(p, a, b, c)
                                         : detail::closestPointOnRegularTriangle(p, a, b, c);
}

}  // namespace clod
