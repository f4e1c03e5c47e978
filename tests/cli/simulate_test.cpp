// clod simulate end to end: output files, exit codes.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

int run(const std::string& args) {
  const int status = std::system((std::string(CLOD_CLI_PATH) + " " + args + " > /dev/null 2>&1").c_str());
  return WEXITSTATUS(status);
}

std::string readAll(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SimulateCli, BoxOnBoxWritesTrajectoryContactsAndSummary) {
  const auto dir = std::filesystem::temp_directory_path() / "clod_simulate_cli_test";
  std::filesystem::remove_all(dir);
  const std::string scene = std::string(CLOD_TEST_DATA_DIR) + "/../../scenes/box_on_box.json";
  ASSERT_EQ(run("simulate " + scene + " -o " + dir.string()), 0);
  const std::string traj = readAll(dir / "trajectory.csv");
  EXPECT_EQ(traj.rfind("step,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n", 0), 0u);
  EXPECT_EQ(readAll(dir / "contacts.csv").rfind("step,body_a,body_b,px,py,pz,nx,ny,nz,depth,level\n", 0), 0u);
  const auto summary = nlohmann::json::parse(readAll(dir / "summary.json"));
  ASSERT_EQ(summary["bodies"].size(), 2u);
  EXPECT_EQ(summary["bodies"][1]["name"], "box");
  // Box (half 0.5) on the slab (top z = 0.25) at rest: centre between 0.75 and 1.75 (sphere
  // models may rest on their spheres), velocity under 1 cm/s.
  const double z = summary["bodies"][1]["position"][2];
  EXPECT_GT(z, 0.7);
  EXPECT_LT(z, 1.75);
  EXPECT_EQ(summary["energy"].size(), summary["steps"].get<std::size_t>());
  // 1 + 180 steps of 2 bodies + header.
  EXPECT_EQ(std::count(traj.begin(), traj.end(), '\n'), 1 + 181 * 2);
  // Second run: shapes from the cache.
  ASSERT_EQ(run("simulate " + scene + " -o " + dir.string() + " --budget 32 --contact-model exact"), 0);
  const auto again = nlohmann::json::parse(readAll(dir / "summary.json"));
  EXPECT_EQ(again["shapes_baked"], 0);
  EXPECT_EQ(again["contact_model"], "exact");
  std::filesystem::remove_all(dir);
}

TEST(SimulateCli, BadSceneExitsOneAndBadUsageTwo) {
  const auto dir = std::filesystem::temp_directory_path() / "clod_simulate_cli_bad";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.json") << R"({"bodies": [{"box": [1, "a", 1]}]})";
  EXPECT_EQ(run("simulate " + (dir / "bad.json").string() + " -o " + (dir / "out").string()), 1);
  EXPECT_EQ(run("simulate " + (dir / "missing.json").string() + " -o " + (dir / "out").string()), 1);
  EXPECT_EQ(run("simulate " + (dir / "bad.json").string()), 2);  // no -o
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "summary.json"));
  std::filesystem::remove_all(dir);
}

}  // namespace
