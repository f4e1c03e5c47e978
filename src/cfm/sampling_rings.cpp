// Ring schemes (full polar, adaptive polar, HEALPix): construction and O(1) nearest-sample lookup.
//
// All three place samples on iso-latitude rings with equal theta steps inside a ring, so one
// lookup serves them all. Why not just round phi then theta (the paper's equations 4-5)? Near a
// boundary between rings the nearest sample can sit in the neighbouring ring (its theta grid is
// offset or coarser), and near the poles a ring of few samples is often farther than the next
// ring. Exactness comes from a bound: every sample on ring k has dot product with the query of
// at most cos(phi - phi_k), the dot product with the ring point at the query's own theta, so a
// ring can be skipped - and every ring beyond it - once that bound is below the best found.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "clod/error.h"
#include "clod/sphere_sampling.h"

namespace clod {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// Slack on the ring-skip bound: a ring whose bound is within this of the best dot product is
// still visited, so rounding in the bound (~1e-16) can never skip a sample that is better by
// more than the 1e-12 tie tolerance the contract allows.
constexpr double kRingBoundSlack = 1e-13;

}  // namespace

void SphereSampling::buildPolarRings(bool adaptive) {
  const int stacks = resolution_;
  for (int i = 0; i < stacks; ++i) {
    const double phi = M_PI * i / stacks;
    std::uint32_t n = static_cast<std::uint32_t>(stacks);
    if (adaptive) {
      long rounded = std::lround(stacks * std::sin(phi));
      n = static_cast<std::uint32_t>(rounded < 1 ? 1 : rounded);
    }
    ringOffset_.push_back(size());
    ringSize_.push_back(n);
    ringPhi_.push_back(phi);
    ringShift_.push_back(0.0);
    // Ring 0 is exactly the pole (sin 0 = 0), so its S full-polar copies coincide exactly.
    const double sinPhi = std::sin(phi), cosPhi = std::cos(phi);
    ringCosPhi_.push_back(cosPhi);
    ringSinPhi_.push_back(sinPhi);
    for (std::uint32_t j = 0; j < n; ++j) {
      const double theta = kTwoPi * j / n;
      addSample({sinPhi * std::cos(theta), sinPhi * std::sin(theta), cosPhi});
    }
  }
}

void SphereSampling::buildHealpixRings() {
  // Gorski et al. 2005, section 4 (eqs. 4-9): rings i = 1..4N-1; polar caps hold 4i pixels at
  // z = 1 - i^2/(3N^2), theta = (j - 1/2) pi/(2i); the equatorial belt (N <= i <= 3N) holds 4N
  // pixels at z = 4/3 - 2i/(3N), theta = (j - s/2) pi/(2N) with s = (i - N + 1) mod 2; j = 1..n.
  const int nside = resolution_;
  const double nn3 = 3.0 * nside * static_cast<double>(nside);
  for (int i = 1; i <= 4 * nside - 1; ++i) {
    double z = 0.0, oneMinusAbsZ = 0.0, shift = 0.5;
    std::uint32_t n = 0;
    if (i < nside || i > 3 * nside) {
      const int capRing = i < nside ? i : 4 * nside - i;
      oneMinusAbsZ = capRing * static_cast<double>(capRing) / nn3;
      z = i < nside ? 1.0 - oneMinusAbsZ : oneMinusAbsZ - 1.0;
      n = 4u * static_cast<std::uint32_t>(capRing);
    } else {
      z = 4.0 / 3.0 - 2.0 * i / (3.0 * nside);
      oneMinusAbsZ = 1.0 - std::abs(z);
      n = 4u * static_cast<std::uint32_t>(nside);
      shift = ((i - nside + 1) % 2 == 0) ? 1.0 : 0.5;  // j starts at 1: theta = (j' + 1 - s/2) step
    }
    // sin(phi) from (1 - |z|)(1 + |z|) keeps full relative precision near the poles.
    const double sinPhi = std::sqrt(oneMinusAbsZ * (2.0 - oneMinusAbsZ));
    ringOffset_.push_back(size());
    ringSize_.push_back(n);
    ringPhi_.push_back(std::atan2(sinPhi, z));
    ringShift_.push_back(shift);
    ringCosPhi_.push_back(z);
    ringSinPhi_.push_back(sinPhi);
    for (std::uint32_t j = 0; j < n; ++j) {
      const double theta = (j + shift) * kTwoPi / n;
      addSample({sinPhi * std::cos(theta), sinPhi * std::sin(theta), z});
    }
  }
}

std::uint32_t SphereSampling::closestRingByFormula(double z, double rho) const noexcept {
  const auto lastRing = static_cast<long>(ringSize_.size()) - 1;
  long ring = 0;
  if (scheme_ == SamplingScheme::kHealpix) {
    // Invert z(i) of the ring layout above (HEALPix ring number i is 1-based).
    const double nside = resolution_;
    long i = 0;
    if (z > 2.0 / 3.0) {
      i = std::lround(nside * std::sqrt(3.0 * (1.0 - z)));
    } else if (z < -2.0 / 3.0) {
      i = 4 * resolution_ - std::lround(nside * std::sqrt(3.0 * (1.0 + z)));
    } else {
      i = std::lround(2.0 * nside - 1.5 * nside * z);
    }
    ring = i - 1;
  } else {
    // Polar schemes: rings at phi = k pi / S (equation 4 of the paper, rounded).
    ring = std::lround(std::atan2(rho, z) * resolution_ / M_PI);
  }
  return static_cast<std::uint32_t>(std::clamp(ring, 0L, lastRing));
}

std::uint32_t SphereSampling::nearestInRings(const Vec3& u) const noexcept {
  const double rho = std::sqrt(u.x() * u.x() + u.y() * u.y());
  const double z = u.z();
  const double theta = std::atan2(u.y(), u.x());  // (-pi, pi]; atan2(0, 0) = 0 at the poles
  const auto ringBound = [&](std::uint32_t k) { return z * ringCosPhi_[k] + rho * ringSinPhi_[k]; };

  // Start at the ring nearest in phi. The formula can be one ring off (rounding at boundaries,
  // HEALPix's curved z(i) in the caps); walking to the local maximum of the bound makes the
  // bound decrease monotonically on both sides, which the early exits below rely on.
  std::uint32_t start = closestRingByFormula(z, rho);
  const std::uint32_t rings = ringCount();
  while (start > 0 && ringBound(start - 1) > ringBound(start)) --start;
  while (start + 1 < rings && ringBound(start + 1) > ringBound(start)) ++start;

  std::uint32_t best = 0;
  double bestDot = -2.0;
  const auto visitRing = [&](std::uint32_t k) {
    const std::uint32_t n = ringSize_[k];
    // The two samples whose thetas bracket the query's theta; the nearer of them is the ring's
    // nearest because the dot product falls monotonically with |theta - theta_j| on a ring.
    const double t = theta * n / kTwoPi - ringShift_[k];
    const auto j0 = static_cast<long>(std::floor(t));
    for (long j = j0; j <= j0 + 1; ++j) {
      long wrapped = j % static_cast<long>(n);
      if (wrapped < 0) wrapped += n;
      const std::uint32_t index = ringOffset_[k] + static_cast<std::uint32_t>(wrapped);
      const double d = x_[index] * u.x() + y_[index] * u.y() + z_[index] * u.z();
      if (d > bestDot) {
        bestDot = d;
        best = index;
      }
    }
  };

  visitRing(start);
  for (std::uint32_t k = start; k-- > 0;) {
    if (ringBound(k) < bestDot - kRingBoundSlack) break;
    visitRing(k);
  }
  for (std::uint32_t k = start + 1; k < rings; ++k) {
    if (ringBound(k) < bestDot - kRingBoundSlack) break;
    visitRing(k);
  }
  return best;
}

std::uint32_t SphereSampling::nearestPaperFormula(const Vec3& u) const noexcept {
  CLOD_ASSERT(ringCount() > 0);
  const double rho = std::sqrt(u.x() * u.x() + u.y() * u.y());
  const std::uint32_t ring = closestRingByFormula(u.z(), rho);
  double theta = std::atan2(u.y(), u.x());
  if (theta < 0.0) theta += kTwoPi;
  const std::uint32_t n = ringSize_[ring];
  long j = std::lround(theta * n / kTwoPi - ringShift_[ring]) % static_cast<long>(n);
  if (j < 0) j += n;
  return ringOffset_[ring] + static_cast<std::uint32_t>(j);
}

}  // namespace clod
