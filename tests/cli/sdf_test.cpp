// `clod sdf` and the contact-tree keys of `clod bake --json`, as external checks use them: run
// the built CLI on a box written here as OBJ text, and check the field against the box's
// analytic signed distance (an oracle independent of the library).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli_runner.h"
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

using clod::test::CliRun;
using clod::test::runCli;

using clod::test::quoted;

// The box: centre and half extents, off the origin and not a cube.
constexpr std::array<double, 3> kCenter{0.5, -1.25, 2.0};
constexpr std::array<double, 3> kHalf{1.0, 0.5, 0.25};

// Analytic signed distance of the box (negative inside).
double boxDistance(const std::array<double, 3>& p) {
  double outside = 0.0, inside = -1e300;
  for (int k = 0; k < 3; ++k) {
    const double q = std::abs(p[k] - kCenter[k]) - kHalf[k];
    outside += std::max(q, 0.0) * std::max(q, 0.0);
    inside = std::max(inside, q);
  }
  return std::sqrt(outside) + std::min(inside, 0.0);
}

double boxDiagonal() { return 2.0 * std::sqrt(kHalf[0] * kHalf[0] + kHalf[1] * kHalf[1] + kHalf[2] * kHalf[2]); }

class SdfCli : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("clod_sdf_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream obj(dir_ / "box.obj");
    for (int v = 0; v < 8; ++v) {
      obj << "v " << kCenter[0] + ((v & 1) ? kHalf[0] : -kHalf[0]) << " " << kCenter[1] + ((v & 2) ? kHalf[1] : -kHalf[1])
          << " " << kCenter[2] + ((v & 4) ? kHalf[2] : -kHalf[2]) << "\n";
    }
    // Counter-clockwise seen from outside (vertex v has bit 0 = +x, bit 1 = +y, bit 2 = +z).
    obj << "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\n"
           "f 2 4 8\nf 2 8 6\n";
    obj.close();
    const CliRun run = runCli("bake " + quoted(dir_ / "box.obj") + " -o " + quoted(bake()) +
                              " --levels 1 --sdf-error 1e-3 --sdf-depth 9 --json");
    ASSERT_EQ(run.exitCode, 0) << run.err;
    bakeJson_ = nlohmann::json::parse(run.out);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path bake() { return dir_ / "box.clod"; }
  static fs::path writePoints(const std::string& name, const std::vector<std::array<double, 3>>& points) {
    std::ofstream out(dir_ / name);
    out.precision(17);
    for (const auto& p : points) out << p[0] << " " << p[1] << " " << p[2] << "\n";
    return dir_ / name;
  }
  static fs::path dir_;
  static nlohmann::json bakeJson_;
};
fs::path SdfCli::dir_;
nlohmann::json SdfCli::bakeJson_;

TEST_F(SdfCli, BakeJsonReportsTheContactTreeAndItsSection) {
  const nlohmann::json& j = bakeJson_;
  for (const char* key : {"sdf_cells", "sdf_leaves", "sdf_bytes", "sdf_seconds"}) ASSERT_TRUE(j.contains(key)) << key;
  const auto cells = j["sdf_cells"].get<std::uint64_t>();
  const auto leaves = j["sdf_leaves"].get<std::uint64_t>();
  // An octree: the root plus eight children per interior node, so 1 + 8k cells and 1 + 7k leaves.
  ASSERT_GT(cells, 1u) << "a box's edges must refine";
  EXPECT_EQ((cells - 1) % 8, 0u);
  EXPECT_EQ(leaves, 1 + 7 * ((cells - 1) / 8));
  EXPECT_GE(j["sdf_seconds"].get<double>(), 0.0);
  EXPECT_EQ(j["sdf_depth"], 9);
  EXPECT_LE(j["sdf_depth_reached"].get<int>(), 9);
  bool found = false;
  for (const auto& s : j["sections"]) {
    if (s["tag"] == "CTRE") {
      found = true;
      EXPECT_EQ(s["version"], 1);
      EXPECT_EQ(s["bytes"], j["sdf_bytes"]);
    }
  }
  EXPECT_TRUE(found) << j["sections"].dump();
  EXPECT_EQ(j["file_bytes"].get<std::uintmax_t>(), fs::file_size(bake()));
}

// Points in the band around the box (where the error target holds), far outside, deep inside,
// and off the root cube, in a known order. Every answer must be within its own error bound of
// the analytic distance (+ f32 storage rounding of the corner values: 2^-24 relative of values
// below the root size, covered by 1e-6 of the diagonal); answers come back in input order.
TEST_F(SdfCli, DistancesMatchTheAnalyticBoxWithinTheirErrorBounds) {
  std::vector<std::array<double, 3>> points;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double band = 0.01 * boxDiagonal();
  while (points.size() < 300) {
    std::array<double, 3> p;
    for (int k = 0; k < 3; ++k) p[k] = kCenter[k] + unit(rng) * (kHalf[k] + band);
    if (std::abs(boxDistance(p)) <= band) points.push_back(p);
  }
  points.push_back(kCenter);                                                // deep inside
  points.push_back({kCenter[0] + 1.01, kCenter[1], kCenter[2]});            // just off the +x face
  points.push_back({kCenter[0] + 50.0, kCenter[1] + 3.0, kCenter[2]});      // far outside the root cube
  const fs::path file = writePoints("points.txt", points);

  const CliRun run = runCli("sdf " + quoted(bake()) + " --points " + quoted(file) + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json answers = nlohmann::json::parse(run.out);
  ASSERT_TRUE(answers.is_array());
  ASSERT_EQ(answers.size(), points.size());
  const double rounding = 1e-6 * boxDiagonal();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const nlohmann::json& a = answers[i];
    for (const char* key : {"distance", "gradient", "error_bound", "depth"}) ASSERT_TRUE(a.contains(key)) << key;
    ASSERT_EQ(a["gradient"].size(), 3u);
    const double exact = boxDistance(points[i]);
    EXPECT_LE(std::abs(a["distance"].get<double>() - exact), a["error_bound"].get<double>() + rounding)
        << "point " << i << ": " << a.dump();
    EXPECT_LE(a["depth"].get<int>(), 9);
  }
  // In the band the stopping leaves meet the requested error (1e-3 of the diagonal) where the
  // field is smooth: just off the middle of the +x face, the field is planar and the gradient
  // is the face normal (trilinear interpolation reproduces a linear field exactly).
  const nlohmann::json& face = answers[points.size() - 2];
  EXPECT_NEAR(face["distance"].get<double>(), 0.01, 1e-3 * boxDiagonal());
  EXPECT_NEAR(face["gradient"][0].get<double>(), 1.0, 1e-3);
  EXPECT_NEAR(face["gradient"][1].get<double>(), 0.0, 1e-3);
  EXPECT_NEAR(face["gradient"][2].get<double>(), 0.0, 1e-3);
  EXPECT_EQ(answers[points.size() - 1]["inside_root"], false);
  EXPECT_LT(answers[points.size() - 3]["distance"].get<double>(), 0.0) << "the centre is inside";
}

TEST_F(SdfCli, DepthLimitStopsHigherWithBoundsThatStillHold) {
  const std::vector<std::array<double, 3>> points = {
      {kCenter[0] + 1.0, kCenter[1] + 0.5, kCenter[2]}, {kCenter[0], kCenter[1], kCenter[2] + 0.3}, kCenter};
  const fs::path file = writePoints("few.txt", points);
  for (int depth : {0, 1, 3}) {
    const CliRun run = runCli("sdf " + quoted(bake()) + " --points " + quoted(file) + " --depth " + std::to_string(depth) + " --json");
    ASSERT_EQ(run.exitCode, 0) << run.err;
    const nlohmann::json answers = nlohmann::json::parse(run.out);
    ASSERT_EQ(answers.size(), points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      EXPECT_LE(answers[i]["depth"].get<int>(), depth);
      EXPECT_LE(std::abs(answers[i]["distance"].get<double>() - boxDistance(points[i])),
                answers[i]["error_bound"].get<double>() + 1e-6 * boxDiagonal())
          << "depth " << depth << ", point " << i;
    }
    if (depth == 0) {
      for (const auto& a : answers) EXPECT_EQ(a["depth"], 0);
    }
  }
}

TEST_F(SdfCli, BadDepthIsUsageErrorAndPrintsNothing) {
  const fs::path file = writePoints("one.txt", {kCenter});
  for (const char* depth : {"-1", "10", "99", "abc"}) {  // the tree was built with --sdf-depth 9
    const CliRun run = runCli("sdf " + quoted(bake()) + " --points " + quoted(file) + " --depth " + depth + " --json");
    EXPECT_EQ(run.exitCode, 2) << depth << ": " << run.err;
    EXPECT_TRUE(run.out.empty()) << depth;
  }
  EXPECT_EQ(runCli("sdf " + quoted(bake()) + " --json").exitCode, 2) << "--points is required";
}

TEST_F(SdfCli, BakeWithoutTheTreeIsDataErrorNamingTheOption) {
  const fs::path plain = dir_ / "plain.clod";
  const CliRun baked = runCli("bake " + quoted(dir_ / "box.obj") + " -o " + quoted(plain) + " --levels 1 --no-sdf --json");
  ASSERT_EQ(baked.exitCode, 0) << baked.err;
  const nlohmann::json j = nlohmann::json::parse(baked.out);
  EXPECT_EQ(j["sdf_cells"], 0);
  EXPECT_EQ(j["sdf_leaves"], 0);
  EXPECT_EQ(j["sdf_bytes"], 0);
  EXPECT_TRUE(j["sdf_seconds"].is_null());
  for (const auto& s : j["sections"]) EXPECT_NE(s["tag"], "CTRE");

  const fs::path file = writePoints("one.txt", {kCenter});
  const CliRun run = runCli("sdf " + quoted(plain) + " --points " + quoted(file) + " --json");
  EXPECT_EQ(run.exitCode, 1) << run.err;
  EXPECT_NE(run.err.find("--no-sdf"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("CTRE"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out.empty());
}

TEST_F(SdfCli, BadPointsAndBadBakesAreDataErrors) {
  std::ofstream(dir_ / "bad.txt") << "1 2\n";
  std::ofstream(dir_ / "nan.txt") << "nan 0 0\n";
  for (const char* name : {"bad.txt", "nan.txt", "absent.txt"}) {
    const CliRun run = runCli("sdf " + quoted(bake()) + " --points " + quoted(dir_ / name) + " --json");
    EXPECT_EQ(run.exitCode, 1) << name << ": " << run.err;
    EXPECT_TRUE(run.out.empty()) << name;
  }
  std::ofstream(dir_ / "text.clod") << "not a bake\n";
  const fs::path file = writePoints("one.txt", {kCenter});
  const CliRun run = runCli("sdf " + quoted(dir_ / "text.clod") + " --points " + quoted(file) + " --json");
  EXPECT_EQ(run.exitCode, 1) << run.err;
}

TEST_F(SdfCli, BadSdfOptionsAreUsageErrorsAndWriteNothing) {
  const fs::path out = dir_ / "never.clod";
  for (const char* extra : {" --sdf-error 0", " --sdf-error -1e-3", " --sdf-error nan", " --sdf-error x",
                            " --sdf-depth 0", " --sdf-depth 21"}) {
    const CliRun run = runCli("bake " + quoted(dir_ / "box.obj") + " -o " + quoted(out) + extra + " --json");
    EXPECT_EQ(run.exitCode, 2) << extra << ": " << run.err;
    EXPECT_TRUE(run.out.empty()) << extra;
    EXPECT_FALSE(fs::exists(out)) << extra;
  }
}

}  // namespace
