// Spherical Fibonacci scheme: n points on a golden-angle spiral, equal-area in z.
#include <cmath>

#include "clod/sphere_sampling.h"

namespace clod {

void SphereSampling::buildFibonacci() {
  // Keinert, Innmann, Saenger, Stamminger, "Spherical Fibonacci Mapping", ACM TOG 34(6) 2015,
  // eq. 2 (after Gonzalez 2010): z_i = 1 - (2i + 1)/n, theta_i = 2 pi frac(i / Phi). The z values
  // split the sphere into n bands of equal area (Archimedes), one point per band; the golden-ratio
  // azimuth step spreads neighbouring bands' points as far apart as possible.
  const auto n = static_cast<std::uint32_t>(resolution_);
  const double inverseGolden = (std::sqrt(5.0) - 1.0) / 2.0;  // 1 / Phi
  for (std::uint32_t i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double sinPhi = std::sqrt((1.0 - z) * (1.0 + z));
    double turns = i * inverseGolden;
    turns -= std::floor(turns);
    const double theta = 2.0 * M_PI * turns;
    addSample({sinPhi * std::cos(theta), sinPhi * std::sin(theta), z});
  }
  buildCandidateGrid();
}

}  // namespace clod
