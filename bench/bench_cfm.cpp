// Closest feature maps: lookup and build cost.
//
//   BM_Cfm_Lookup/<scheme>   sphere index + direction -> decoded normal (ClosestFeatureMap::normal),
//                            spot, bake-default tree (medial, 8-ary, 5 levels), 10 stacks; queries
//                            cycle through 4096 precomputed (random sphere, random direction) pairs
//   BM_Cfm_LookupDos          the D&O normal on the same queries (normalise p - c), for scale
//   BM_Cfm_Build/<mesh>      buildClosestFeatureMap (adaptive polar, 10 stacks) on a prebuilt tree;
//                            counters: spheres, normals stored, pool bytes
// Trees are built once per process (outside the timed loops).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/contact_normal.h"
#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"

namespace {

using namespace clod;

struct Prepared {
  std::unique_ptr<MeshDistance> distance;
  SphereTree tree;
};

const Prepared& prepared(const std::string& mesh) {
  static std::map<std::string, Prepared> cache;
  auto it = cache.find(mesh);
  if (it == cache.end()) {
    Prepared p;
    p.distance = std::make_unique<MeshDistance>(loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / mesh).mesh);
    p.tree = buildSphereTree(*p.distance, SphereTreeSettings{});
    it = cache.emplace(mesh, std::move(p)).first;
  }
  return it->second;
}

struct Query {
  std::uint32_t sphere;
  Vec3 point;
};

std::vector<Query> makeQueries(const SphereTree& tree) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> gauss;
  std::uniform_int_distribution<std::uint32_t> pick(0, tree.sphereCount() - 1);
  std::vector<Query> queries;
  while (queries.size() < 4096) {
    const Vec3 d(gauss(rng), gauss(rng), gauss(rng));
    if (d.norm() < 1e-6) continue;
    const std::uint32_t s = pick(rng);
    queries.push_back({s, tree.center(s) + tree.radius[s] * d.normalized()});
  }
  return queries;
}

void BM_Cfm_Lookup(benchmark::State& state, SamplingScheme scheme) {
  const Prepared& p = prepared("spot.obj");
  ClosestFeatureMapSettings settings;
  settings.scheme = scheme;
  const ClosestFeatureMap maps = buildClosestFeatureMap(*p.distance, p.tree, settings);
  const std::vector<Query> queries = makeQueries(p.tree);
  std::size_t i = 0;
  for (auto _ : state) {
    const Query& q = queries[i++ & 4095];
    Vec3 n = maps.normal(q.sphere, q.point - p.tree.center(q.sphere));
    benchmark::DoNotOptimize(n);
  }
  state.counters["spheres"] = maps.sphereCount();
  state.counters["rootSamples"] = maps.samplesAtLevel(0);
  state.counters["poolBytes"] = static_cast<double>(maps.poolBytes());
}

void BM_Cfm_LookupDos(benchmark::State& state) {
  const Prepared& p = prepared("spot.obj");
  const ClosestFeatureMap maps = buildClosestFeatureMap(*p.distance, p.tree, {});
  const std::vector<Query> queries = makeQueries(p.tree);
  std::size_t i = 0;
  for (auto _ : state) {
    const Query& q = queries[i++ & 4095];
    Vec3 n = contactNormal(ContactNormalModel::kDingliana, p.tree, maps, q.sphere, q.point);
    benchmark::DoNotOptimize(n);
  }
}

void BM_Cfm_Build(benchmark::State& state, const std::string& mesh) {
  const Prepared& p = prepared(mesh);
  std::size_t normals = 0, bytes = 0;
  for (auto _ : state) {
    const ClosestFeatureMap maps = buildClosestFeatureMap(*p.distance, p.tree, {});
    normals = maps.poolSize();
    bytes = maps.poolBytes();
  }
  state.counters["spheres"] = p.tree.sphereCount();
  state.counters["triangles"] = p.distance->mesh().triangleCount();
  state.counters["normals"] = static_cast<double>(normals);
  state.counters["poolBytes"] = static_cast<double>(bytes);
}

const bool kRegistered = [] {
  for (SamplingScheme scheme : allSamplingSchemes()) {
    benchmark::RegisterBenchmark(("BM_Cfm_Lookup/" + std::string(samplingSchemeName(scheme))).c_str(), BM_Cfm_Lookup, scheme);
  }
  benchmark::RegisterBenchmark("BM_Cfm_LookupDos", BM_Cfm_LookupDos);
  for (const char* mesh : {"bunny-1500.obj", "spot.obj", "fandisk.obj", "rocker-arm.obj"}) {
    std::string name = mesh;
    name = name.substr(0, name.find('.'));
    benchmark::RegisterBenchmark(("BM_Cfm_Build/" + name).c_str(), BM_Cfm_Build, std::string(mesh))
        ->Unit(benchmark::kMillisecond)
        ->Iterations(3);
  }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
