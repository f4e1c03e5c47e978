// The C++ side of bench/python_overhead.py: the same batched work as the Python calls
// mesh.closest(points) and clod.query_batch(bake, pose, bake, poses), written as a C++ user of the
// library would (TBB over the items, one QueryScratch per thread, results kept in memory), so the
// Python script can report the bindings' overhead. Built on request only:
//   cmake --build build --target clod_python_overhead
// Usage (the script passes these): clod_python_overhead BAKE POINTS.f64 POSES.f64 MODEL BUDGET REPS
//   POINTS.f64: K x 3 float64, POSES.f64: P x 7 float64 (tx ty tz qw qx qy qz of body B; A at the
//   identity), raw little-endian. Prints one JSON object: the per-repetition wall seconds of each.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/proximity.h"
#include "clod/query.h"

namespace {

std::vector<double> readDoubles(const char* path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) {
    std::fprintf(stderr, "cannot read %s\n", path);
    std::exit(2);
  }
  const auto bytes = static_cast<std::size_t>(in.tellg());
  std::vector<double> values(bytes / sizeof(double));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(double)));
  return values;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void printList(const char* name, const std::vector<double>& values, bool last) {
  std::printf("\"%s\": [", name);
  for (std::size_t i = 0; i < values.size(); ++i) std::printf("%s%.9g", i ? ", " : "", values[i]);
  std::printf("]%s", last ? "" : ", ");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s BAKE POINTS.f64 POSES.f64 MODEL BUDGET REPS\n", argv[0]);
    return 2;
  }
  const clod::BakeContents contents = clod::loadBake(argv[1]);
  const std::vector<double> pointData = readDoubles(argv[2]);
  const std::vector<double> poseData = readDoubles(argv[3]);
  const int reps = std::atoi(argv[6]);

  // Closest points: MeshDistance built once (Python builds it on the warm-up call too).
  const clod::MeshDistance distance(contents.mesh);
  std::vector<clod::Vec3> points(pointData.size() / 3);
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = {pointData[3 * i], pointData[3 * i + 1], pointData[3 * i + 2]};
  std::vector<clod::MeshDistance::Signed> closest(points.size());
  std::vector<double> closestSeconds;
  for (int r = 0; r <= reps; ++r) {  // r = 0: warm-up, not reported
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 64), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i) closest[i] = distance.signedQuery(points[i]);
    });
    if (r > 0) closestSeconds.push_back(secondsSince(start));
  }

  // Queries: body A at the identity, body B at each pose.
  const clod::CollisionBody body = clod::CollisionBody::fromBake(contents);
  std::vector<clod::Pose> poses(poseData.size() / 7);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const double* v = &poseData[7 * i];
    poses[i].translation = {v[0], v[1], v[2]};
    poses[i].rotation = clod::Quat(v[3], v[4], v[5], v[6]).normalized();
  }
  clod::QuerySettings settings;
  settings.model = clod::parseContactModel(argv[4]);
  const long long budget = std::atoll(argv[5]);
  if (budget > 0) settings.budget = clod::QueryBudget::tests(static_cast<std::uint64_t>(budget));
  std::vector<double> querySeconds;
  std::size_t contacts = 0;
  for (int r = 0; r <= reps; ++r) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<clod::QueryResult> results(poses.size());
    tbb::enumerable_thread_specific<clod::QueryScratch> scratch;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, poses.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
      clod::QueryScratch& local = scratch.local();
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        clod::queryContacts(body, clod::Pose{}, body, poses[i], settings, local, results[i]);
    });
    if (r > 0) querySeconds.push_back(secondsSince(start));
    contacts = 0;
    for (const clod::QueryResult& q : results) contacts += q.contacts.size();
  }
  std::printf("{");
  printList("closest_seconds", closestSeconds, false);
  printList("query_seconds", querySeconds, false);
  std::printf("\"contacts\": %zu}\n", contacts);
  return 0;
}
