#pragma once
// Rotations given as four numbers (poses on the command line, scene files, Python arrays, body
// descriptions): the unit quaternion they point to.

#include <algorithm>
#include <cmath>
#include <optional>

#include "clod/math.h"

namespace clod {

/// The rotation of quaternion (w, x, y, z) of any finite, nonzero magnitude, as a unit
/// quaternion; nullopt for a zero or non-finite one. The components are scaled by the largest
/// before normalising, so (1e200, 1e200, 0, 0) -- whose norm overflows -- and (1e-200, 0, 0, 0)
/// -- whose squared norm underflows -- are the rotations they point to, not errors.
inline std::optional<Quat> unitQuaternion(double w, double x, double y, double z) {
  if (!(std::isfinite(w) && std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) return std::nullopt;
  const double largest = std::max({std::abs(w), std::abs(x), std::abs(y), std::abs(z)});
  if (!(largest > 0.0)) return std::nullopt;
  const Quat scaled(w / largest, x / largest, y / largest, z / largest);
  return Quat(scaled.coeffs() / scaled.norm());
}

}  // namespace clod
