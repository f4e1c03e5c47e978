// Tables 1 and 2 of the closest-feature-map paper, and the miss rate of its plain lookup formula.
#include "clod/sampling_statistics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "clod/error.h"

namespace clod {
namespace {

constexpr std::array<NeighbourDefinition, 3> kDefinitions = {
    NeighbourDefinition::kNearest1, NeighbourDefinition::kNearest4, NeighbourDefinition::kNearest6};
constexpr std::uint32_t kMaxStatsSamples = 50000;

// Sum, sum of squares, min, max of distances; combined across TBB chunks.
struct Accumulator {
  std::uint64_t count = 0;
  double sum = 0.0, sumSquares = 0.0;
  double min = std::numeric_limits<double>::infinity(), max = 0.0;
  void add(double d) {
    ++count;
    sum += d;
    sumSquares += d * d;
    min = std::min(min, d);
    max = std::max(max, d);
  }
  void merge(const Accumulator& o) {
    count += o.count;
    sum += o.sum;
    sumSquares += o.sumSquares;
    min = std::min(min, o.min);
    max = std::max(max, o.max);
  }
};

}  // namespace

std::string_view neighbourDefinitionName(NeighbourDefinition definition) noexcept {
  switch (definition) {
    case NeighbourDefinition::kNearest1: return "nearest-1";
    case NeighbourDefinition::kNearest4: return "nearest-4";
    case NeighbourDefinition::kNearest6: return "nearest-6";
  }
  return "unknown";
}

NeighbourDefinition parseNeighbourDefinition(std::string_view name) {
  for (NeighbourDefinition d : kDefinitions) {
    if (neighbourDefinitionName(d) == name) return d;
  }
  throw Error(ErrorCode::kInvalidArgument, "unknown neighbour definition '" + std::string(name) +
                                               "' (valid: nearest-1, nearest-4, nearest-6)");
}

NeighbourDistanceStats computeNeighbourDistanceStats(const SphereSampling& sampling,
                                                     NeighbourDefinition definition) {
  const std::uint32_t n = sampling.size();
  const auto k = static_cast<std::uint32_t>(definition);
  if (n > kMaxStatsSamples || n < k + 1) {
    throw Error(ErrorCode::kInvalidArgument,
                std::string(samplingSchemeName(sampling.scheme())) + " at resolution " +
                    std::to_string(sampling.resolution()) + ": " + std::to_string(n) +
                    " samples, neighbour statistics need " + std::to_string(k + 1) + " to " +
                    std::to_string(kMaxStatsSamples));
  }
  const auto xs = sampling.xs(), ys = sampling.ys(), zs = sampling.zs();
  // Sums are accumulated in sample order within a chunk and chunks merged; the result can differ
  // in the last bits between runs with different thread splits, far below the figures' precision.
  Accumulator total = tbb::parallel_reduce(
      tbb::blocked_range<std::uint32_t>(0, n), Accumulator{},
      [&](const tbb::blocked_range<std::uint32_t>& range, Accumulator acc) {
        std::array<std::pair<double, std::uint32_t>, 8> nearestK{};
        for (std::uint32_t i = range.begin(); i != range.end(); ++i) {
          std::uint32_t filled = 0;
          for (std::uint32_t j = 0; j < n; ++j) {
            if (j == i) continue;
            const double dx = xs[i] - xs[j], dy = ys[i] - ys[j], dz = zs[i] - zs[j];
            const std::pair<double, std::uint32_t> candidate{dx * dx + dy * dy + dz * dz, j};
            if (filled < k) {
              nearestK[filled++] = candidate;
              std::push_heap(nearestK.begin(), nearestK.begin() + filled);
            } else if (candidate < nearestK[0]) {
              std::pop_heap(nearestK.begin(), nearestK.begin() + k);
              nearestK[k - 1] = candidate;
              std::push_heap(nearestK.begin(), nearestK.begin() + k);
            }
          }
          for (std::uint32_t m = 0; m < k; ++m) acc.add(std::sqrt(nearestK[m].first));
        }
        return acc;
      },
      [](Accumulator a, const Accumulator& b) {
        a.merge(b);
        return a;
      });
  NeighbourDistanceStats stats;
  stats.distanceCount = total.count;
  stats.mean = total.sum / static_cast<double>(total.count);
  stats.stdDev = std::sqrt(std::max(0.0, total.sumSquares / static_cast<double>(total.count) - stats.mean * stats.mean));
  stats.min = total.min;
  stats.max = total.max;
  return stats;
}

std::optional<double> paperTable2StdDev(SamplingScheme scheme, int stacks) noexcept {
  // Giang & O'Sullivan 2006, Table 2 (full-precision figures as printed).
  const int column = stacks == 5 ? 0 : stacks == 10 ? 1 : stacks == 20 ? 2 : -1;
  if (column < 0) return std::nullopt;
  static constexpr std::array<double, 3> kFullPolar = {0.371169, 0.144332, 0.0717484};
  static constexpr std::array<double, 3> kAdaptivePolar = {0.17718, 0.119856, 0.0661784};
  if (scheme == SamplingScheme::kPolar) return kFullPolar[column];
  if (scheme == SamplingScheme::kAdaptivePolar) return kAdaptivePolar[column];
  return std::nullopt;
}

std::vector<SamplingTable2Row> computeSamplingTable2(NeighbourDefinition definition) {
  std::vector<SamplingTable2Row> rows;
  for (int stacks : {5, 10, 20}) {
    for (SamplingScheme scheme : allSamplingSchemes()) {
      SamplingTable2Row row;
      row.scheme = scheme;
      row.stacks = stacks;
      row.resolution = samplingResolutionForStacks(scheme, stacks);
      const SphereSampling sampling = SphereSampling::build(scheme, row.resolution);
      row.samples = sampling.size();
      row.neighbourDefinition = definition;
      row.stats = computeNeighbourDistanceStats(sampling, definition);
      row.paperStdDev = paperTable2StdDev(scheme, stacks);
      rows.push_back(row);
    }
  }
  return rows;
}

std::vector<SamplingTable1Row> computeSamplingTable1() {
  std::vector<SamplingTable1Row> rows;
  constexpr int kLeafLevel = 2;
  for (int rootStacks : {10, 16}) {
    for (SamplingScheme scheme : allSamplingSchemes()) {
      SamplingTable1Row row;
      row.scheme = scheme;
      row.rootStacks = rootStacks;
      row.leafLevel = kLeafLevel;
      row.leafStacks = stacksAtLevel(rootStacks, kLeafLevel);
      row.rootSamples = samplingSampleCount(scheme, samplingResolutionForStacks(scheme, rootStacks));
      row.leafSamples = samplingSampleCount(scheme, samplingResolutionForStacks(scheme, row.leafStacks));
      if (scheme == SamplingScheme::kAdaptivePolar) {
        // Giang & O'Sullivan 2006, Table 1.
        row.paperRootSamples = rootStacks == 10 ? 65u : 167u;
        row.paperLeafSamples = rootStacks == 10 ? 3u : 11u;
      }
      rows.push_back(row);
    }
  }
  return rows;
}

PaperFormulaMissStats measurePaperFormulaMisses(const SphereSampling& sampling, std::uint64_t queries,
                                                std::uint64_t seed) {
  CLOD_ASSERT(sampling.ringCount() > 0);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  PaperFormulaMissStats stats;
  double excessSum = 0.0;
  for (std::uint64_t q = 0; q < queries; ++q) {
    Vec3 u(gauss(rng), gauss(rng), gauss(rng));
    const double norm = u.norm();
    if (!(norm > 1e-6)) continue;  // isotropic: dropping near-zero draws keeps it uniform
    u /= norm;
    ++stats.queries;
    const double formulaDot = sampling.direction(sampling.nearestPaperFormula(u)).dot(u);
    // nearest() is exact (tests/cfm/sampling_nearest_test.cpp checks it against brute force) and
    // O(1), so this measurement stays cheap for large samplings.
    const double bestDot = sampling.direction(sampling.nearest(u)).dot(u);
    if (formulaDot < bestDot - 1e-12) {
      ++stats.misses;
      const double excess = std::acos(std::clamp(formulaDot, -1.0, 1.0)) - std::acos(std::clamp(bestDot, -1.0, 1.0));
      excessSum += excess;
      stats.maxExcessAngle = std::max(stats.maxExcessAngle, excess);
    }
  }
  if (stats.misses > 0) stats.meanExcessAngleOfMisses = excessSum / static_cast<double>(stats.misses);
  return stats;
}

}  // namespace clod
