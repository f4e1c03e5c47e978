#pragma once
// A piece of the mesh surface: one triangle clipped to an axis-aligned box. Builders partition
// the surface into pieces and make every sphere contain every vertex of every piece assigned to
// it; a sphere is convex, so it then contains the whole (convex) piece and coverage is exact.

#include <array>
#include <cstdint>
#include <span>

#include "clod/math.h"
#include "clod/mesh.h"

namespace clod::detail {

/// A triangle clipped to an axis-aligned box has at most 3 + 6 = 9 corners (each of the six
/// planes adds at most one), so pieces fit in fixed storage and never allocate.
inline constexpr int kMaxPieceCorners = 9;

struct SurfacePiece {
  std::array<Vec3, kMaxPieceCorners> corners;
  std::uint8_t cornerCount = 0;
  std::uint32_t triangle = 0;
  double area = 0.0;
  /// Medial builder: vector from the piece towards the inner medial pole nearest to it
  /// (unused by the octree builder).
  Vec3 poleOffset = Vec3::Zero();
  /// Medial builder: id of that inner pole (SurfaceSamples::poleId), so pieces can be grouped
  /// by the medial sphere they touch (unused by the octree builder).
  std::uint32_t pole = 0;

  std::span<const Vec3> points() const { return {corners.data(), cornerCount}; }
  Vec3 centroid() const;
  Aabb bounds() const;
};

/// The whole triangle t as a piece.
SurfacePiece makeTrianglePiece(const TriangleMesh& mesh, std::uint32_t t);

/// Area of a planar convex polygon (fan triangulation).
double polygonArea(std::span<const Vec3> corners);

/// Keeps the part of `piece` with coordinate[axis] <= value (keepBelow) or >= value
/// (otherwise), Sutherland–Hodgman against one axis-aligned plane. The cut points get exactly
/// `value` on `axis`, so pieces on both sides of a cut share their cut edge bit for bit.
/// Should rounding ever make the result overflow the storage, the piece is returned unclipped:
/// a superset keeps coverage exact and only loosens the fit.
SurfacePiece clipPiece(const SurfacePiece& piece, int axis, double value, bool keepBelow);

/// Clips `piece` to the box [lo, hi] (all six planes).
SurfacePiece clipPieceToBox(const SurfacePiece& piece, const Vec3& lo, const Vec3& hi);

/// Whether a clipped part is worth keeping: a non-empty part with real area, or any non-empty
/// part of a piece that had no area to begin with (degenerate triangles still need covering).
/// Zero-area slivers of a piece with area (touching a cut plane) are covered by the other side.
bool keepClippedPart(const SurfacePiece& part, const SurfacePiece& whole);

}  // namespace clod::detail
