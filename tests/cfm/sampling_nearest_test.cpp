// Nearest-sample retrieval of every scheme against brute force over all samples (the oracle).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "clod/sampling_statistics.h"
#include "clod/sphere_sampling.h"
#include "support/test_scale.h"

namespace {

using clod::SamplingScheme;
using clod::SphereSampling;
using clod::Vec3;

using clod::test::sanitizerRun;

// The issue asks for 10^5 random directions per (scheme, resolution). Under ASan+UBSan the
// brute-force oracle over up to 4000 samples dominates; 2000 directions keep it within budget.
int randomQueryCount() { return sanitizerRun() ? 2000 : 100000; }

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss;
  for (;;) {
    Vec3 v(gauss(rng), gauss(rng), gauss(rng));
    const double n = v.norm();
    if (n > 1e-6) return v / n;
  }
}

Vec3 fromAngles(double phi, double theta) {
  return {std::sin(phi) * std::cos(theta), std::sin(phi) * std::sin(theta), std::cos(phi)};
}

// Oracle: the largest dot product over all samples, computed here from the directions alone.
double bruteForceBestDot(const SphereSampling& s, const Vec3& u) {
  double best = -2.0;
  for (std::uint32_t i = 0; i < s.size(); ++i) best = std::max(best, s.direction(i).dot(u));
  return best;
}

// Ties between equidistant samples may go either way: accept any sample within 1e-12 in dot.
constexpr double kTieTolerance = 1e-12;

// Directions where a lookup is most likely to go wrong: poles, axes, ring midlines (where the
// nearest ring changes), just either side of them, and the samples themselves.
std::vector<Vec3> hardDirections(const SphereSampling& s, std::mt19937_64& rng) {
  std::vector<Vec3> dirs = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  for (std::uint32_t i = 0; i < s.size(); i += 1 + s.size() / 200) dirs.push_back(s.direction(i));
  for (std::uint32_t k = 0; k + 1 < s.ringCount(); ++k) {
    const double mid = 0.5 * (s.ringPolarAngle(k) + s.ringPolarAngle(k + 1));
    for (double offset : {-1e-9, 0.0, 1e-9, 1e-3}) {
      for (int r = 0; r < 8; ++r) dirs.push_back(fromAngles(mid + offset, angle(rng)));
    }
  }
  for (double phi : {1e-12, 1e-6, 1e-3, M_PI - 1e-3, M_PI - 1e-9}) {
    for (int r = 0; r < 8; ++r) dirs.push_back(fromAngles(phi, angle(rng)));
  }
  return dirs;
}

struct Case {
  SamplingScheme scheme;
  int resolution;
};

std::vector<Case> allCases() {
  std::vector<Case> cases;
  for (int r : {1, 2, 5, 10, 16, 20, 33}) cases.push_back({SamplingScheme::kPolar, r});
  for (int r : {1, 2, 4, 5, 10, 16, 20, 33}) cases.push_back({SamplingScheme::kAdaptivePolar, r});
  for (int r : {1, 2, 3, 5, 8, 16}) cases.push_back({SamplingScheme::kGeodesic, r});
  for (int r : {1, 2, 3, 4, 8, 16}) cases.push_back({SamplingScheme::kHealpix, r});
  for (int r : {1, 2, 12, 65, 163, 1000, 4000}) cases.push_back({SamplingScheme::kFibonacci, r});
  return cases;
}

std::string label(const Case& c) {
  return std::string(clod::samplingSchemeName(c.scheme)) + "/" + std::to_string(c.resolution);
}

TEST(SphereSamplingNearest, EveryRetrievalOfEverySchemeReturnsTheBruteForceNearestSample) {
  for (const Case& c : allCases()) {
    const SphereSampling s = SphereSampling::build(c.scheme, c.resolution);
    std::mt19937_64 rng(1234 + c.resolution);
    std::vector<Vec3> queries = hardDirections(s, rng);
    for (int q = 0; q < randomQueryCount(); ++q) queries.push_back(randomUnit(rng));
    int failures = 0;
    for (const Vec3& u : queries) {
      const double best = bruteForceBestDot(s, u);
      const std::uint32_t got = s.nearest(u);
      ASSERT_LT(got, s.size()) << label(c);
      if (s.direction(got).dot(u) < best - kTieTolerance && ++failures <= 3) {
        ADD_FAILURE() << label(c) << ": nearest(" << u.transpose() << ") = " << got << " with dot "
                      << s.direction(got).dot(u) << ", brute force " << best;
      }
      // The paper's geodesic retrieval and the linear scan share the oracle computed above.
      if (c.scheme == SamplingScheme::kGeodesic) {
        EXPECT_GE(s.direction(s.nearestQuadrantSearch(u)).dot(u), best - kTieTolerance) << label(c);
        EXPECT_GE(s.direction(s.nearestLinearScan(u)).dot(u), best - kTieTolerance) << label(c);
      }
    }
    EXPECT_EQ(failures, 0) << label(c) << " over " << queries.size() << " queries";
  }
}

TEST(SphereSamplingNearest, GeodesicCoveringRadiusBoundsTheDistanceToTheNearestSample) {
  for (int f : {1, 2, 4, 8}) {
    const SphereSampling s = SphereSampling::build(SamplingScheme::kGeodesic, f);
    std::mt19937_64 rng(5 + f);
    double worst = 0.0;
    for (int q = 0; q < 25000; ++q) {  // fixed: the 15% check below needs dense coverage
      const Vec3 u = randomUnit(rng);
      worst = std::max(worst, std::acos(std::min(1.0, bruteForceBestDot(s, u))));
    }
    EXPECT_LE(worst, s.coveringRadius()) << "geodesic/" << f;
    // A bound far above what occurs would make the quadrant lists needlessly long: random
    // directions come within 15% of the true worst case at these sizes.
    EXPECT_GE(worst, 0.85 * s.coveringRadius()) << "geodesic/" << f;
  }
}

TEST(SphereSamplingNearest, PaperFormulaMissesNearRingBoundariesButTheExactLookupDoesNot) {
  // The paper's rounding of phi then theta: report how often and how far it misses. The exact
  // lookup is checked above; here we check the plain formula's misses against brute force and
  // that the misses really exist (so the exact variant is needed), as REFERENCES.md states.
  for (SamplingScheme scheme : {SamplingScheme::kPolar, SamplingScheme::kAdaptivePolar, SamplingScheme::kHealpix}) {
    for (int stacks : {5, 10, 16, 20}) {
      const SphereSampling s = SphereSampling::buildForStacks(scheme, stacks);
      std::mt19937_64 rng(99 + stacks);
      int misses = 0, queries = randomQueryCount() / 2;
      double worstExcess = 0.0;
      for (int q = 0; q < queries; ++q) {
        const Vec3 u = randomUnit(rng);
        const double best = bruteForceBestDot(s, u);
        const double formula = s.direction(s.nearestPaperFormula(u)).dot(u);
        ASSERT_LE(formula, best + kTieTolerance);
        if (formula < best - kTieTolerance) {
          ++misses;
          worstExcess = std::max(worstExcess, std::acos(std::min(1.0, formula)) - std::acos(std::min(1.0, best)));
        }
      }
      const std::string key = std::string(clod::samplingSchemeName(scheme)) + "_" + std::to_string(stacks);
      RecordProperty(key + "_miss_rate_ppm", static_cast<int>(1e6 * misses / queries));
      std::cout << "[ paper formula ] " << key << ": misses " << misses << " / " << queries
                << ", worst excess " << worstExcess * 180.0 / M_PI << " deg\n";
      EXPECT_GT(misses, 0) << key << ": expected the plain formula to miss sometimes";
    }
  }
}

TEST(SphereSamplingNearest, MissStatisticsAgreeWithAnIndependentCount) {
  const SphereSampling s = SphereSampling::build(SamplingScheme::kAdaptivePolar, 10);
  const auto stats = clod::measurePaperFormulaMisses(s, 20000, 7);
  EXPECT_EQ(stats.queries, 20000u);
  EXPECT_GT(stats.misses, 0u);
  EXPECT_LT(stats.misses, stats.queries);
  EXPECT_GT(stats.maxExcessAngle, 0.0);
  EXPECT_LE(stats.meanExcessAngleOfMisses, stats.maxExcessAngle);
  // Independent recount with the same seed and the same direction generator (std::normal on
  // mt19937_64, normalised) against the brute-force oracle.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  std::uint64_t misses = 0;
  for (int q = 0; q < 20000; ++q) {
    Vec3 u(gauss(rng), gauss(rng), gauss(rng));
    u.normalize();
    misses += s.direction(s.nearestPaperFormula(u)).dot(u) < bruteForceBestDot(s, u) - kTieTolerance;
  }
  EXPECT_EQ(stats.misses, misses);
}

}  // namespace
