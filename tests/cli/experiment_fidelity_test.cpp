// `clod experiment fidelity`: the JSON contract, the files written with -o, bad usage.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "support/test_scale.h"

namespace {

namespace fs = std::filesystem;
using clod::test::quoted;
using clod::test::runCli;

fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clod_experiment_fidelity_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Two trials keep the test short (one under the sanitizers); the contract does not depend on it.
int trials() { return clod::test::sanitizerRun() ? 1 : 2; }
const std::string kArgs = "experiment fidelity --trials " + std::to_string(trials()) + " --mesh-dir " + quoted(CLOD_SHARED_MESH_DIR);

TEST(ExperimentFidelityCli, WritesEveryShapeModelLevelRowWithProbabilitiesAndFiles) {
  const fs::path dir = scratchDir("out");
  const clod::test::CliRun run = runCli(kArgs + " --json -o " + quoted(dir / "o"));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json doc = nlohmann::json::parse(run.out);
  EXPECT_EQ(doc["experiment"], "fidelity");
  EXPECT_EQ(doc["settings"]["trials"], trials());
  ASSERT_EQ(doc["rows"].size(), 2u * 4u * 4u);  // shapes x models x levels
  std::set<std::string> seen;
  for (const auto& row : doc["rows"]) {
    seen.insert(row["shape"].get<std::string>() + "/" + row["model"].get<std::string>() + "/" +
                std::to_string(row["level"].get<int>()));
    EXPECT_EQ(row["trials"], trials());
    for (const char* key : {"angular_moving", "angular_resting", "linear_velocity", "angular_velocity", "gap", "overall"}) {
      const double p = row["probabilities"][key].get<double>();
      EXPECT_GE(p, 0.0) << key;
      EXPECT_LE(p, 1.0) << key;
      EXPECT_GE(row["std_dev"][key].get<double>(), 0.0) << key;
      EXPECT_GE(row["ci95"][key].get<double>(), 0.0) << key;
    }
    // The overall probability is the product of components each <= 1.
    EXPECT_LE(row["probabilities"]["overall"].get<double>(), row["probabilities"]["gap"].get<double>() + 1e-12);
    EXPECT_TRUE(row["mean_distortion"].contains("gap_rel"));
  }
  EXPECT_EQ(seen.size(), 32u);
  for (const char* m : {"dos", "average", "cfm", "contact-tree"}) {
    EXPECT_TRUE(seen.count(std::string("cube/") + m + "/0")) << m;
    EXPECT_TRUE(seen.count(std::string("bunny-1500/") + m + "/3")) << m;
  }
  ASSERT_EQ(doc["shapes"].size(), 2u);
  EXPECT_TRUE(doc["paper"].contains("claims"));

  const fs::path out = dir / "o";
  EXPECT_EQ(nlohmann::json::parse(readFile(out / "fidelity.json")), doc);
  const std::string csv = readFile(out / "fidelity.csv");
  EXPECT_EQ(csv.rfind("shape,model,level,trials,p_angular_moving", 0), 0u);
  for (const char* f : {"fidelity_cube.csv", "fidelity_bunny-1500.csv", "fidelity_cube_overall.png",
                        "fidelity_bunny-1500_overall.png", "fidelity_cube_angular_moving.png", "fidelity_cube_overall.gp"}) {
    ASSERT_TRUE(fs::exists(out / f)) << f;
    EXPECT_GT(fs::file_size(out / f), 0u) << f;
  }
  fs::remove_all(dir);
}

TEST(ExperimentFidelityCli, BadArgumentsExitWithTwo) {
  EXPECT_EQ(runCli("experiment fidelity --trials -3").exitCode, 2);
  EXPECT_EQ(runCli("experiment fidelity --trials many").exitCode, 2);
  EXPECT_EQ(runCli("experiment fidelity --no-such-flag").exitCode, 2);
}

TEST(ExperimentFidelityCli, MissingMeshDirectoryIsADataError) {
  const clod::test::CliRun run = runCli("experiment fidelity --trials 1 --mesh-dir /nonexistent/clod-meshes");
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("bunny-1500"), std::string::npos) << run.err;
}

}  // namespace
