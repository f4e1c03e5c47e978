// Closest-point query throughput and build time of clod::MeshDistance, side by side with the
// peers people use today: CGAL's AABB_tree and Embree's rtcPointQuery. The peers are compiled
// in only when bench/proximity.cmake finds them (CLOD_BENCH_HAVE_CGAL / CLOD_BENCH_HAVE_EMBREE).
//
// Point sets (per mesh, fixed seeds): "box" = uniform in the bounding box grown by 10% of the
// diagonal on every side; "near" = random surface points moved by up to 0.5% of the diagonal
// in a random direction. Every benchmark answers the same points; the counter `maxErrRel`
// reports the largest |distance - clod distance| / diagonal, so exactness is visible too.
//
// Run: build-prox/bin/bench_proximity --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "proximity/triangle_bvh.h"

#ifdef CLOD_BENCH_HAVE_CGAL
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#endif
#ifdef CLOD_BENCH_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using clod::Vec3;

constexpr int kPointCount = 20000;

struct Scenario {
  clod::TriangleMesh mesh;
  double diagonal = 0.0;
  std::vector<Vec3> boxPoints, nearPoints;
  std::vector<double> boxReference, nearReference;  // clod distances, for maxErrRel
  std::unique_ptr<clod::MeshDistance> distance;
};

Scenario& scenario(const std::string& file) {
  static std::map<std::string, Scenario> cache;
  Scenario& s = cache[file];
  if (s.distance) return s;
  s.mesh = clod::loadMesh(std::filesystem::path(CLOD_SHARED_MESH_DIR) / file).mesh;
  const clod::Aabb box = s.mesh.bounds();
  s.diagonal = box.diagonal();
  std::mt19937_64 rng(2024);
  for (int i = 0; i < kPointCount; ++i) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      p[k] = std::uniform_real_distribution<double>(box.min[k] - 0.1 * s.diagonal, box.max[k] + 0.1 * s.diagonal)(rng);
    }
    s.boxPoints.push_back(p);
  }
  std::uniform_int_distribution<std::uint32_t> pick(0, s.mesh.triangleCount() - 1);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> gauss;
  for (int i = 0; i < kPointCount; ++i) {
    const std::uint32_t t = pick(rng);
    double r1 = unit(rng), r2 = unit(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Vec3 onSurface = s.mesh.corner(t, 0) + r1 * (s.mesh.corner(t, 1) - s.mesh.corner(t, 0)) +
                           r2 * (s.mesh.corner(t, 2) - s.mesh.corner(t, 0));
    s.nearPoints.push_back(onSurface + 0.005 * unit(rng) * s.diagonal *
                                           Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized());
  }
  s.distance = std::make_unique<clod::MeshDistance>(s.mesh);
  for (const Vec3& p : s.boxPoints) s.boxReference.push_back(s.distance->closestPoint(p).distance);
  for (const Vec3& p : s.nearPoints) s.nearReference.push_back(s.distance->closestPoint(p).distance);
  return s;
}

const char* kMeshes[] = {"stanford-bunny.obj", "fandisk.obj"};

std::string shortName(const std::string& file) { return file.substr(0, file.find('.')); }

// Runs `query(i) -> distance` over a point set, single-threaded or with tbb::parallel_for.
template <class Query>
void runQueries(benchmark::State& state, const Scenario& s, bool near, bool threaded, Query&& query) {
  const auto& points = near ? s.nearPoints : s.boxPoints;
  const auto& reference = near ? s.nearReference : s.boxReference;
  std::vector<double> result(points.size());
  for (auto _ : state) {
    if (threaded) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) result[i] = query(points[i]);
      });
    } else {
      for (std::size_t i = 0; i < points.size(); ++i) result[i] = query(points[i]);
    }
    benchmark::DoNotOptimize(result.data());
    benchmark::ClobberMemory();
  }
  double maxErr = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) maxErr = std::max(maxErr, std::abs(result[i] - reference[i]));
  state.counters["maxErrRel"] = maxErr / s.diagonal;
  state.SetItemsProcessed(state.iterations() * std::int64_t(points.size()));
}

// Single-thread runs are timed in CPU time (the machines they were measured on are shared and
// busy, so wall time mostly measures the neighbours); multi-threaded runs and builds (which use
// threads in clod and Embree) in wall time.
void configure(benchmark::internal::Benchmark* bench, bool threaded) {
  bench->Unit(benchmark::kMillisecond);
  if (threaded) bench->UseRealTime();
}

// ---- clod -------------------------------------------------------------------------------

void registerClod() {
  for (const char* file : kMeshes) {
    for (bool near : {false, true}) {
      for (bool threaded : {false, true}) {
        const std::string name = std::string("BM_ClosestPoint_Clod/") + shortName(file) + (near ? "/near" : "/box") +
                                 (threaded ? "/all_threads" : "/1_thread");
        auto* bench = benchmark::RegisterBenchmark(name.c_str(), [file, near, threaded](benchmark::State& state) {
          const Scenario& s = scenario(file);
          runQueries(state, s, near, threaded, [&](const Vec3& p) { return s.distance->closestPoint(p).distance; });
        });
        configure(bench, threaded);
      }
    }
    benchmark::RegisterBenchmark((std::string("BM_Build_Clod/") + shortName(file) + "/bvh").c_str(),
                                 [file](benchmark::State& state) {
                                   const Scenario& s = scenario(file);
                                   std::vector<clod::Aabb> boxes(s.mesh.triangleCount());
                                   for (std::uint32_t t = 0; t < s.mesh.triangleCount(); ++t) {
                                     for (int k = 0; k < 3; ++k) boxes[t].extend(s.mesh.corner(t, k));
                                   }
                                   for (auto _ : state) {
                                     clod::detail::TriangleBvh bvh(boxes, {});
                                     benchmark::DoNotOptimize(bvh.nodes().data());
                                   }
                                 })->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark((std::string("BM_Build_Clod/") + shortName(file) + "/mesh_distance").c_str(),
                                 [file](benchmark::State& state) {
                                   const Scenario& s = scenario(file);
                                   for (auto _ : state) {
                                     clod::MeshDistance md(s.mesh);
                                     benchmark::DoNotOptimize(&md);
                                   }
                                 })->Unit(benchmark::kMillisecond)->UseRealTime();
  }
}

// ---- CGAL -------------------------------------------------------------------------------

#ifdef CLOD_BENCH_HAVE_CGAL
using CgalKernel = CGAL::Simple_cartesian<double>;
using CgalTriangle = CgalKernel::Triangle_3;
using CgalIterator = std::vector<CgalTriangle>::const_iterator;
using CgalPrimitive = CGAL::AABB_triangle_primitive<CgalKernel, CgalIterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<CgalKernel, CgalPrimitive>>;

std::vector<CgalTriangle> cgalTriangles(const clod::TriangleMesh& m) {
  std::vector<CgalTriangle> out;
  for (std::uint32_t t = 0; t < m.triangleCount(); ++t) {
    auto pt = [&](int k) { return CgalKernel::Point_3(m.corner(t, k).x(), m.corner(t, k).y(), m.corner(t, k).z()); };
    out.emplace_back(pt(0), pt(1), pt(2));
  }
  return out;
}

void registerCgal() {
  for (const char* file : kMeshes) {
    for (bool near : {false, true}) {
      for (bool threaded : {false, true}) {
        const std::string name = std::string("BM_ClosestPoint_Cgal/") + shortName(file) + (near ? "/near" : "/box") +
                                 (threaded ? "/all_threads" : "/1_thread");
        auto* bench = benchmark::RegisterBenchmark(name.c_str(), [file, near, threaded](benchmark::State& state) {
          const Scenario& s = scenario(file);
          const std::vector<CgalTriangle> triangles = cgalTriangles(s.mesh);
          CgalTree tree(triangles.begin(), triangles.end());
          tree.accelerate_distance_queries();
          runQueries(state, s, near, threaded, [&](const Vec3& p) {
            const CgalKernel::Point_3 q(p.x(), p.y(), p.z());
            return std::sqrt(CGAL::to_double(CGAL::squared_distance(q, tree.closest_point(q))));
          });
        });
        configure(bench, threaded);
      }
    }
    benchmark::RegisterBenchmark((std::string("BM_Build_Cgal/") + shortName(file) + "/aabb_tree").c_str(),
                                 [file](benchmark::State& state) {
                                   const Scenario& s = scenario(file);
                                   const std::vector<CgalTriangle> triangles = cgalTriangles(s.mesh);
                                   for (auto _ : state) {
                                     CgalTree tree(triangles.begin(), triangles.end());
                                     tree.accelerate_distance_queries();  // part of a usable distance tree
                                     benchmark::DoNotOptimize(&tree);
                                   }
                                 })->Unit(benchmark::kMillisecond)->UseRealTime();
  }
}
#endif

// ---- Embree -----------------------------------------------------------------------------

#ifdef CLOD_BENCH_HAVE_EMBREE
// The point-query callback computes the exact double-precision closest point on the original
// triangle (the same routine clod uses), so Embree is measured as a BVH for exact queries.
struct EmbreeQueryData {
  const clod::TriangleMesh* mesh;
  double bestSquared;
};

bool embreeClosestCallback(RTCPointQueryFunctionArguments* args) {
  auto* data = static_cast<EmbreeQueryData*>(args->userPtr);
  const clod::TriangleMesh& m = *data->mesh;
  const std::uint32_t t = args->primID;
  const Vec3 p(args->query->x, args->query->y, args->query->z);
  const clod::TrianglePoint tp = clod::closestPointOnTriangle(p, m.corner(t, 0), m.corner(t, 1), m.corner(t, 2));
  if (tp.distanceSquared < data->bestSquared) {
    data->bestSquared = tp.distanceSquared;
    args->query->radius = static_cast<float>(std::sqrt(tp.distanceSquared));
    return true;  // radius shrank: Embree re-culls with it
  }
  return false;
}

struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  explicit EmbreeScene(const clod::TriangleMesh& m) {
    device = rtcNewDevice(nullptr);
    scene = rtcNewScene(device);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.vertexCount()));
    for (std::uint32_t v = 0; v < m.vertexCount(); ++v) {
      for (int k = 0; k < 3; ++k) vertices[3 * v + k] = static_cast<float>(m.vertices[v][k]);
    }
    auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), m.triangleCount()));
    for (std::uint32_t t = 0; t < m.triangleCount(); ++t) {
      for (int k = 0; k < 3; ++k) indices[3 * t + k] = m.triangles[t][k];
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
};

void registerEmbree() {
  for (const char* file : kMeshes) {
    for (bool near : {false, true}) {
      for (bool threaded : {false, true}) {
        const std::string name = std::string("BM_ClosestPoint_Embree/") + shortName(file) + (near ? "/near" : "/box") +
                                 (threaded ? "/all_threads" : "/1_thread");
        auto* bench = benchmark::RegisterBenchmark(name.c_str(), [file, near, threaded](benchmark::State& state) {
          const Scenario& s = scenario(file);
          const EmbreeScene embree(s.mesh);
          runQueries(state, s, near, threaded, [&](const Vec3& p) {
            RTCPointQuery query;
            query.x = static_cast<float>(p.x());
            query.y = static_cast<float>(p.y());
            query.z = static_cast<float>(p.z());
            query.radius = std::numeric_limits<float>::infinity();
            query.time = 0.0f;
            RTCPointQueryContext context;
            rtcInitPointQueryContext(&context);
            EmbreeQueryData data{&s.mesh, std::numeric_limits<double>::infinity()};
            rtcPointQuery(embree.scene, &query, &context, embreeClosestCallback, &data);
            return std::sqrt(data.bestSquared);
          });
        });
        configure(bench, threaded);
      }
    }
    benchmark::RegisterBenchmark((std::string("BM_Build_Embree/") + shortName(file) + "/scene").c_str(),
                                 [file](benchmark::State& state) {
                                   const Scenario& s = scenario(file);
                                   for (auto _ : state) {
                                     EmbreeScene embree(s.mesh);
                                     benchmark::DoNotOptimize(embree.scene);
                                   }
                                 })->Unit(benchmark::kMillisecond)->UseRealTime();
  }
}
#endif

}  // namespace

int main(int argc, char** argv) {
  registerClod();
#ifdef CLOD_BENCH_HAVE_CGAL
  registerCgal();
#endif
#ifdef CLOD_BENCH_HAVE_EMBREE
  registerEmbree();
#endif
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
