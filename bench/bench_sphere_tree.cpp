// Sphere-tree build time (single-threaded and all threads) and fit per level, for the shared
// closed meshes and the 69k-triangle Stanford bunny: octree, medial (default: per node the better
// of merge/burst and k-means), medial-mergeburst (Bradshaw's merge/burst reduction alone) and
// medial-kmeans (the earlier k-means reduction alone).
//   BM_SphereTree_Build/<mesh>/<builder>/<threads>   threads: 1, or 0 = all cores
// Counters: spheres per level (L<l>_spheres) and fit mean/max per level (L<l>_fitMean, L<l>_fitMax,
// in units of the bounding-box diagonal), measured once outside the timed loop.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <tbb/global_control.h>

#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"

namespace {

const clod::MeshDistance& meshNamed(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<clod::MeshDistance>> cache;
  std::lock_guard lock(mutex);
  auto& slot = cache[name];
  if (!slot) {
    const auto path = std::filesystem::path(CLOD_SHARED_MESH_DIR) / (name + ".obj");
    slot = std::make_unique<clod::MeshDistance>(clod::loadMesh(path).mesh);
  }
  return *slot;
}

struct Builder {
  const char* name;
  clod::SphereTreeMethod method;
  clod::MedialReduction reduction;
};
constexpr Builder kBuilders[] = {
    {"octree", clod::SphereTreeMethod::kOctree, clod::MedialReduction::kBest},
    {"medial", clod::SphereTreeMethod::kMedial, clod::MedialReduction::kBest},
    {"medial-mergeburst", clod::SphereTreeMethod::kMedial, clod::MedialReduction::kMergeBurst},
    {"medial-kmeans", clod::SphereTreeMethod::kMedial, clod::MedialReduction::kKMeans},
};

void buildBenchmark(benchmark::State& state, const std::string& mesh, const Builder& builder) {
  const clod::MeshDistance& distance = meshNamed(mesh);
  const int threads = static_cast<int>(state.range(0));
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  clod::SphereTreeSettings settings;
  settings.method = builder.method;
  settings.medialReduction = builder.reduction;
  clod::SphereTree tree;
  for (auto _ : state) {
    tree = clod::buildSphereTree(distance, settings);
    benchmark::DoNotOptimize(tree.radius.data());
  }
  limit.reset();
  const auto fit = clod::measureSphereTreeFit(tree, distance);
  for (std::size_t l = 0; l < fit.size(); ++l) {
    // Names built with append: GCC 12 warns falsely (-Wrestrict) on some operator+ chains.
    std::string prefix = "L";
    prefix.append(std::to_string(l)).append("_");
    state.counters[std::string(prefix).append("spheres")] = fit[l].spheres;
    state.counters[std::string(prefix).append("fitMean")] = fit[l].fitMean;
    state.counters[std::string(prefix).append("fitMax")] = fit[l].fitMax;
  }
  state.counters["triangles"] = distance.mesh().triangleCount();
}

const bool registered = [] {
  for (const char* mesh : {"stanford-bunny", "spot", "fandisk", "rocker-arm", "cow"})
    for (const Builder& builder : kBuilders) {
      std::string name = "BM_SphereTree_Build/";
      name.append(mesh).append("/").append(builder.name);
      benchmark::RegisterBenchmark(name.c_str(), [mesh = std::string(mesh), &builder](benchmark::State& state) {
        buildBenchmark(state, mesh, builder);
      })
          ->ArgName("threads")
          ->Arg(1)
          ->Arg(0)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->Iterations(3);
    }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
