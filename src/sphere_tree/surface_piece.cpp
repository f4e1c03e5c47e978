#include "surface_piece.h"

#include <algorithm>

namespace clod::detail {

Vec3 SurfacePiece::centroid() const {
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < cornerCount; ++i) sum += corners[i];
  return cornerCount > 0 ? Vec3(sum / cornerCount) : sum;
}

Aabb SurfacePiece::bounds() const {
  Aabb box;
  for (int i = 0; i < cornerCount; ++i) box.extend(corners[i]);
  return box;
}

SurfacePiece makeTrianglePiece(const TriangleMesh& mesh, std::uint32_t t) {
  SurfacePiece piece;
  for (int k = 0; k < 3; ++k) piece.corners[k] = mesh.corner(t, k);
  piece.cornerCount = 3;
  piece.triangle = t;
  piece.area = mesh.triangleArea(t);
  return piece;
}

double polygonArea(std::span<const Vec3> corners) {
  if (corners.size() < 3) return 0.0;
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    sum += (corners[i] - corners[0]).cross(corners[i + 1] - corners[0]);
  return 0.5 * sum.norm();
}

SurfacePiece clipPiece(const SurfacePiece& piece, int axis, double value, bool keepBelow) {
  SurfacePiece out;
  out.triangle = piece.triangle;
  out.poleOffset = piece.poleOffset;
  out.pole = piece.pole;
  const int n = piece.cornerCount;
  auto inside = [&](const Vec3& p) { return keepBelow ? p[axis] <= value : p[axis] >= value; };
  bool allInside = true;
  for (int i = 0; i < n; ++i) allInside = allInside && inside(piece.corners[i]);
  if (allInside) return piece;
  for (int i = 0; i < n; ++i) {
    const Vec3& p = piece.corners[i];
    const Vec3& q = piece.corners[(i + 1) % n];
    const bool pIn = inside(p);
    const bool qIn = inside(q);
    const int needed = (pIn ? 1 : 0) + (pIn != qIn ? 1 : 0);
    if (out.cornerCount + needed > kMaxPieceCorners) return piece;
    if (pIn) out.corners[out.cornerCount++] = p;
    if (pIn != qIn) {
      // p and q lie strictly on opposite sides, so the denominator is non-zero.
      const double t = (value - p[axis]) / (q[axis] - p[axis]);
      Vec3 cut = p + t * (q - p);
      cut[axis] = value;
      out.corners[out.cornerCount++] = cut;
    }
  }
  out.area = polygonArea(out.points());
  return out;
}

SurfacePiece clipPieceToBox(const SurfacePiece& piece, const Vec3& lo, const Vec3& hi) {
  SurfacePiece out = piece;
  for (int axis = 0; axis < 3 && out.cornerCount > 0; ++axis) {
    out = clipPiece(out, axis, lo[axis], false);
    if (out.cornerCount > 0) out = clipPiece(out, axis, hi[axis], true);
  }
  return out;
}

bool keepClippedPart(const SurfacePiece& part, const SurfacePiece& whole) {
  if (part.cornerCount == 0) return false;
  if (whole.area <= 0.0) return true;
  return part.area > 1e-12 * whole.area;
}

}  // namespace clod::detail
