// SphereSampling: scheme names, sample counts, the stacks mapping, and dispatch of lookups to the
// ring (sampling_rings.cpp) and geodesic (sampling_geodesic.cpp) implementations.
#include "clod/sphere_sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>

#include "clod/error.h"

namespace clod {
namespace {

constexpr std::array<SamplingScheme, 5> kAllSchemes = {
    SamplingScheme::kPolar, SamplingScheme::kAdaptivePolar, SamplingScheme::kGeodesic,
    SamplingScheme::kHealpix, SamplingScheme::kFibonacci};

void checkResolution(SamplingScheme scheme, int resolution) {
  int maxResolution = maxSamplingResolution(scheme);
  if (resolution < 1 || resolution > maxResolution) {
    throw Error(ErrorCode::kInvalidArgument,
                std::string(samplingSchemeName(scheme)) + ": resolution " +
                    std::to_string(resolution) + " outside [1, " + std::to_string(maxResolution) +
                    "]");
  }
}

std::uint32_t adaptiveRingSize(int stacks, int ring) {
  // Paper section 4: samples per ring proportional to sin(phi); at least one so the pole and
  // near-pole rings are represented (REFERENCES.md: this reproduces Table 1's 65 / 3 / 11).
  double phi = M_PI * ring / stacks;
  long n = std::lround(stacks * std::sin(phi));
  return static_cast<std::uint32_t>(n < 1 ? 1 : n);
}

}  // namespace

std::span<const SamplingScheme> allSamplingSchemes() noexcept { return kAllSchemes; }

std::string_view samplingSchemeName(SamplingScheme scheme) noexcept {
  switch (scheme) {
    case SamplingScheme::kPolar: return "polar";
    case SamplingScheme::kAdaptivePolar: return "adaptive-polar";
    case SamplingScheme::kGeodesic: return "geodesic";
    case SamplingScheme::kHealpix: return "healpix";
    case SamplingScheme::kFibonacci: return "fibonacci";
  }
  return "unknown";
}

SamplingScheme parseSamplingScheme(std::string_view name) {
  for (SamplingScheme scheme : kAllSchemes) {
    if (samplingSchemeName(scheme) == name) return scheme;
  }
  std::string valid;
  for (SamplingScheme scheme : kAllSchemes) {
    if (!valid.empty()) valid += ", ";
    valid += samplingSchemeName(scheme);
  }
  throw Error(ErrorCode::kInvalidArgument,
              "unknown sampling scheme '" + std::string(name) + "' (valid: " + valid + ")");
}

int maxSamplingResolution(SamplingScheme scheme) noexcept {
  switch (scheme) {
    case SamplingScheme::kPolar: return 1024;          // 1,048,576 samples
    case SamplingScheme::kAdaptivePolar: return 1024;  // ~667,000 samples
    case SamplingScheme::kGeodesic: return 64;         // 40,962 samples (grid build ~1 s)
    case SamplingScheme::kHealpix: return 256;         // 786,432 samples
    case SamplingScheme::kFibonacci: return 16384;     // samples (grid build ~1 s)
  }
  return 0;
}

int stacksAtLevel(int rootStacks, int level) noexcept {
  CLOD_ASSERT(rootStacks >= 1);
  CLOD_ASSERT(level >= 0);
  int stacks = rootStacks;
  for (int i = 0; i < level && stacks > 1; ++i) stacks /= 2;
  return stacks < 1 ? 1 : stacks;
}

std::uint32_t samplingSampleCount(SamplingScheme scheme, int resolution) {
  checkResolution(scheme, resolution);
  auto r = static_cast<std::uint32_t>(resolution);
  switch (scheme) {
    case SamplingScheme::kPolar: return r * r;
    case SamplingScheme::kAdaptivePolar: {
      std::uint32_t count = 0;
      for (int i = 0; i < resolution; ++i) count += adaptiveRingSize(resolution, i);
      return count;
    }
    case SamplingScheme::kGeodesic: return 10 * r * r + 2;
    case SamplingScheme::kHealpix: return 12 * r * r;
    case SamplingScheme::kFibonacci: return r;
  }
  return 0;
}

int samplingResolutionForStacks(SamplingScheme scheme, int stacks) {
  checkResolution(SamplingScheme::kPolar, stacks);
  if (scheme == SamplingScheme::kPolar || scheme == SamplingScheme::kAdaptivePolar) return stacks;
  long target = samplingSampleCount(SamplingScheme::kAdaptivePolar, stacks);
  if (scheme == SamplingScheme::kFibonacci) {
    return static_cast<int>(std::min<long>(target, maxSamplingResolution(scheme)));
  }
  int best = 1;
  long bestDiff = std::labs(static_cast<long>(samplingSampleCount(scheme, 1)) - target);
  for (int r = 2; r <= maxSamplingResolution(scheme); ++r) {
    long count = samplingSampleCount(scheme, r);
    long diff = std::labs(count - target);
    if (diff < bestDiff) {
      best = r;
      bestDiff = diff;
    }
    if (count > target) break;  // counts grow with r: nothing further can be closer
  }
  return best;
}

SphereSampling SphereSampling::build(SamplingScheme scheme, int resolution) {
  checkResolution(scheme, resolution);
  SphereSampling sampling;
  sampling.scheme_ = scheme;
  sampling.resolution_ = resolution;
  std::uint32_t count = samplingSampleCount(scheme, resolution);
  sampling.x_.reserve(count);
  sampling.y_.reserve(count);
  sampling.z_.reserve(count);
  switch (scheme) {
    case SamplingScheme::kPolar: sampling.buildPolarRings(false); break;
    case SamplingScheme::kAdaptivePolar: sampling.buildPolarRings(true); break;
    case SamplingScheme::kGeodesic: sampling.buildGeodesic(); break;
    case SamplingScheme::kHealpix: sampling.buildHealpixRings(); break;
    case SamplingScheme::kFibonacci: sampling.buildFibonacci(); break;
  }
  CLOD_ASSERT(sampling.size() == count);
  return sampling;
}

SphereSampling SphereSampling::buildForStacks(SamplingScheme scheme, int stacks) {
  return build(scheme, samplingResolutionForStacks(scheme, stacks));
}

void SphereSampling::addSample(const Vec3& direction) {
  x_.push_back(direction.x());
  y_.push_back(direction.y());
  z_.push_back(direction.z());
}

Vec3 SphereSampling::direction(std::uint32_t index) const noexcept {
  CLOD_ASSERT(index < size());
  return {x_[index], y_[index], z_[index]};
}

std::uint32_t SphereSampling::nearest(const Vec3& unitDirection) const noexcept {
  CLOD_ASSERT(std::abs(unitDirection.squaredNorm() - 1.0) < 2e-6);
  if (scheme_ == SamplingScheme::kGeodesic || scheme_ == SamplingScheme::kFibonacci) {
    return nearestInGrid(unitDirection);
  }
  return nearestInRings(unitDirection);
}

std::uint32_t SphereSampling::nearestLinearScan(const Vec3& u) const noexcept {
  std::uint32_t best = 0;
  double bestDot = -2.0;
  const std::uint32_t n = size();
  for (std::uint32_t i = 0; i < n; ++i) {
    double d = x_[i] * u.x() + y_[i] * u.y() + z_[i] * u.z();
    if (d > bestDot) {
      bestDot = d;
      best = i;
    }
  }
  return best;
}

std::size_t SphereSampling::memoryBytes() const noexcept {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return sizeof(*this) + bytes(x_) + bytes(y_) + bytes(z_) + bytes(ringOffset_) +
         bytes(ringSize_) + bytes(ringPhi_) + bytes(ringCosPhi_) + bytes(ringSinPhi_) +
         bytes(ringShift_) + bytes(octantStart_) + bytes(octantSamples_) + bytes(cellStart_) +
         bytes(cellSamples_);
}

}  // namespace clod
