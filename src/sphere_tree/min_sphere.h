#pragma once
// Smallest enclosing sphere of a point set (Welzl 1991, move-to-front variant as described by
// Gärtner, "Fast and robust smallest enclosing balls", ESA 1999).

#include <span>
#include <vector>

#include "clod/math.h"

namespace clod::detail {

struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};

/// Smallest sphere containing `points` (expected O(n)). `scratch` is reused storage.
/// The radius is finally set to the largest distance from the centre to any point, so the
/// result contains every point exactly as computed in double precision, whatever rounding did
/// to the support set. Empty input gives a zero sphere at the origin.
Sphere minimumEnclosingSphere(std::span<const Vec3> points, std::vector<Vec3>& scratch);

/// Largest distance from `center` to any of `points` (0 for none).
double farthestDistance(const Vec3& center, std::span<const Vec3> points);

}  // namespace clod::detail
