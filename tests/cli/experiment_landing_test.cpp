// `clod experiment landing`: the JSON contract, the time series and plots written with -o, bad usage.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace {

namespace fs = std::filesystem;
using clod::test::quoted;
using clod::test::runCli;

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ExperimentLandingCli, ReportsBothScenariosForDosCfmAndExactAndWritesTimeSeries) {
  const fs::path dir = fs::temp_directory_path() / ("clod_experiment_landing_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  // One random drop per body and --quick (1 s drops): the contract does not depend on the counts.
  const clod::test::CliRun run = runCli("experiment landing --trials 1 --quick --json --mesh-dir " +
                                        quoted(CLOD_SHARED_MESH_DIR) + " -o " + quoted(dir));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json doc = nlohmann::json::parse(run.out);
  EXPECT_EQ(doc["experiment"], "landing");
  ASSERT_EQ(doc["scenarios"].size(), 2u);
  EXPECT_EQ(doc["scenarios"][0]["scenario"], "bunny");
  EXPECT_EQ(doc["scenarios"][1]["scenario"], "root");
  EXPECT_EQ(doc["scenarios"][1]["level"], 0);
  for (const auto& sc : doc["scenarios"]) {
    ASSERT_EQ(sc["models"].size(), 3u);
    EXPECT_EQ(sc["models"][0]["model"], "dos");
    EXPECT_EQ(sc["models"][1]["model"], "cfm");
    EXPECT_EQ(sc["models"][2]["model"], "exact");
    for (const auto& m : sc["models"]) {
      for (const auto& b : m["bodies"]) {
        for (const char* key : {"final_tilt_deg", "final_turned_deg", "final_slide_rel", "orientation_error_deg",
                                "position_error_rel", "final_angular_speed"}) {
          ASSERT_TRUE(b.contains(key)) << key;
          EXPECT_GE(b[key].get<double>(), 0.0) << key;
        }
        EXPECT_LE(b["final_tilt_deg"].get<double>(), 180.0);
      }
      // Exact is its own reference: no error against itself.
      if (m["model"] == "exact") {
        for (const auto& b : m["bodies"]) {
          EXPECT_EQ(b["orientation_error_deg"].get<double>(), 0.0);
          EXPECT_EQ(b["position_error_rel"].get<double>(), 0.0);
        }
      }
    }
  }
  // The randomised drops: every (body, model, level) row, statistics over the one start.
  const auto& drops = doc["drops"];
  EXPECT_EQ(drops["trials"], 1);
  EXPECT_EQ(drops["duration"], 1.0);
  const std::vector<int> levels = drops["levels"].get<std::vector<int>>();
  ASSERT_EQ(drops["rows"].size(), 2u * (1u + 2u * levels.size()));  // bodies x (exact + dos, cfm per level)
  std::set<std::string> seen;
  for (const auto& row : drops["rows"]) {
    const std::string model = row["model"];
    seen.insert(row["body"].get<std::string>() + "/" + model + "/" + (row["level"].is_null() ? "-" : std::to_string(row["level"].get<int>())));
    EXPECT_EQ(row["level"].is_null(), model == "exact");
    EXPECT_EQ(row["trials"], 1);
    for (const char* key : {"final_tilt_deg", "tilt_error_deg", "orientation_error_deg", "position_error_rel",
                            "normal_tilt_deg", "max_normal_tilt_deg", "contact_steps"}) {
      ASSERT_TRUE(row.contains(key)) << key;
      for (const char* stat : {"mean", "sd", "min", "max"}) ASSERT_TRUE(row[key].contains(stat)) << key << " " << stat;
      EXPECT_GE(row[key]["mean"].get<double>(), 0.0) << key;
      EXPECT_EQ(row[key]["sd"].get<double>(), 0.0) << key;  // one start: no spread
    }
    // A normal's angle from the vertical lies in [0, 90] degrees.
    EXPECT_LE(row["max_normal_tilt_deg"]["max"].get<double>(), 90.0);
    // Every body lands within the second (it starts at most 10 cm above the box).
    EXPECT_GT(row["contact_steps"]["mean"].get<double>(), 0.0) << row.dump();
    if (model == "exact") {
      EXPECT_EQ(row["orientation_error_deg"]["mean"].get<double>(), 0.0);
    }
  }
  EXPECT_EQ(seen.size(), drops["rows"].size());
  const std::string series = readFile(dir / "landing_bunny.csv");
  EXPECT_EQ(series.rfind("time,tilt_deg bunny dos", 0), 0u);
  EXPECT_GT(std::count(series.begin(), series.end(), '\n'), 100);  // 2 s at 60 Hz + header
  for (const char* f : {"landing.json", "landing.csv", "landing_root.csv", "landing_bunny_tilt.png",
                        "landing_bunny_slide.png", "landing_root_turned.png", "landing_drops.csv",
                        "landing_drop_cube.csv", "landing_drop_bunny.csv", "landing_drop_cube_tilt.png",
                        "landing_drop_cube_normal.png", "landing_drop_bunny_tilt.png", "landing_drop_bunny_normal.png"}) {
    ASSERT_TRUE(fs::exists(dir / f)) << f;
    EXPECT_GT(fs::file_size(dir / f), 0u) << f;
  }
  fs::remove_all(dir);
}

TEST(ExperimentLandingCli, BadArgumentsExitWithTwoAndMissingMeshesWithOne) {
  EXPECT_EQ(runCli("experiment landing --seed x").exitCode, 2);
  EXPECT_EQ(runCli("experiment landing --bogus").exitCode, 2);
  EXPECT_EQ(runCli("experiment landing --trials 101").exitCode, 2);
  const clod::test::CliRun run = runCli("experiment landing --mesh-dir /nonexistent/clod-meshes");
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("bunny-1500"), std::string::npos) << run.err;
}

}  // namespace
