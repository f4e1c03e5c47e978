// `clod experiment retrieval`: the JSON contract external checks rely on, the files written with
// -o, bad usage. Timings themselves are not asserted (they are measurements, not results); only
// that they are positive and finite, and the structure, which follows from the sphere-tree and
// the sampling schemes (independent of the timing code).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace {

namespace fs = std::filesystem;
using clod::test::quoted;
using clod::test::runCli;

// One timed batch per row: the contract is the same, and the CLI test must stay quick.
const std::string kArgs = std::string("experiment retrieval --trials 1 --mesh-dir ") + quoted(CLOD_SHARED_MESH_DIR);

fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clod_experiment_retrieval_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool positiveFinite(const nlohmann::json& v) { return v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() > 0.0; }

TEST(ExperimentRetrievalCli, JsonHasEveryMethodAtEveryLevelAndWritesCsvAndPlotWithOutput) {
  const fs::path dir = scratchDir("json");
  const clod::test::CliRun run = runCli(kArgs + " --json -o " + quoted(dir / "out"));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto doc = nlohmann::json::parse(run.out);
  for (const char* key : {"mesh", "triangles", "spheres", "levels", "batches", "queries", "lookups", "nearest", "ratios", "paper"}) {
    ASSERT_TRUE(doc.contains(key)) << key;
  }
  EXPECT_EQ(doc["mesh"], "spot.obj");
  EXPECT_EQ(doc["batches"], 1);
  const int levels = doc["levels"];
  ASSERT_GE(levels, 2);
  // Every baseline once per level; cfm once per (5 schemes x {10, 16} stacks) per level.
  std::map<std::string, int> perMethod;
  std::set<std::pair<std::string, int>> cfmConfigs;
  for (const auto& row : doc["lookups"]) {
    for (const char* key : {"method", "scheme", "stacks", "level", "spheres", "samples", "ns_median", "ns_min", "ns_max",
                            "cpu_ns_median", "lookups_per_batch"}) {
      ASSERT_TRUE(row.contains(key)) << key;
    }
    EXPECT_TRUE(positiveFinite(row["ns_median"])) << row.dump();
    EXPECT_LE(row["ns_min"].get<double>(), row["ns_median"].get<double>());
    EXPECT_LE(row["ns_median"].get<double>(), row["ns_max"].get<double>());
    const std::string method = row["method"];
    ++perMethod[method];
    if (method == "cfm") {
      cfmConfigs.insert({row["scheme"].get<std::string>(), row["stacks"].get<int>()});
      EXPECT_GE(row["samples"].get<int>(), 1);
    } else {
      EXPECT_TRUE(row["scheme"].is_null());
    }
  }
  for (const char* m : {"dos", "average", "exact-closest-point", "closest-among-sphere-triangles"}) EXPECT_EQ(perMethod[m], levels) << m;
  EXPECT_EQ(perMethod["cfm"], 10 * levels);
  EXPECT_EQ(cfmConfigs.size(), 10u);
  // Root of the adaptive-polar 10-stack map: the paper's 65 samples (Table 1).
  for (const auto& row : doc["lookups"]) {
    if (row["method"] == "cfm" && row["scheme"] == "adaptive-polar" && row["stacks"] == 10 && row["level"] == 0) {
      EXPECT_EQ(row["samples"], 65);
    }
  }
  // Nearest-sample methods: the quadrant search only for geodesic, the paper's formula only for
  // the ring schemes.
  for (const auto& row : doc["nearest"]) {
    const std::string scheme = row["scheme"], method = row["method"];
    EXPECT_TRUE(positiveFinite(row["ns_median"])) << row.dump();
    if (method == "quadrant-search") {
      EXPECT_EQ(scheme, "geodesic");
    }
    if (method == "paper-formula") {
      EXPECT_TRUE(scheme == "polar" || scheme == "adaptive-polar" || scheme == "healpix") << scheme;
    }
  }
  EXPECT_EQ(doc["paper"]["geodesic_quadrant_speedup"], 4.0);
  for (const char* key : {"cfm_over_dos_root", "exact_over_cfm_root", "geodesic_linear_over_quadrant_10"}) {
    EXPECT_TRUE(positiveFinite(doc["ratios"][key])) << key;
  }
  for (const char* file : {"retrieval.json", "retrieval.csv", "retrieval_levels.csv", "retrieval_nearest.csv", "retrieval_levels.png",
                           "retrieval_levels.gp"}) {
    ASSERT_TRUE(fs::exists(dir / "out" / file)) << file;
    EXPECT_GT(fs::file_size(dir / "out" / file), 0u) << file;
  }
  std::ifstream csv(dir / "out" / "retrieval.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("method,scheme,stacks,level,", 0), 0u);
  fs::remove_all(dir);
}

TEST(ExperimentRetrievalCli, BadArgumentsExitWithTwo) {
  clod::test::CliRun run = runCli("experiment retrieval --trials 5000");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("--trials"), std::string::npos);
  run = runCli("experiment retrieval --trials -1");
  EXPECT_EQ(run.exitCode, 2);
  run = runCli("experiment retrieval --trials many");
  EXPECT_EQ(run.exitCode, 2);
}

TEST(ExperimentRetrievalCli, MissingMeshDirectoryIsADataError) {
  const clod::test::CliRun run = runCli("experiment retrieval --trials 1 --mesh-dir /nonexistent/clod-meshes");
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("spot.obj"), std::string::npos) << run.err;
}

}  // namespace
