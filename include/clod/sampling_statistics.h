#pragma once
// Measurements of sphere samplings that reproduce the closest-feature-map paper's Tables 1 and 2
// (Giang & O'Sullivan 2006, section 5 and 7) and quantify retrieval accuracy. Used by
// `clod experiment sampling`, the tests and docs/sampling.md. Not meant for the query path.

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "clod/sphere_sampling.h"

namespace clod {

/// Which pairs of samples count as "neighbouring" in Table 2. The paper does not say; each
/// definition below is directed: every sample contributes the distances to its own k nearest
/// other samples (chord length on the unit sphere; coincident samples - the S copies of the
/// pole in full polar - count, at distance 0; ties broken by lower index), so a mutual pair is
/// counted twice. The standard deviation is the population one (divide by the count).
enum class NeighbourDefinition : std::uint8_t {
  kNearest1 = 1,  ///< each sample's nearest other sample
  kNearest4 = 4,  ///< each sample's 4 nearest (a polar grid's N/S/E/W); closest to the paper
  kNearest6 = 6,  ///< each sample's 6 nearest (a triangulation's typical valence)
};

/// "nearest-1", "nearest-4", "nearest-6".
std::string_view neighbourDefinitionName(NeighbourDefinition definition) noexcept;
/// Inverse of neighbourDefinitionName; throws clod::Error(kInvalidArgument) naming the string.
NeighbourDefinition parseNeighbourDefinition(std::string_view name);

/// Statistics of the neighbour distances of one sampling.
struct NeighbourDistanceStats {
  std::uint64_t distanceCount = 0;  ///< number of (sample, neighbour) distances
  double mean = 0.0;                ///< chord length, unit sphere
  double stdDev = 0.0;              ///< population standard deviation
  double min = 0.0;
  double max = 0.0;
};

/// Neighbour-distance statistics by brute force: O(n^2) time (parallel), O(n) memory.
/// Throws clod::Error(kInvalidArgument) if the sampling has more than 50,000 samples (the
/// quadratic cost would run for minutes) or fewer than k + 1.
NeighbourDistanceStats computeNeighbourDistanceStats(const SphereSampling& sampling,
                                                     NeighbourDefinition definition);

/// One row of Table 2: a scheme at a stack count (or the matched resolution).
struct SamplingTable2Row {
  SamplingScheme scheme = SamplingScheme::kPolar;
  int stacks = 0;                      ///< the paper's stack count this row belongs to
  int resolution = 0;                  ///< samplingResolutionForStacks(scheme, stacks)
  std::uint32_t samples = 0;
  NeighbourDefinition neighbourDefinition = NeighbourDefinition::kNearest4;
  NeighbourDistanceStats stats;        ///< stats.stdDev is the Table 2 figure
  std::optional<double> paperStdDev;   ///< the paper's figure (polar and adaptive polar only)
};

/// The paper's Table 2 values: full polar and adaptive polar at 5, 10, 20 stacks
/// (0.371169 / 0.144332 / 0.0717484 and 0.17718 / 0.119856 / 0.0661784); nullopt otherwise.
std::optional<double> paperTable2StdDev(SamplingScheme scheme, int stacks) noexcept;

/// Table 2 for every scheme at 5, 10 and 20 stacks (geodesic and HEALPix at the resolution whose
/// count matches adaptive polar), rows ordered by stacks then scheme. Deterministic. ~0.1 s.
std::vector<SamplingTable2Row> computeSamplingTable2(NeighbourDefinition definition);

/// One row of Table 1: sample counts at the root and at a leaf level of a sphere-tree under the
/// progressive refinement rule (stacksAtLevel).
struct SamplingTable1Row {
  SamplingScheme scheme = SamplingScheme::kAdaptivePolar;
  int rootStacks = 0;
  int leafLevel = 0;     ///< the paper's trees have leaves at level 2 (10 -> 5 -> 2, 16 -> 8 -> 4)
  int leafStacks = 0;
  std::uint32_t rootSamples = 0;
  std::uint32_t leafSamples = 0;
  std::optional<std::uint32_t> paperRootSamples;  ///< 65 and 167 (adaptive polar only)
  std::optional<std::uint32_t> paperLeafSamples;  ///< 3 and 11 (adaptive polar only)
};

/// Table 1 for root stacks 10 and 16, leaves at level 2, every scheme. The paper's 167 at 16
/// stacks is not reproduced (the rule gives 163); the row reports both.
std::vector<SamplingTable1Row> computeSamplingTable1();

/// How far the paper's plain formula (nearestPaperFormula) is from the true nearest sample.
struct PaperFormulaMissStats {
  std::uint64_t queries = 0;
  std::uint64_t misses = 0;         ///< queries where its sample is farther than the nearest by > 1e-12 in dot
  double maxExcessAngle = 0.0;      ///< radians: max of angle(formula sample) - angle(nearest sample)
  double meanExcessAngleOfMisses = 0.0;
};

/// Measures PaperFormulaMissStats over `queries` uniformly random directions (fixed `seed`, so
/// deterministic), comparing with nearest() (exact). O(queries). CLOD_ASSERT: a ring scheme.
PaperFormulaMissStats measurePaperFormulaMisses(const SphereSampling& sampling, std::uint64_t queries,
                                                std::uint64_t seed);

}  // namespace clod
