// `clod query` as external checks use it: run the built CLI on bakes of boxes written here as
// OBJ text, parse its JSON, check the analytic answers, the budget and the exit codes.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_runner.h"
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

using clod::test::CliRun;
using clod::test::runCli;

// A cube of half extent 1 as OBJ text (8 vertices, 12 counter-clockwise triangles), baked once.
class QueryCli : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("clod_query_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream obj(dir_ / "cube.obj");
    obj << "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n"
           "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\n"
           "f 2 4 8\nf 2 8 6\n";
    obj.close();
    const CliRun bake = runCli("bake \"" + (dir_ / "cube.obj").string() + "\" -o \"" + cube().string() + "\" --levels 2");
    ASSERT_EQ(bake.exitCode, 0) << bake.err;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path cube() { return dir_ / "cube.clod"; }
  static std::string pair() { return "query \"" + cube().string() + "\" \"" + cube().string() + "\" "; }
  static fs::path dir_;
};
fs::path QueryCli::dir_;

double angleToUp(const nlohmann::json& normal) {
  const double x = normal[0], y = normal[1], z = normal[2];
  return std::atan2(std::hypot(x, y), z);
}

constexpr double kTwoDegrees = 2.0 * 3.14159265358979323846 / 180.0;

TEST_F(QueryCli, ExactBoxRestingOnBoxGivesTheFaceNormalAndTheDepth) {
  // A rests on B, 0.01 deep, offset sideways by (0.3, 0.2).
  const CliRun run = runCli(pair() + "--pose-a \"0.3 0.2 1.99 1 0 0 0\" --model exact --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j.at("colliding").get<bool>());
  EXPECT_TRUE(j.at("finished").get<bool>());
  EXPECT_GT(j.at("tests").get<std::uint64_t>(), 0u);
  EXPECT_GE(j.at("seconds").get<double>(), 0.0);
  const auto& contacts = j.at("contacts");
  ASSERT_GE(contacts.size(), 3u);
  EXPECT_LE(contacts.size(), 8u);
  for (const auto& c : contacts) {
    EXPECT_LT(angleToUp(c.at("normal")), kTwoDegrees) << c.dump();
    // Exact: the overlap's height, measured along N, which the thin side strips tilt by about
    // depth/width = 0.006 rad: 0.01 cos(tilt) is off by 0.01 tilt^2 / 2 ~ 2e-7.
    EXPECT_NEAR(c.at("depth").get<double>(), 0.01, 1e-6) << c.dump();
    EXPECT_NEAR(c.at("point")[2].get<double>(), 0.995, 0.005 + 1e-9);
    EXPECT_TRUE(c.contains("level"));
  }
}

// A pose's quaternion is a direction: any finite, nonzero magnitude is the rotation it points
// to. (1e200, 1e200, 0, 0) overflowed the norm and was refused as "not finite or a zero rotation
// quaternion"; (1e-13, 0, 0, 0) was refused as zero. Oracle: the same query with the quaternion
// written at unit scale. The scaled decimals round differently, so the rotations agree to a few
// ulps, and every number within 1e-9 (the cube's diagonal is 3.5; the answers move by ~1e-15).
TEST_F(QueryCli, QuaternionsOfAnyFiniteNonzeroMagnitudeAreTheirRotation) {
  auto contacts = [](const std::string& quaternion) {
    const CliRun run = runCli(pair() + "--pose-a \"0.3 0.2 1.99 " + quaternion + "\" --model exact --json");
    EXPECT_EQ(run.exitCode, 0) << quaternion << ": " << run.err;
    return run.exitCode == 0 ? nlohmann::json::parse(run.out).at("contacts") : nlohmann::json::array();
  };
  // The same contacts, in any order (the manifold's order among equal depths may follow an ulp).
  auto expectSame = [](const nlohmann::json& got, const nlohmann::json& want, const std::string& what) {
    ASSERT_EQ(got.size(), want.size()) << what;
    auto same = [](const nlohmann::json& a, const nlohmann::json& b) {
      bool close = std::abs(a.at("depth").get<double>() - b.at("depth").get<double>()) <= 1e-9;
      for (int k = 0; k < 3; ++k) {
        close = close && std::abs(a.at("point")[k].get<double>() - b.at("point")[k].get<double>()) <= 1e-9;
        close = close && std::abs(a.at("normal")[k].get<double>() - b.at("normal")[k].get<double>()) <= 1e-9;
      }
      return close;
    };
    for (const auto& w : want)
      EXPECT_TRUE(std::any_of(got.begin(), got.end(), [&](const nlohmann::json& g) { return same(g, w); }))
          << what << ": no contact like " << w.dump();
  };
  const nlohmann::json turned = contacts("0.9 0.1 0 0");
  ASSERT_FALSE(turned.empty());
  expectSame(contacts("0.9e200 0.1e200 0 0"), turned, "1e200");
  expectSame(contacts("0.9e-200 0.1e-200 0 0"), turned, "1e-200");
  expectSame(contacts("1e-13 0 0 0"), contacts("1 0 0 0"), "1e-13");
}

TEST_F(QueryCli, BudgetIsRespectedAndSeparatedBodiesDoNotCollide) {
  for (const char* model : {"dos", "average", "cfm", "exact"}) {
    const CliRun run = runCli(pair() + "--pose-a \"0.3 0.2 1.99 1 0 0 0\" --budget 5 --model " + model + " --json");
    ASSERT_EQ(run.exitCode, 0) << model << run.err;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    EXPECT_LE(j.at("tests").get<std::uint64_t>(), 5u) << model;
    EXPECT_TRUE(j.at("colliding").get<bool>()) << model;
  }
  // 0.5 apart (a quarter of the width): the sphere models' leaf spheres may still overlap, the
  // exact model must say no.
  const CliRun far = runCli(pair() + "--pose-a \"0 0 2.5 0.7071067811865476 0.7071067811865476 0 0\" --model exact --json");
  ASSERT_EQ(far.exitCode, 0) << far.err;
  const nlohmann::json j = nlohmann::json::parse(far.out);
  EXPECT_FALSE(j.at("colliding").get<bool>());
  EXPECT_TRUE(j.at("contacts").empty());
  EXPECT_TRUE(j.at("finished").get<bool>());
  // A deadline already reached: at most one batch of 32 tests.
  const CliRun late = runCli(pair() + "--pose-a \"0.3 0.2 1.5 1 0 0 0\" --model exact --deadline-us 0 --json");
  ASSERT_EQ(late.exitCode, 0) << late.err;
  EXPECT_LE(nlohmann::json::parse(late.out).at("tests").get<std::uint64_t>(), 32u);
}

TEST_F(QueryCli, BadInputGivesClearMessagesAndExitCodes) {
  CliRun run = runCli(pair() + "--model fancy");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("fancy"), std::string::npos) << run.err;
  run = runCli(pair() + "--pose-a \"1 2 3\"");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("--pose-a"), std::string::npos) << run.err;
  run = runCli(pair() + "--budget 0");
  EXPECT_EQ(run.exitCode, 2);
  run = runCli(pair() + "--max-contacts 0");
  EXPECT_EQ(run.exitCode, 2);
  run = runCli("query \"" + (dir_ / "missing.clod").string() + "\" \"" + cube().string() + "\"");
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("missing.clod"), std::string::npos) << run.err;
  // No contact tree in this bake (baked with --no-sdf): bad data naming the option.
  const fs::path plain = dir_ / "cube-no-sdf.clod";
  ASSERT_EQ(runCli("bake \"" + (dir_ / "cube.obj").string() + "\" -o \"" + plain.string() + "\" --levels 2 --no-sdf").exitCode, 0);
  run = runCli("query \"" + plain.string() + "\" \"" + plain.string() + "\" --model contact-tree");
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("contact tree"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("clod bake"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--no-sdf"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out.empty());
}

}  // namespace
