#pragma once
// Internal pieces of clod::closestPointOnTriangle, so the BVH can classify each triangle once
// at build time instead of per query.

#include "clod/proximity.h"

namespace clod::detail {

/// True for needle and flat triangles (width/length below about 1e-4), including zero-area ones.
bool isThinTriangle(const Vec3& a, const Vec3& b, const Vec3& c) noexcept;

/// Voronoi-region walk (Ericson); exact for triangles that are not thin.
TrianglePoint closestPointOnRegularTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) noexcept;

/// Best of the three sides and, if it falls strictly inside, the plane projection.
TrianglePoint closestPointOnThinTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) noexcept;

}  // namespace clod::detail
