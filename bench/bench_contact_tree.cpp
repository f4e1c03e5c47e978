// Contact-tree benchmarks: build time, memory, accuracy and trilinear sampling throughput,
// side by side with an OpenVDB narrow-band level set (openvdb::tools::meshToLevelSet) when
// bench/contact_tree.cmake found OpenVDB (CLOD_BENCH_HAVE_OPENVDB).
//
// Accuracy is measured the same way for both: the largest |approx - exact| over 20,000 random
// points within 1 % of the diagonal of the surface, exact = clod::MeshDistance. Throughput uses
// 2^17 such points, one thread.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <memory>
#include <random>
#include <string>

#include <tbb/parallel_for.h>

#include "clod/contact_sampling.h"
#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

#ifdef CLOD_BENCH_HAVE_OPENVDB
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#endif

namespace {

using namespace clod;

const char* kMeshes[] = {"stanford-bunny.obj", "fandisk.obj"};

struct MeshData {
  std::unique_ptr<MeshDistance> exact;
  double diagonal = 0.0;
  std::vector<Vec3> queryPoints;   // 2^17 band points for throughput
  std::vector<Vec3> errorPoints;   // 20,000 band points for accuracy
  std::vector<double> errorExact;  // exact signed distance at errorPoints
};

std::vector<Vec3> bandPoints(const TriangleMesh& mesh, double band, std::size_t count, std::uint64_t seed) {
  std::vector<double> prefix;
  double sum = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) prefix.push_back(sum += mesh.triangleArea(t));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<Vec3> points;
  while (points.size() < count) {
    const auto t = std::min<std::size_t>(std::upper_bound(prefix.begin(), prefix.end(), uni(rng) * sum) - prefix.begin(),
                                         mesh.triangleCount() - 1);
    double a = uni(rng), b = uni(rng);
    if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
    const auto tri = static_cast<std::uint32_t>(t);
    Vec3 p = mesh.corner(tri, 0) + a * (mesh.corner(tri, 1) - mesh.corner(tri, 0)) + b * (mesh.corner(tri, 2) - mesh.corner(tri, 0));
    Vec3 offset;
    do offset = 2.0 * Vec3(uni(rng), uni(rng), uni(rng)) - Vec3::Ones();
    while (offset.squaredNorm() > 1.0);
    points.push_back(p + band * offset);
  }
  return points;
}

MeshData& meshData(const std::string& name) {
  static std::map<std::string, std::unique_ptr<MeshData>> cache;
  auto& slot = cache[name];
  if (!slot) {
    slot = std::make_unique<MeshData>();
    LoadedMesh loaded = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/" + name);
    slot->diagonal = loaded.mesh.bounds().diagonal();
    slot->queryPoints = bandPoints(loaded.mesh, 0.01 * slot->diagonal, 1u << 17, 1);
    slot->errorPoints = bandPoints(loaded.mesh, 0.01 * slot->diagonal, 20000, 2);
    slot->exact = std::make_unique<MeshDistance>(std::move(loaded.mesh));
    slot->errorExact.resize(slot->errorPoints.size());
    tbb::parallel_for(std::size_t{0}, slot->errorPoints.size(),
                      [&](std::size_t i) { slot->errorExact[i] = slot->exact->signedDistance(slot->errorPoints[i]); });
  }
  return *slot;
}

// Largest and 99.9th-percentile |approx - exact| at the error points, relative to the diagonal.
template <class Sampler>
std::pair<double, double> measureError(const MeshData& data, Sampler&& sampleAt) {
  std::vector<double> errors(data.errorPoints.size());
  for (std::size_t i = 0; i < errors.size(); ++i) errors[i] = std::abs(sampleAt(data.errorPoints[i]) - data.errorExact[i]);
  std::sort(errors.begin(), errors.end());
  return {errors.back() / data.diagonal, errors[errors.size() * 999 / 1000] / data.diagonal};
}

// eps_s of an exponent argument: 3 -> 1e-3, 4 -> 1e-4 of the diagonal; 2 -> 5e-3, the coarse
// tree whose max error matches OpenVDB's at voxel = diag/128 (5.8e-3 on fandisk).
double errorRelOf(std::int64_t arg) { return arg == 2 ? 5e-3 : arg == 3 ? 1e-3 : 1e-4; }

std::map<std::pair<std::string, std::int64_t>, ContactTree>& treeCache() {
  static std::map<std::pair<std::string, std::int64_t>, ContactTree> cache;
  return cache;
}

// The tree BM_ContactTree_Build made in this run (a 1e-4 build costs minutes), else a new one.
const ContactTree& cachedTree(const std::string& name, std::int64_t errorExponent) {
  auto& cache = treeCache();
  auto it = cache.find({name, errorExponent});
  if (it == cache.end()) {
    ContactTreeSettings settings;
    settings.errorRel = errorRelOf(errorExponent);
    settings.maxDepth = errorExponent == 4 ? 14 : 12;
    it = cache.emplace(std::make_pair(name, errorExponent), buildContactTree(*meshData(name).exact, settings)).first;
  }
  return it->second;
}

// Arguments: mesh index, eps_s exponent (errorRelOf).
void BM_ContactTree_Build(benchmark::State& state) {
  const std::string name = kMeshes[state.range(0)];
  MeshData& data = meshData(name);
  ContactTreeSettings settings;
  settings.errorRel = errorRelOf(state.range(1));
  settings.maxDepth = state.range(1) == 4 ? 14 : 12;
  ContactTree tree;
  ContactTreeBuildStats stats;
  const std::clock_t cpuStart = std::clock();  // process CPU time: all TBB threads together
  for (auto _ : state) {
    tree = buildContactTree(*data.exact, settings, &stats);
    benchmark::DoNotOptimize(tree.nodeWords.data());
  }
  state.counters["buildCpuS"] = double(std::clock() - cpuStart) / CLOCKS_PER_SEC / double(state.iterations());
  const auto [maxErr, p999] = measureError(data, [&](const Vec3& p) { return tree.distance(p); });
  state.SetLabel(name);
  state.counters["nodes"] = double(stats.nodes);
  state.counters["MiB"] = double(tree.memoryBytes()) / (1 << 20);
  state.counters["bytesPerNode"] = double(tree.memoryBytes()) / double(stats.nodes);
  state.counters["maxErrRel"] = maxErr;
  state.counters["p999ErrRel"] = p999;
  state.counters["exactQueries"] = double(stats.distanceQueries);
  state.counters["leavesOverEps"] = double(stats.leavesAboveError);
  state.counters["discontinuousCells"] = double(stats.discontinuousCells);
  state.counters["gridDepth"] = double(tree.gridDepth);
  treeCache()[{name, state.range(1)}] = std::move(tree);
}
BENCHMARK(BM_ContactTree_Build)->ArgsProduct({{0, 1}, {2, 3, 4}})->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ContactTree_Sample(benchmark::State& state) {
  const std::string name = kMeshes[state.range(0)];
  const ContactTree& tree = cachedTree(name, state.range(1));
  const auto& points = meshData(name).queryPoints;
  std::size_t i = 0;
  double sum = 0.0;
  for (auto _ : state) {
    const ContactFieldSample s = tree.sample(points[i]);
    sum += s.distance + s.gradient.x();
    i = (i + 1) & (points.size() - 1);
  }
  benchmark::DoNotOptimize(sum);
  state.SetLabel(name);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ContactTree_Sample)->ArgsProduct({{0, 1}, {2, 3, 4}});

// The same queries on a copy of the tree without its lookup grid (descent from the root):
// what the grid buys, measured in the same run.
void BM_ContactTree_SampleNoGrid(benchmark::State& state) {
  const std::string name = kMeshes[state.range(0)];
  ContactTree tree = cachedTree(name, state.range(1));
  tree.gridDepth = 0;
  tree.gridNode.clear();
  tree.gridCorners.clear();
  const auto& points = meshData(name).queryPoints;
  std::size_t i = 0;
  double sum = 0.0;
  for (auto _ : state) {
    const ContactFieldSample s = tree.sample(points[i]);
    sum += s.distance + s.gradient.x();
    i = (i + 1) & (points.size() - 1);
  }
  benchmark::DoNotOptimize(sum);
  state.SetLabel(name);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ContactTree_SampleNoGrid)->ArgsProduct({{0, 1}, {3, 4}});

// Distance only, stopped at depth 6: what a budget-limited query costs.
void BM_ContactTree_SampleDepth6(benchmark::State& state) {
  const std::string name = kMeshes[state.range(0)];
  const ContactTree& tree = cachedTree(name, 3);
  const auto& points = meshData(name).queryPoints;
  std::size_t i = 0;
  double sum = 0.0;
  for (auto _ : state) {
    sum += tree.sample(points[i], 6).distance;
    i = (i + 1) & (points.size() - 1);
  }
  benchmark::DoNotOptimize(sum);
  state.SetLabel(name);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ContactTree_SampleDepth6)->Arg(0)->Arg(1);

// Full contact generation (traversal + sampling + thinning) for one pair.
// Arg 0: a 0.5-box resting on a 1-box, 1e-3 deep, full depth. Arg 1: the same stopped at
// depth 6 (what a time budget buys). Arg 2: two spot meshes, one shifted by 60 % of the
// bounding box along x so that they interpenetrate.
void BM_ContactTree_FindContacts(benchmark::State& state) {
  static ContactTree smallBox, bigBox;
  if (bigBox.nodeCount() == 0) {
    ContactTreeSettings settings;
    settings.errorRel = 1e-3;
    smallBox = buildContactTree(MeshDistance(makeBox(Vec3::Constant(0.5))), settings);
    bigBox = buildContactTree(MeshDistance(makeBox(Vec3::Constant(1.0))), settings);
  }
  const bool boxes = state.range(0) != 2;
  const ContactTree& a = boxes ? smallBox : cachedTree("spot.obj", 3);
  const ContactTree& b = boxes ? bigBox : cachedTree("spot.obj", 3);
  Pose poseA;
  if (boxes) {
    poseA.translation = Vec3(0.3, -0.2, 1.5 - 1e-3);
  } else {
    poseA.translation = Vec3(0.6 * meshData("spot.obj").exact->mesh().bounds().extent().x(), 0, 0);
  }
  std::vector<ContactPoint> contacts;
  ContactQueryStats stats;
  ContactSamplingSettings settings;
  if (state.range(0) == 1) settings.maxDepth = 6;
  for (auto _ : state) {
    findContacts(a, poseA, b, Pose{}, settings, contacts, &stats);
    benchmark::DoNotOptimize(contacts.data());
  }
  state.SetLabel(boxes ? (state.range(0) == 1 ? "box on box, depth 6" : "box on box") : "spot into spot");
  state.counters["contacts"] = double(contacts.size());
  state.counters["rawContacts"] = double(stats.rawContacts);
  state.counters["pairsVisited"] = double(stats.cellPairsVisited);
}
BENCHMARK(BM_ContactTree_FindContacts)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

#ifdef CLOD_BENCH_HAVE_OPENVDB
struct VdbInput {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
};

VdbInput vdbInput(const MeshData& data) {
  VdbInput in;
  for (const Vec3& v : data.exact->mesh().vertices) in.points.emplace_back(float(v.x()), float(v.y()), float(v.z()));
  for (const Triangle& t : data.exact->mesh().triangles) in.triangles.emplace_back(t[0], t[1], t[2]);
  return in;
}

// The band must cover 1 % of the diagonal plus one voxel for trilinear stencils.
float halfWidthFor(double voxel, double diagonal) { return std::max(3.0f, float(std::ceil(0.01 * diagonal / voxel)) + 2.0f); }

openvdb::FloatGrid::Ptr cachedVdb(const std::string& name, std::int64_t divisions) {
  static std::map<std::pair<std::string, std::int64_t>, openvdb::FloatGrid::Ptr> cache;
  auto& grid = cache[{name, divisions}];
  if (!grid) {
    const MeshData& data = meshData(name);
    const VdbInput in = vdbInput(data);
    const double voxel = data.diagonal / double(divisions);
    grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*openvdb::math::Transform::createLinearTransform(voxel),
                                                              in.points, in.triangles, halfWidthFor(voxel, data.diagonal));
  }
  return grid;
}

// Arguments: mesh index, voxel = diagonal / divisions.
void BM_OpenVdb_Build(benchmark::State& state) {
  openvdb::initialize();
  const std::string name = kMeshes[state.range(0)];
  const MeshData& data = meshData(name);
  const VdbInput in = vdbInput(data);
  const double voxel = data.diagonal / double(state.range(1));
  openvdb::FloatGrid::Ptr grid;
  const std::clock_t cpuStart = std::clock();
  for (auto _ : state) {
    grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*openvdb::math::Transform::createLinearTransform(voxel),
                                                              in.points, in.triangles, halfWidthFor(voxel, data.diagonal));
    benchmark::DoNotOptimize(grid.get());
  }
  state.counters["buildCpuS"] = double(std::clock() - cpuStart) / CLOCKS_PER_SEC / double(state.iterations());
  openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
      grid->getConstAccessor(), grid->transform());
  const auto [maxErr, p999] = measureError(
      data, [&](const Vec3& p) { return double(sampler.wsSample(openvdb::Vec3d(p.x(), p.y(), p.z()))); });
  state.SetLabel(name);
  state.counters["voxels"] = double(grid->activeVoxelCount());
  state.counters["MiB"] = double(grid->memUsage()) / (1 << 20);
  state.counters["maxErrRel"] = maxErr;
  state.counters["p999ErrRel"] = p999;
}
BENCHMARK(BM_OpenVdb_Build)->ArgsProduct({{0, 1}, {128, 512, 1024}})->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_OpenVdb_Sample(benchmark::State& state) {
  openvdb::initialize();
  const std::string name = kMeshes[state.range(0)];
  const openvdb::FloatGrid::Ptr grid = cachedVdb(name, state.range(1));
  const auto& points = meshData(name).queryPoints;
  openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
      grid->getConstAccessor(), grid->transform());
  std::size_t i = 0;
  double sum = 0.0;
  for (auto _ : state) {
    sum += sampler.wsSample(openvdb::Vec3d(points[i].x(), points[i].y(), points[i].z()));
    i = (i + 1) & (points.size() - 1);
  }
  benchmark::DoNotOptimize(sum);
  state.SetLabel(name);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_OpenVdb_Sample)->ArgsProduct({{0, 1}, {128, 512, 1024}});
#endif

}  // namespace

BENCHMARK_MAIN();
