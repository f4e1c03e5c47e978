#pragma once
// Contact points of two faces pressed together along a normal: the corners of the region where
// their footprints overlap, each with its own depth. This is how polyhedral colliders turn one
// separating axis into a manifold with a support area (reference face / incident face clipping;
// Gregorius, "Robust contact creation for physics simulations", GDC 2015, gives the idea; the
// code is ours): a box resting on a box gets its four corners, not one point at the face centre,
// so friction and tilt see a lever arm at every level of the hierarchy.
#include <array>
#include <cstddef>
#include <span>

#include "clod/math.h"

namespace clod::detail {

/// A face's plane: points x of the face satisfy normal . x = offset (normal unit, outward).
struct FacePlane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
};

struct FacePoint {
  Vec3 point = Vec3::Zero();  ///< midway between the two face planes along the contact normal
  double depth = 0.0;         ///< > 0 where the faces interpenetrate there, < 0 where they are apart
};

/// Most corners faceOverlapPoints returns (a clip of two convex polygons of up to 32 corners).
inline constexpr std::size_t kMaxFaceOverlapPoints = 64;

/// The corners of the overlap of face B and face A seen along n (unit, from B toward A): both
/// faces' corners are projected onto the plane perpendicular to n, each set's convex hull is
/// taken, and the hulls are intersected (a segment hull -- a face seen edge-on -- is clipped to
/// the other hull). Face B's outward normal must face A (planeB.normal . n > 0) and face A's face
/// B (planeA.normal . n < 0), both by a margin the caller ensures (their planes' heights are
/// divided by it). At each corner q: depth = height of B's plane - height of A's plane along n.
/// Returns the number of corners written to `out`; 0 when the footprints overlap in a point or
/// not at all, or a hull is a single point (the caller keeps its single contact).
/// O((|cornersA| + |cornersB|)^2) at most 32 corners each; no allocation.
std::size_t faceOverlapPoints(const Vec3& n, const FacePlane& planeB, std::span<const Vec3> cornersB,
                              const FacePlane& planeA, std::span<const Vec3> cornersA,
                              std::array<FacePoint, kMaxFaceOverlapPoints>& out);

}  // namespace clod::detail
