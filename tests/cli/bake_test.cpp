// `clod bake` and `clod spheres` as external checks use them: run the built CLI, parse its
// JSON, check exit codes and that failures leave no files. Expected counts come from the shared
// meshes' README; sphere positions are checked against the OBJ's own vertices.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
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
fs::path sharedMesh(const char* name) { return fs::path(CLOD_SHARED_MESH_DIR) / name; }

// The vertices of an OBJ file ('v x y z' lines), read here independently of the library.
std::vector<std::array<double, 3>> objVertices(const fs::path& path) {
  std::vector<std::array<double, 3>> vertices;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 2 || line[0] != 'v' || line[1] != ' ') continue;
    std::istringstream fields(line.substr(2));
    std::array<double, 3> v{};
    fields >> v[0] >> v[1] >> v[2];
    vertices.push_back(v);
  }
  return vertices;
}

class CliBake : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clod_cli_bake_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::size_t filesInDir() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}));
  }
  fs::path dir_;
};

TEST_F(CliBake, JsonHasTheContractKeysAndSpheresMatchTheLevelCounts) {
  const fs::path mesh = sharedMesh("bunny-1500.obj");
  const fs::path out = dir_ / "bunny.clod";
  const CliRun run = runCli("bake " + quoted(mesh) + " -o " + quoted(out) + " --sphere-tree octree --levels 3 --sdf-error 1e-2 --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  for (const char* key : {"levels", "build_seconds", "file_bytes", "mesh_hash", "vertices", "triangles", "sign_method",
                          "method", "branching"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  // README: 782 vertices, 1,499 triangles, open (71 boundary edges) -> winding-number signs.
  EXPECT_EQ(j["vertices"], 782);
  EXPECT_EQ(j["triangles"], 1499);
  EXPECT_EQ(j["sign_method"], "winding_number");
  EXPECT_EQ(j["method"], "octree");
  EXPECT_EQ(j["branching"], 8);
  EXPECT_EQ(j["file_bytes"].get<std::uintmax_t>(), fs::file_size(out));
  EXPECT_GE(j["build_seconds"].get<double>(), 0.0);
  ASSERT_TRUE(j["levels"].is_array());
  ASSERT_EQ(j["levels"].size(), 4u) << "--levels 3 means 3 levels below the root";
  EXPECT_EQ(j["levels"][0]["spheres"], 1);
  EXPECT_EQ(filesInDir(), 1u) << "only the bake file, no temporary left behind";

  // The contact tree is built by default: its keys, octree counts (1 + 8k cells, 1 + 7k leaves)
  // and the size of its 'CTRE' section as listed in the file's own table.
  for (const char* key : {"sdf_cells", "sdf_leaves", "sdf_bytes", "sdf_seconds"}) ASSERT_TRUE(j.contains(key)) << key;
  const auto sdfCells = j["sdf_cells"].get<std::uint64_t>();
  ASSERT_GT(sdfCells, 1u);
  EXPECT_EQ((sdfCells - 1) % 8, 0u);
  EXPECT_EQ(j["sdf_leaves"].get<std::uint64_t>(), 1 + 7 * ((sdfCells - 1) / 8));
  EXPECT_GE(j["sdf_seconds"].get<double>(), 0.0);
  bool ctre = false;
  for (const auto& section : j["sections"]) {
    if (section["tag"] == "CTRE") ctre = section["bytes"] == j["sdf_bytes"];
  }
  EXPECT_TRUE(ctre) << j["sections"].dump();

  // Sphere coverage, checked against the OBJ's own vertices: every vertex lies in a sphere of
  // every level. Tolerance: the loader may weld vertices within 1e-7 of the bbox diagonal and
  // the builder pads radii by 1e-9; 1e-6 of the diagonal covers both with margin.
  const auto vertices = objVertices(mesh);
  ASSERT_EQ(vertices.size(), 782u);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const auto& v : vertices)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  const double diagonal = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  for (std::size_t level = 0; level < j["levels"].size(); ++level) {
    const nlohmann::json& entry = j["levels"][level];
    for (const char* key : {"spheres", "fit_mean", "fit_max"}) ASSERT_TRUE(entry.contains(key)) << key;
    EXPECT_LE(entry["fit_mean"].get<double>(), entry["fit_max"].get<double>());
    const CliRun spheres = runCli("spheres " + quoted(out) + " --level " + std::to_string(level) + " --json");
    ASSERT_EQ(spheres.exitCode, 0) << spheres.err;
    const nlohmann::json list = nlohmann::json::parse(spheres.out);
    ASSERT_TRUE(list.is_array());
    ASSERT_EQ(list.size(), entry["spheres"].get<std::size_t>()) << "level " << level;
    for (const auto& v : vertices) {
      bool covered = false;
      for (const auto& s : list) {
        const auto& c = s["center"];
        const double d = std::hypot(v[0] - c[0].get<double>(), v[1] - c[1].get<double>(), v[2] - c[2].get<double>());
        if (d <= s["radius"].get<double>() + 1e-6 * diagonal) {
          covered = true;
          break;
        }
      }
      ASSERT_TRUE(covered) << "vertex (" << v[0] << ", " << v[1] << ", " << v[2] << ") outside level " << level;
    }
  }
}

TEST_F(CliBake, MedialBakeWithoutJsonPrintsASummary) {
  const fs::path out = dir_ / "suzanne.clod";
  const CliRun run = runCli("bake " + quoted(sharedMesh("suzanne.obj")) + " -o " + quoted(out) +
                            " --sphere-tree medial --branching 4 --levels 2 --medial-samples 1000 --no-sdf");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("suzanne.clod"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("level 2"), std::string::npos) << run.out;
  EXPECT_TRUE(fs::exists(out));
}

TEST_F(CliBake, OutOfRangeLevelIsUsageErrorNamingTheValidRange) {
  const fs::path out = dir_ / "box.clod";
  ASSERT_EQ(runCli("bake " + quoted(sharedMesh("bunny-1500.obj")) + " -o " + quoted(out) +
                   " --sphere-tree octree --levels 2 --no-sdf --json")
                .exitCode,
            0);
  for (const char* level : {"3", "-1", "4000000000"}) {
    const CliRun run = runCli("spheres " + quoted(out) + " --level " + level + " --json");
    EXPECT_EQ(run.exitCode, 2) << level << ": " << run.err;
    EXPECT_NE(run.err.find("0..2"), std::string::npos) << level << ": " << run.err;
    EXPECT_TRUE(run.out.empty());
  }
}

TEST_F(CliBake, DamagedOrMissingBakeFilesAreDataErrors) {
  const fs::path good = dir_ / "good.clod";
  ASSERT_EQ(runCli("bake " + quoted(sharedMesh("bunny-1500.obj")) + " -o " + quoted(good) + " --sphere-tree octree --levels 2 --no-sdf")
                .exitCode,
            0);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  auto writeFile = [&](const char* name, const std::string& content) {
    std::ofstream(dir_ / name, std::ios::binary) << content;
    return dir_ / name;
  };
  std::string flipped = bytes;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x40);
  const fs::path cases[] = {writeFile("flipped.clod", flipped), writeFile("cut.clod", bytes.substr(0, bytes.size() - 100)),
                            writeFile("text.clod", "not a bake file\n"), writeFile("empty.clod", ""), dir_ / "absent.clod"};
  for (const fs::path& path : cases) {
    const CliRun run = runCli("spheres " + quoted(path) + " --level 0 --json");
    EXPECT_EQ(run.exitCode, 1) << path << ": " << run.err;
    EXPECT_FALSE(run.err.empty()) << path;
    EXPECT_TRUE(run.out.empty()) << path;
  }
}

TEST_F(CliBake, UnwritableOutputIsDataErrorAndLeavesNoFile) {
  // A regular file where the output directory should be: no user (root included) can create
  // anything under it, unlike a chmod'ed directory.
  std::ofstream(dir_ / "blocker") << "x";
  const fs::path out = dir_ / "blocker" / "bunny.clod";
  const CliRun run = runCli("bake " + quoted(sharedMesh("bunny-1500.obj")) + " -o " + quoted(out) +
                            " --sphere-tree octree --levels 1 --no-sdf --json");
  EXPECT_EQ(run.exitCode, 1) << run.err;
  EXPECT_NE(run.err.find("bunny.clod"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out.empty());
  EXPECT_EQ(filesInDir(), 1u) << "only the blocker file";
}

TEST_F(CliBake, FailedBakeLeavesAnExistingOutputUntouched) {
  const fs::path out = dir_ / "keep.clod";
  std::ofstream(out) << "previous content";
  std::ofstream(dir_ / "bad.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 9\n";
  const CliRun run = runCli("bake " + quoted(dir_ / "bad.obj") + " -o " + quoted(out) + " --json");
  EXPECT_EQ(run.exitCode, 1) << run.err;
  std::ifstream in(out);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()), "previous content");
  EXPECT_EQ(filesInDir(), 2u) << "no temporary file left behind";
}

TEST_F(CliBake, BadOptionsAreUsageErrorsAndWriteNothing) {
  const fs::path out = dir_ / "x.clod";
  const std::string base = "bake " + quoted(sharedMesh("bunny-1500.obj")) + " -o " + quoted(out);
  for (const std::string& extra : {std::string(" --sphere-tree voxels"), std::string(" --branching 1"),
                                   std::string(" --levels 99"), std::string(" --branching many")}) {
    const CliRun run = runCli(base + extra + " --json");
    EXPECT_EQ(run.exitCode, 2) << extra << ": " << run.err;
    EXPECT_FALSE(fs::exists(out)) << extra;
  }
  EXPECT_EQ(runCli("bake " + quoted(sharedMesh("bunny-1500.obj"))).exitCode, 2) << "-o is required";
  EXPECT_EQ(filesInDir(), 0u);
}

TEST_F(CliBake, MissingMeshIsDataError) {
  const fs::path out = dir_ / "x.clod";
  const CliRun run = runCli("bake " + quoted(dir_ / "absent.obj") + " -o " + quoted(out));
  EXPECT_EQ(run.exitCode, 1) << run.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
