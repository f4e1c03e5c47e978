// `clod inspect` as external checks use it: run the built CLI, parse its JSON, check exit codes.
// Expected values come from the shared meshes' README and from the box test file's geometry.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_runner.h"

namespace {

using clod::test::CliRun;
using clod::test::runCli;

std::string quoted(const std::string& path) { return "\"" + path + "\""; }
std::string sharedMesh(const char* name) { return quoted(std::string(CLOD_SHARED_MESH_DIR) + "/" + name); }
std::string testFile(const char* name) { return quoted(std::string(CLOD_TEST_DATA_DIR) + "/" + name); }

TEST(CliInspect, JsonOfSuzanneHasTheContractKeysAndReadmeCounts) {
  const CliRun run = runCli("inspect " + sharedMesh("suzanne.obj") + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  for (const char* key : {"vertices", "triangles", "closed", "boundary_edges", "nonmanifold_edges",
                          "degenerate_triangles", "components", "bbox_min", "bbox_max", "volume", "warnings"})
    EXPECT_TRUE(j.contains(key)) << key;
  // README: 505 distinct vertices, 968 triangles, 42 boundary edges, 1 non-manifold edge.
  EXPECT_EQ(j["vertices"], 505);
  EXPECT_EQ(j["triangles"], 968);
  EXPECT_EQ(j["boundary_edges"], 42);
  EXPECT_EQ(j["nonmanifold_edges"], 1);
  EXPECT_EQ(j["closed"], false);
  EXPECT_TRUE(j["volume"].is_null());
  EXPECT_TRUE(j["warnings"].is_array());
  EXPECT_FALSE(j["warnings"].empty());
  EXPECT_EQ(j["bbox_min"].size(), 3u);
  EXPECT_EQ(j["bbox_max"].size(), 3u);
}

TEST(CliInspect, JsonOfTheBoxHasExactVolumeAndInertia) {
  // box.obj is [0,1] x [0,2] x [0,3]: volume 6, centre (0.5, 1, 1.5),
  // inertia (density 1) = m/12 * (b^2 + c^2, a^2 + c^2, a^2 + b^2) with m = 6.
  const CliRun run = runCli("inspect " + testFile("good/box.obj") + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["vertices"], 8);
  EXPECT_EQ(j["triangles"], 12);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["degenerate_triangles"], 0);
  EXPECT_NEAR(j["volume"].get<double>(), 6.0, 1e-12);
  const double expectedCom[3] = {0.5, 1.0, 1.5};
  const double expectedInertia[3] = {0.5 * (4 + 9), 0.5 * (1 + 9), 0.5 * (1 + 4)};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j["center_of_mass"][i].get<double>(), expectedCom[i], 1e-12);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(j["inertia"][i][k].get<double>(), i == k ? expectedInertia[i] : 0.0, 1e-12);
  }
  EXPECT_EQ(j["bbox_max"], nlohmann::json::array({1.0, 2.0, 3.0}));
  EXPECT_TRUE(j["warnings"].empty());
}

TEST(CliInspect, InsideOutBoxIsReportedFlipped) {
  const CliRun run = runCli("inspect " + testFile("good/box_inside_out.obj") + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["flipped"], true);
  EXPECT_NEAR(j["volume"].get<double>(), 6.0, 1e-12);
}

TEST(CliInspect, ClosedSharedMeshHasAPositiveVolume) {
  const CliRun run = runCli("inspect " + sharedMesh("spot.obj") + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["boundary_edges"], 0);
  ASSERT_TRUE(j["volume"].is_number());
  EXPECT_GT(j["volume"].get<double>(), 0.0);
}

TEST(CliInspect, TextReportMentionsTheCounts) {
  const CliRun run = runCli("inspect " + testFile("good/box.off"));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("triangles 12"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("closed"), std::string::npos) << run.out;
}

TEST(CliInspect, BadDataExitsOneWithAMessageAndNoOutput) {
  for (const char* name : {"bad/nan_vertex.obj", "bad/empty.obj", "bad/garbage.xyz", "bad/index_out_of_range.off",
                           "bad/missing_file.obj", "bad"}) {
    SCOPED_TRACE(name);
    const CliRun run = runCli("inspect " + testFile(name) + " --json");
    EXPECT_EQ(run.exitCode, 1);
    EXPECT_TRUE(run.out.empty()) << run.out;
    EXPECT_NE(run.err.find("error"), std::string::npos) << run.err;
    const std::string base = std::filesystem::path(name).filename().string();
    EXPECT_NE(run.err.find(base), std::string::npos) << run.err;
  }
  const CliRun nan = runCli("inspect " + testFile("bad/nan_vertex.obj"));
  EXPECT_NE(nan.err.find("non_finite_vertex"), std::string::npos) << nan.err;
}

TEST(CliInspect, BadUsageExitsTwo) {
  EXPECT_EQ(runCli("inspect").exitCode, 2);
  EXPECT_EQ(runCli("inspect " + testFile("good/box.obj") + " --no-such-option").exitCode, 2);
  EXPECT_EQ(runCli("inspect " + testFile("good/box.obj") + " --weld-tolerance abc").exitCode, 2);
  EXPECT_EQ(runCli("inspect " + testFile("good/box.obj") + " --weld-tolerance nan").exitCode, 2);
}

}  // namespace
