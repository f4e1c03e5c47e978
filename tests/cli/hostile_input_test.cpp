// Hostile input to the tool: every case ends in one `clod: error [code]: message` line and a
// non-zero exit code, never a crash, a raw CLI11 message or a damaged file system.
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_runner.h"

namespace clod::test {
namespace {

namespace fs = std::filesystem;

class HostileInput : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clod_hostile_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // Expects exit `code` and stderr of one line "clod: error [name]: ..." mentioning `culprit`.
  static void expectError(const CliRun& run, int code, const std::string& name, const std::string& culprit) {
    EXPECT_EQ(run.exitCode, code) << run.err;
    EXPECT_EQ(run.err.rfind("clod: error [" + name + "]: ", 0), 0u) << run.err;
    EXPECT_NE(run.err.find(culprit), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "one line: " << run.err;
  }
  static std::string readAll(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  fs::path dir_;
};

TEST_F(HostileInput, DeeplyNestedGltfIsAParseErrorInEveryCommand) {
  const fs::path deep = dir_ / "deep.gltf";  // 400 kB: overflowed the importer's stack (exit 139)
  std::ofstream(deep) << R"({"asset": {"version": "2.0"}, "extras": )" << std::string(200000, '[')
                      << std::string(200000, ']') << "}";
  std::ofstream(dir_ / "scene.json") << R"({"steps": 1, "bodies": [{"mesh": "deep.gltf"}]})";
  expectError(runCli("inspect " + quoted(deep)), 1, "parse_error", "maxJsonDepth");
  expectError(runCli("bake " + quoted(deep) + " -o " + quoted(dir_ / "deep.clod")), 1, "parse_error", "maxJsonDepth");
  expectError(runCli("simulate " + quoted(dir_ / "scene.json") + " -o " + quoted(dir_ / "out")), 1, "parse_error",
              "maxJsonDepth");
  EXPECT_FALSE(fs::exists(dir_ / "deep.clod"));
}

// Memory limits: a bake past --max-memory-mb and a pile of bodies past the world's pair limit
// end in resource_limit naming the setting, and leave no output behind.
TEST_F(HostileInput, BakesAndWorldsPastTheirMemoryLimitsAreResourceLimitErrors) {
  const fs::path mesh = dir_ / "box.obj";
  std::ofstream(mesh) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  // 4 triangles x 1.5 kB fit in 1 MiB; the contact tree's ~190-byte nodes at 1e-5 do not.
  expectError(runCli("bake " + quoted(mesh) + " -o " + quoted(dir_ / "t.clod") + " --sdf-error 1e-5 --max-memory-mb 1"), 1,
              "resource_limit", "maxNodes");
  EXPECT_FALSE(fs::exists(dir_ / "t.clod"));
  // The loader's limits are flags of every command that reads a mesh file.
  expectError(runCli("inspect " + quoted(mesh) + " --max-triangles 3"), 1, "unsupported_mesh", "--max-triangles");
  expectError(runCli("bake " + quoted(mesh) + " -o " + quoted(dir_ / "t.clod") + " --max-vertices 3"), 1, "unsupported_mesh",
              "--max-vertices");
  EXPECT_EQ(runCli("inspect " + quoted(mesh) + " --max-triangles 4").exitCode, 0);
  std::ofstream scene(dir_ / "pile.json");
  scene << R"({"steps": 1, "max_pairs": 44, "bodies": [)";  // 10 spheres at one point: 45 pairs
  for (int i = 0; i < 10; ++i) scene << (i ? "," : "") << R"({"sphere": 0.1, "position": [0, 0, 5]})";
  scene << "]}";
  scene.close();
  expectError(runCli("simulate " + quoted(dir_ / "pile.json") + " -o " + quoted(dir_ / "out")), 1, "resource_limit",
              "WorldSettings::maxPairs");
  EXPECT_FALSE(fs::exists(dir_ / "out" / "trajectory.csv"));
}

// A pose that is not finite (or not a rotation) gave `colliding` with NaN contacts.
TEST_F(HostileInput, NonFinitePosesAreUsageErrors) {
  const std::string query = "query " + quoted(dir_ / "a.clod") + " " + quoted(dir_ / "b.clod");
  expectError(runCli(query + " --pose-a \"nan 0 0 1 0 0 0\""), 2, "invalid_argument", "--pose-a");
  expectError(runCli(query + " --pose-b \"0 0 0 inf 0 0 0\""), 2, "invalid_argument", "--pose-b");
  expectError(runCli(query + " --pose-b \"0 0 0 0 0 0 0\""), 2, "invalid_argument", "--pose-b");
}

TEST_F(HostileInput, NegativeOrTooLargeBudgetsAndDeadlinesAreUsageErrors) {
  // Usage is checked before any file is read, so the bake files need not exist.
  const std::string query = "query " + quoted(dir_ / "a.clod") + " " + quoted(dir_ / "b.clod");
  expectError(runCli(query + " --budget -1"), 2, "invalid_argument", "--budget '-1'");
  expectError(runCli(query + " --budget 18446744073709551616"), 2, "invalid_argument", "--budget '18446744073709551616'");
  expectError(runCli(query + " --budget 0"), 2, "invalid_argument", "--budget '0'");
  expectError(runCli(query + " --deadline-us -1"), 2, "invalid_argument", "--deadline-us '-1'");
  expectError(runCli(query + " --deadline-us nan"), 2, "invalid_argument", "--deadline-us 'nan'");
  const std::string simulate = "simulate " + quoted(dir_ / "missing.json") + " -o " + quoted(dir_ / "out");
  expectError(runCli(simulate + " --budget -1"), 2, "invalid_argument", "--budget '-1'");
  expectError(runCli(simulate + " --budget 18446744073709551616"), 2, "invalid_argument", "--budget");
  expectError(runCli(simulate + " --budget-us -1"), 2, "invalid_argument", "--budget-us '-1'");
}

TEST_F(HostileInput, UnknownFlagsAndMissingArgumentsAreUsageErrorsInTheCommonFormat) {
  const std::string mesh = quoted(fs::path(CLOD_TEST_DATA_DIR) / "good" / "box.obj");
  expectError(runCli("inspect " + mesh + " --no-such-flag"), 2, "invalid_argument", "--no-such-flag");
  expectError(runCli("inspect"), 2, "invalid_argument", "mesh is required");
  expectError(runCli("query " + quoted(dir_ / "a.clod")), 2, "invalid_argument", "b");
  expectError(runCli("query " + quoted(dir_ / "a.clod") + " " + quoted(dir_ / "b.clod") + " --budget"), 2,
              "invalid_argument", "--budget");
  expectError(runCli("no-such-command"), 2, "invalid_argument", "unknown command 'no-such-command'");
  expectError(runCli(""), 2, "invalid_argument", "subcommand is required");
  const CliRun help = runCli("query --help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("--deadline-us"), std::string::npos);
}

// Shapes of absurd size: a sphere of radius 1e300 was "every triangle of the mesh has zero area"
// (its areas overflowed), a box of half extent 1e200 a sphere-tree radius of infinity reported as
// a usage error. The size range is a fatal finding of the mesh (kMinMeshDiagonal), naming the body.
TEST_F(HostileInput, ShapesOfAbsurdSizeAreUnsupportedMeshesNamingTheirBody) {
  for (const char* shape : {R"("sphere": 1e300)", R"("box": [1e200, 1, 1])", R"("sphere": 1e-300)"}) {
    std::ofstream(dir_ / "huge.json") << R"({"steps": 1, "bodies": [{"name": "giant", )" << shape << "}]}";
    expectError(runCli("simulate " + quoted(dir_ / "huge.json") + " -o " + quoted(dir_ / "out")), 1, "unsupported_mesh",
                "body 0 'giant': bounding-box diagonal");
    EXPECT_FALSE(fs::exists(dir_ / "out" / "trajectory.csv")) << shape;
  }
}

TEST_F(HostileInput, BodyNamesAreQuotedInTheCsvFiles) {
  std::ofstream(dir_ / "scene.json") << R"({"steps": 2, "bodies": [
      {"name": "ground, \"flat\"", "box": [2, 2, 0.25], "static": true, "bake": {"depth": 1}},
      {"name": "box\nnew line", "box": [0.5, 0.5, 0.5], "position": [0, 0, 0.74], "bake": {"depth": 1}}]})";
  const CliRun run = runCli("simulate " + quoted(dir_ / "scene.json") + " -o " + quoted(dir_ / "out") +
                            " --contact-model exact");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const std::string trajectory = readAll(dir_ / "out" / "trajectory.csv");
  EXPECT_NE(trajectory.find("\n0,0,\"ground, \"\"flat\"\"\",0,"), std::string::npos) << trajectory;
  EXPECT_NE(trajectory.find("\n0,0,\"box\nnew line\",0,"), std::string::npos) << trajectory;
  const std::string contacts = readAll(dir_ / "out" / "contacts.csv");
  EXPECT_NE(contacts.find(",\"box\nnew line\","), std::string::npos) << contacts;
  EXPECT_NE(contacts.find(",\"ground, \"\"flat\"\"\","), std::string::npos) << contacts;
}

TEST_F(HostileInput, AnOutputThatIsADeviceIsLeftAlone) {
  // `clod bake -o /dev/full` as root replaced the device with a regular file. A private copy of
  // the device (root only; a named pipe otherwise) keeps a regression from damaging /dev.
  fs::path target = dir_ / "full";
  const bool device = ::mknod(target.c_str(), S_IFCHR | 0666, makedev(1, 7)) == 0;
  if (!device) {
    ASSERT_EQ(::mkfifo(target.c_str(), 0600), 0);
  }
  const std::string mesh = quoted(fs::path(CLOD_TEST_DATA_DIR) / "good" / "box.obj");
  expectError(runCli("bake " + mesh + " -o " + quoted(target) + " --sphere-tree octree --levels 1 --no-sdf"), 1, "file_write_failed",
              "refusing to replace '" + target.string() + "'");
  EXPECT_TRUE(device ? fs::is_character_file(target) : fs::is_fifo(target));
}

}  // namespace
}  // namespace clod::test
