// Nearest-sample retrieval cost per scheme and method, and octahedral normal encode/decode cost.
//
//   BM_Sampling_Nearest/<scheme>/<stacks>             exact default lookup (nearest())
//   BM_Sampling_NearestPaperFormula/<scheme>/<stacks>  the paper's plain rounding (ring schemes)
//   BM_Sampling_NearestQuadrant/geodesic/<stacks>      the paper's geodesic retrieval
// Schemes: polar, adaptive-polar, geodesic, healpix, fibonacci.
//   BM_Sampling_NearestLinearScan/<scheme>/<stacks>    argmax over all samples
// <stacks> is the paper's stack count; geodesic and HEALPix use the resolution with the closest
// sample count (samplingResolutionForStacks), reported in the counters with the sample count.
// Queries cycle through 4096 precomputed uniform random directions (fixed seed).
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "clod/normal_encoding.h"
#include "clod/sphere_sampling.h"

namespace {

using clod::SamplingScheme;
using clod::SphereSampling;
using clod::Vec3;

const std::vector<Vec3>& queryDirections() {
  static const std::vector<Vec3> dirs = [] {
    std::mt19937_64 rng(42);
    std::normal_distribution<double> gauss;
    std::vector<Vec3> v;
    while (v.size() < 4096) {
      Vec3 d(gauss(rng), gauss(rng), gauss(rng));
      if (d.norm() > 1e-6) v.push_back(d.normalized());
    }
    return v;
  }();
  return dirs;
}

enum class Method { kNearest, kPaperFormula, kQuadrant, kLinearScan };

void runLookup(benchmark::State& state, SamplingScheme scheme, int stacks, Method method) {
  const SphereSampling sampling = SphereSampling::buildForStacks(scheme, stacks);
  const auto& dirs = queryDirections();
  std::size_t i = 0;
  std::uint32_t sink = 0;
  for (auto _ : state) {
    const Vec3& u = dirs[i++ & 4095];
    std::uint32_t index = 0;
    switch (method) {
      case Method::kNearest: index = sampling.nearest(u); break;
      case Method::kPaperFormula: index = sampling.nearestPaperFormula(u); break;
      case Method::kQuadrant: index = sampling.nearestQuadrantSearch(u); break;
      case Method::kLinearScan: index = sampling.nearestLinearScan(u); break;
    }
    sink += index;
    benchmark::DoNotOptimize(sink);
  }
  state.counters["samples"] = sampling.size();
  state.counters["resolution"] = sampling.resolution();
  state.counters["bytes"] = static_cast<double>(sampling.memoryBytes());
  state.SetItemsProcessed(state.iterations());
}

void registerLookups() {
  const int stackCounts[] = {5, 10, 16, 20, 40, 100};
  for (SamplingScheme scheme : clod::allSamplingSchemes()) {
    const std::string name(clod::samplingSchemeName(scheme));
    for (int stacks : stackCounts) {
      if (scheme == SamplingScheme::kGeodesic && clod::samplingResolutionForStacks(scheme, stacks) > 32) continue;
      const std::string suffix = "/" + name + "/" + std::to_string(stacks);
      benchmark::RegisterBenchmark(("BM_Sampling_Nearest" + suffix).c_str(), runLookup, scheme, stacks, Method::kNearest);
      const bool ringScheme = scheme == SamplingScheme::kPolar || scheme == SamplingScheme::kAdaptivePolar ||
                              scheme == SamplingScheme::kHealpix;
      if (ringScheme) {
        benchmark::RegisterBenchmark(("BM_Sampling_NearestPaperFormula" + suffix).c_str(), runLookup, scheme, stacks, Method::kPaperFormula);
      }
      if (scheme == SamplingScheme::kGeodesic) {
        benchmark::RegisterBenchmark(("BM_Sampling_NearestQuadrant" + suffix).c_str(), runLookup, scheme, stacks, Method::kQuadrant);
      }
      if (stacks <= 40) {
        benchmark::RegisterBenchmark(("BM_Sampling_NearestLinearScan" + suffix).c_str(), runLookup, scheme, stacks, Method::kLinearScan);
      }
    }
  }
}

void BM_NormalEncoding_Encode16(benchmark::State& state) {
  const auto& dirs = queryDirections();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(clod::encodeOctahedral16(dirs[i++ & 4095]));
}
BENCHMARK(BM_NormalEncoding_Encode16);

void BM_NormalEncoding_Decode16(benchmark::State& state) {
  std::uint16_t code = 12345;
  for (auto _ : state) {
    const Vec3 v = clod::decodeOctahedral16(code);
    benchmark::DoNotOptimize(v);
    code = static_cast<std::uint16_t>(code * 31u + 7u);
  }
}
BENCHMARK(BM_NormalEncoding_Decode16);

void BM_NormalEncoding_Decode32(benchmark::State& state) {
  std::uint32_t code = 123456789u;
  for (auto _ : state) {
    const Vec3 v = clod::decodeOctahedral32(code);
    benchmark::DoNotOptimize(v);
    code = code * 1664525u + 1013904223u;
  }
}
BENCHMARK(BM_NormalEncoding_Decode32);

}  // namespace

int main(int argc, char** argv) {
  registerLookups();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
