// `clod closest` end to end: the built CLI against an independent brute-force oracle, and its
// error contract (exit codes, empty stdout, messages naming the culprit).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "clod/mesh_io.h"
#include "clod/mesh_topology.h"
#include "proximity/oracle.h"

namespace {

namespace fs = std::filesystem;
using clod::Vec3;

struct CliRun {
  int exitCode;
  std::string out, err;
};

class ClosestCli : public ::testing::Test {
protected:
  fs::path dir_ = fs::temp_directory_path() /
                  ("clod_closest_cli_" + std::to_string(::getpid()) + "_" +
                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& content) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }
  static std::string slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  CliRun run(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command =
        quoted(CLOD_CLI_PATH) + " closest " + args + " > " + quoted(out.string()) + " 2> " + quoted(err.string());
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
  }
  // Shell-quoted path of a shared mesh. Strings are built by appending: GCC 12 -O3 warns
  // (-Wrestrict, a known false positive) about "literal" + std::string temporaries.
  static std::string mesh(const std::string& name) { return quoted(std::string(CLOD_SHARED_MESH_DIR) + "/" + name); }
  static std::string quoted(const std::string& text) {
    std::string out = "'";
    out += text;
    out += '\'';
    return out;
  }
};

TEST_F(ClosestCli, JsonMatchesBruteForceOnAClosedMesh) {
  const clod::TriangleMesh m = clod::loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/spot.obj").mesh;
  const clod::MeshTopology topology(m);
  const clod::Aabb box = m.bounds();
  std::mt19937_64 rng(21);
  std::ostringstream text;
  text.precision(17);
  std::vector<Vec3> points;
  for (int i = 0; i < 200; ++i) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      p[k] = std::uniform_real_distribution<double>(box.min[k] - 0.1 * box.diagonal(), box.max[k] + 0.1 * box.diagonal())(rng);
    }
    points.push_back(p);
    text << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  }
  const CliRun r = run(mesh("spot.obj") + " --points " + quoted(write("points.txt", text.str()).string()) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  ASSERT_TRUE(out.is_array());
  ASSERT_EQ(out.size(), points.size());
  const oracle::BruteForce bruteForce(m);
  // Same tolerance argument as the library tests; JSON carries doubles round-trip exactly.
  const double tol = 1e-9 * box.diagonal();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const nlohmann::json& o = out[i];
    for (const char* key : {"distance", "signed_distance", "point", "feature", "normal", "sign_method"}) {
      ASSERT_TRUE(o.contains(key)) << "point " << i << " lacks " << key;
    }
    EXPECT_EQ(o["sign_method"], "pseudonormal");
    const double d = o["distance"];
    const auto ref = bruteForce.closest(points[i]);
    ASSERT_NEAR(d, ref.hit.distance, tol) << "point " << i;
    const Vec3 q(o["point"][0], o["point"][1], o["point"][2]);
    ASSERT_NEAR((q - points[i]).norm(), d, tol);
    const Vec3 n(o["normal"][0], o["normal"][1], o["normal"][2]);
    ASSERT_NEAR(n.norm(), 1.0, 1e-12);
    const std::string type = o["feature"]["type"];
    const std::uint32_t index = o["feature"]["index"];
    ASSERT_TRUE(type == "vertex" || type == "edge" || type == "face") << type;
    if (type == "vertex") {
      ASSERT_LT(index, m.vertexCount());
      ASSERT_NEAR((m.vertices[index] - q).norm(), 0.0, tol);
    } else if (type == "edge") {
      ASSERT_LT(index, topology.edgeCount());
      const clod::Edge e = topology.edges()[index];
      ASSERT_NEAR(oracle::closestOnSegment(q, m.vertices[e.v0], m.vertices[e.v1], 0).distance, 0.0, tol);
    } else {
      ASSERT_LT(index, m.triangleCount());
      ASSERT_NEAR(oracle::closestOnTriangle(q, m.corner(index, 0), m.corner(index, 1), m.corner(index, 2)).distance,
                  0.0, tol);
    }
    const double signedDistance = o["signed_distance"];
    ASSERT_EQ(std::abs(signedDistance), d);
    if (d > 1e-6 * box.diagonal()) {
      std::mt19937_64 rayRng(i);
      const int inside = oracle::insideByRayParity(m, points[i], rayRng);
      if (inside >= 0) {
        ASSERT_EQ(signedDistance < 0, inside == 1) << "point " << i;
      }
    }
  }
}

TEST_F(ClosestCli, OpenMeshReportsWindingNumberSigns) {
  const CliRun r = run(mesh("bunny-1500.obj") + " --points " + quoted(write("p.txt", "0 0 0\n1 1 1\n").string()) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  ASSERT_EQ(out.size(), 2u);
  for (const auto& o : out) EXPECT_EQ(o["sign_method"], "winding_number");
}

TEST_F(ClosestCli, EmptyPointListGivesAnEmptyArray) {
  const CliRun r = run(mesh("spot.obj") + " --points " + quoted(write("p.txt", "# no points\n").string()) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out), nlohmann::json::array());
}

TEST_F(ClosestCli, MalformedPointsFilesFailWithExitOneNamingTheLine) {
  struct Case {
    const char* content;
    const char* expected;
  };
  for (const Case& c : {Case{"0 0 0\n1 two 3\n", "line 2"}, Case{"0 0 0\n\n1 2\n", "line 3"},
                        Case{"0 0 0 1\n", "line 1"}, Case{"0 0 0\n0 nan 0\n", "line 2"},
                        Case{"inf 0 0\n", "line 1"}}) {
    const CliRun r = run(mesh("spot.obj") + " --points " + quoted(write("bad.txt", c.content).string()) + " --json");
    EXPECT_EQ(r.exitCode, 1) << c.content;
    EXPECT_TRUE(r.out.empty()) << "partial output for " << c.content;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("bad.txt"), std::string::npos) << r.err;
  }
}

TEST_F(ClosestCli, MissingFilesFailWithExitOne) {
  const fs::path points = write("p.txt", "0 0 0\n");
  CliRun r = run(quoted((dir_ / "absent.obj").string()) + " --points " + quoted(points.string()) + " --json");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("absent.obj"), std::string::npos) << r.err;
  r = run(mesh("spot.obj") + " --points " + quoted((dir_ / "absent.txt").string()) + " --json");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("absent.txt"), std::string::npos) << r.err;
}

TEST_F(ClosestCli, BadUsageFailsWithExitTwo) {
  CliRun r = run(mesh("spot.obj") + " --json");  // no --points
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_TRUE(r.out.empty());
  r = run(mesh("spot.obj") + " --points " + quoted(write("p.txt", "0 0 0\n").string()) + " --bogus");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_TRUE(r.out.empty());
}

}  // namespace
