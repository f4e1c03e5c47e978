#include "clod/normal_accuracy.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <tbb/parallel_for.h>

#include "clod/error.h"
#include "clod/proximity.h"

namespace clod {

namespace {

// SplitMix64 (Steele, Lea, Flood 2014): tiny, good enough for sampling, and seekable, so each
// attempt gets its own stream and the result does not depend on how TBB splits the work.
std::uint64_t splitMix(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double uniform01(std::uint64_t& state) { return static_cast<double>(splitMix(state) >> 11) * 0x1.0p-53; }

double angleDeg(const Vec3& a, const Vec3& b) {
  // atan2 of |a x b| and a.b: accurate for small and large angles alike (acos loses digits near 0).
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

}  // namespace

AngleErrorStats computeAngleErrorStats(std::span<const double> errorsDeg) {
  AngleErrorStats stats;
  if (errorsDeg.empty()) return stats;
  std::vector<double> sorted(errorsDeg.begin(), errorsDeg.end());
  std::sort(sorted.begin(), sorted.end());
  auto rank = [&](double q) {
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
    return sorted[std::clamp<std::size_t>(k, 1, sorted.size()) - 1];
  };
  stats.medianDeg = rank(0.5);
  stats.p95Deg = rank(0.95);
  double sum = 0.0;
  for (double e : sorted) sum += e;
  stats.meanDeg = sum / static_cast<double>(sorted.size());
  stats.maxDeg = sorted.back();
  return stats;
}

std::vector<NormalAccuracyLevel> measureNormalAccuracy(const MeshDistance& mesh, const SphereTree& tree,
                                                       std::span<const NormalAccuracyCandidate> candidates,
                                                       const NormalAccuracySettings& settings) {
  if (candidates.empty()) throw Error(ErrorCode::kInvalidArgument, "measureNormalAccuracy: no candidate models");
  for (const NormalAccuracyCandidate& c : candidates) {
    if (c.maps == nullptr || c.maps->sphereCount() != tree.sphereCount()) {
      throw Error(ErrorCode::kInvalidArgument, "measureNormalAccuracy: candidate '" + c.label + "' has no map for this tree");
    }
  }
  if (settings.pointsPerLevel < 1 || settings.maxAttemptsPerLevel < settings.pointsPerLevel) {
    throw Error(ErrorCode::kInvalidArgument, "measureNormalAccuracy: need 1 <= pointsPerLevel <= maxAttemptsPerLevel");
  }
  if (!(settings.nearSurfaceFraction > 0.0 && settings.nearSurfaceFraction <= 1.0)) {
    throw Error(ErrorCode::kInvalidArgument, "measureNormalAccuracy: nearSurfaceFraction " +
                                                 std::to_string(settings.nearSurfaceFraction) + " outside (0, 1]");
  }

  struct Attempt {
    bool kept = false;
    std::uint32_t sphere = 0;
    Vec3 point = Vec3::Zero();
    Vec3 reference = Vec3::Zero();
  };
  constexpr std::uint64_t kBatch = 4096;
  std::vector<NormalAccuracyLevel> levels;
  for (std::uint32_t level = 0; level < tree.levelCount(); ++level) {
    const std::uint32_t begin = tree.levelBegin(level);
    const std::uint32_t count = tree.levelEnd(level) - begin;
    std::vector<std::uint32_t> spheres;
    std::vector<Vec3> points, references;
    std::uint64_t attempts = 0;
    std::vector<Attempt> batch(kBatch);
    while (points.size() < settings.pointsPerLevel && attempts < settings.maxAttemptsPerLevel) {
      const std::uint64_t n = std::min(kBatch, settings.maxAttemptsPerLevel - attempts);
      tbb::parallel_for(std::uint64_t(0), n, [&](std::uint64_t k) {
        std::uint64_t state = settings.seed ^ (0x632be59bd9b4e019ull * (level + 1)) ^ ((attempts + k) * 0x9e3779b97f4a7c15ull);
        splitMix(state);
        Attempt& a = batch[k];
        a.sphere = begin + std::min(count - 1, static_cast<std::uint32_t>(uniform01(state) * count));
        // Uniform direction: z uniform in [-1, 1], azimuth uniform (Archimedes' hat-box theorem).
        const double z = 2.0 * uniform01(state) - 1.0;
        const double phi = 2.0 * std::numbers::pi * uniform01(state);
        const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
        const Vec3 u(rho * std::cos(phi), rho * std::sin(phi), z);
        const double r = tree.radius[a.sphere];
        a.point = tree.center(a.sphere) + r * u;
        const ClosestPoint closest = mesh.closestPoint(a.point);
        a.kept = closest.distance <= settings.nearSurfaceFraction * r;
        a.reference = closest.normal;
      });
      for (std::uint64_t k = 0; k < n && points.size() < settings.pointsPerLevel; ++k) {
        if (!batch[k].kept) continue;
        spheres.push_back(batch[k].sphere);
        points.push_back(batch[k].point);
        references.push_back(batch[k].reference);
      }
      attempts += n;
    }

    NormalAccuracyLevel result;
    result.level = level;
    result.spheres = count;
    result.points = static_cast<std::uint32_t>(points.size());
    result.attempts = attempts;
    std::vector<double> errors(points.size());
    for (const NormalAccuracyCandidate& c : candidates) {
      tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t k) {
        errors[k] = angleDeg(contactNormal(c.model, tree, *c.maps, spheres[k], points[k]), references[k]);
      });
      result.models.push_back(computeAngleErrorStats(errors));
    }
    levels.push_back(std::move(result));
  }
  return levels;
}

}  // namespace clod
