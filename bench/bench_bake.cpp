// Bake files: how fast an engine gets a mesh's precomputed data back, against the baseline of
// loading the source OBJ (and, for scale, rebuilding the sphere-tree).
//
//   BM_Bake_Load/<mesh>      loadBake from a file (page cache warm): open + read + checksums + decode
//   BM_Bake_Decode/<mesh>    decodeBake from memory (no I/O)
//   BM_Bake_Encode/<mesh>    encodeBake to memory
//   BM_Mesh_LoadObj/<mesh>   loadMesh of the source OBJ (Assimp + weld + validation): the baseline
//
// Meshes: 0 = bunny-1500.obj, 1 = stanford-bunny.obj (69,451 triangles). Each is baked once per
// process with the default settings (medial, branching 8, depth 4) into the temp directory.
// Counters: file_bytes, spheres, bytes_per_sphere (STRE section bytes / spheres), triangles.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <string>
#include <unistd.h>

#include "clod/bake.h"
#include "clod/mesh_io.h"

namespace {

const char* const kMeshes[] = {"bunny-1500.obj", "stanford-bunny.obj"};

struct BakedMesh {
  std::filesystem::path objPath;
  std::filesystem::path bakePath;
  std::vector<std::byte> bytes;
  clod::BakeContents contents;
  double stre = 0.0;  // STRE payload bytes
};

const BakedMesh& bakedMesh(std::int64_t index) {
  static std::map<std::int64_t, BakedMesh> cache;
  auto found = cache.find(index);
  if (found != cache.end()) return found->second;
  BakedMesh baked;
  baked.objPath = std::filesystem::path(CLOD_SHARED_MESH_DIR) / kMeshes[index];
  baked.bakePath = std::filesystem::temp_directory_path() /
                   ("clod_bench_bake_" + std::to_string(::getpid()) + "_" + std::to_string(index) + ".clod");
  clod::BakeSettings settings;
  settings.measureFit = false;
  settings.sourceName = kMeshes[index];
  baked.contents = clod::bakeMesh(clod::loadMesh(baked.objPath).mesh, settings).contents;
  baked.bytes = clod::encodeBake(baked.contents);
  clod::saveBake(baked.bakePath, baked.contents);
  for (const auto& e : clod::BakeFileReader(baked.bytes).entries()) {
    if (e.tag == clod::kBakeSphereTreeTag) baked.stre = static_cast<double>(e.size);
  }
  return cache.emplace(index, std::move(baked)).first->second;
}

void setCounters(benchmark::State& state, const BakedMesh& baked) {
  state.SetLabel(kMeshes[state.range(0)]);
  state.counters["file_bytes"] = static_cast<double>(baked.bytes.size());
  state.counters["spheres"] = baked.contents.sphereTree.sphereCount();
  state.counters["bytes_per_sphere"] = baked.stre / baked.contents.sphereTree.sphereCount();
  state.counters["triangles"] = baked.contents.mesh.triangleCount();
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * baked.bytes.size()));
}

void BM_Bake_Load(benchmark::State& state) {
  const BakedMesh& baked = bakedMesh(state.range(0));
  for (auto _ : state) {
    clod::BakeContents contents = clod::loadBake(baked.bakePath);
    benchmark::DoNotOptimize(contents.sphereTree.radius.data());
  }
  setCounters(state, baked);
}

void BM_Bake_Decode(benchmark::State& state) {
  const BakedMesh& baked = bakedMesh(state.range(0));
  for (auto _ : state) {
    clod::BakeContents contents = clod::decodeBake(baked.bytes);
    benchmark::DoNotOptimize(contents.sphereTree.radius.data());
  }
  setCounters(state, baked);
}

void BM_Bake_Encode(benchmark::State& state) {
  const BakedMesh& baked = bakedMesh(state.range(0));
  for (auto _ : state) {
    std::vector<std::byte> bytes = clod::encodeBake(baked.contents);
    benchmark::DoNotOptimize(bytes.data());
  }
  setCounters(state, baked);
}

void BM_Mesh_LoadObj(benchmark::State& state) {
  const BakedMesh& baked = bakedMesh(state.range(0));
  for (auto _ : state) {
    clod::LoadedMesh loaded = clod::loadMesh(baked.objPath);
    benchmark::DoNotOptimize(loaded.mesh.vertices.data());
  }
  state.SetLabel(kMeshes[state.range(0)]);
  state.counters["triangles"] = baked.contents.mesh.triangleCount();
}

BENCHMARK(BM_Bake_Load)->DenseRange(0, 1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Bake_Decode)->DenseRange(0, 1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Bake_Encode)->DenseRange(0, 1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Mesh_LoadObj)->DenseRange(0, 1)->Unit(benchmark::kMicrosecond);

// Removes the temporary bake files when the process ends.
struct Cleanup {
  ~Cleanup() {
    for (std::int64_t i = 0; i < 2; ++i) {
      std::error_code ec;
      std::filesystem::remove(std::filesystem::temp_directory_path() /
                                  ("clod_bench_bake_" + std::to_string(::getpid()) + "_" + std::to_string(i) + ".clod"),
                              ec);
    }
  }
} gCleanup;

}  // namespace

BENCHMARK_MAIN();
