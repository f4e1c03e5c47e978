// `clod simulate --gltf` and `clod export` as the web viewer and outside checks use them: run
// the built CLI, read scene.glb with the specification-based reader of tests/export/glb_reader.h
// and layers.json with nlohmann::json, and compare with what the other outputs say
// independently: trajectory.csv, contacts.csv, summary.json, `clod bake --json`, the OBJ file.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_runner.h"
#include "export/glb_reader.h"

namespace {

namespace fs = std::filesystem;
using clod::test::accessorValues;
using clod::test::CliRun;
using clod::test::parseGlb;
using clod::test::quoted;
using clod::test::runCli;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Comma-separated rows after the header line.
std::vector<std::vector<std::string>> readCsv(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream s(line);
    std::string field;
    while (std::getline(s, field, ',')) fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

class CliExport : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clod_cli_export_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// A floor, a box dropped tilted and a box thrown sideways; dt = 1/120 s so the output is
// decimated to every 2nd step (60 frames per simulated second).
constexpr const char* kScene = R"({
  "dt": 0.008333333333333333, "steps": 60, "contact_model": "cfm",
  "bodies": [
    {"name": "floor", "box": [2, 2, 0.2], "position": [0, 0, -0.2], "static": true},
    {"name": "tilted", "box": [0.2, 0.2, 0.2], "position": [0, 0, 0.3], "orientation": [0.98, 0.2, 0, 0],
     "bake": {"depth": 2}},
    {"name": "thrown", "box": [0.3, 0.1, 0.1], "position": [1, 0, 0.5], "velocity": [-1, 0, 0],
     "angular_velocity": [0, 0, 3], "bake": {"depth": 2}}
  ]})";

TEST_F(CliExport, SimulateGltfKeyframesAndContactsMatchTheCsvOutputs) {
  std::ofstream(dir_ / "scene.json") << kScene;
  const fs::path out = dir_ / "out";
  const CliRun run = runCli("simulate " + quoted(dir_ / "scene.json") + " -o " + quoted(out) + " --gltf");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("31 frames (every 2 steps"), std::string::npos) << run.out;  // 1 + 60 / 2

  const nlohmann::json summary = nlohmann::json::parse(readAll(out / "summary.json"));
  const auto glb = parseGlb(readAll(out / "scene.glb"));  // throws on bad framing
  EXPECT_EQ(glb.json["asset"]["version"], "2.0");
  const auto& nodes = glb.json["nodes"];
  ASSERT_EQ(nodes.size(), summary["bodies"].size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    EXPECT_EQ(nodes[i]["name"], summary["bodies"][i]["name"]);
    EXPECT_EQ(nodes[i]["extras"]["body"], i);
    EXPECT_EQ(nodes[i]["extras"]["static"], i == 0);
    // Boxes: 12 triangles each.
    const auto& prim = glb.json["meshes"][nodes[i]["mesh"].get<int>()]["primitives"][0];
    EXPECT_EQ(glb.json["accessors"][prim["indices"].get<int>()]["count"], 36);
  }
  for (const auto& view : glb.json["bufferViews"]) EXPECT_EQ(view.value("byteOffset", 0u) % 4, 0u);

  // Keyframes: trajectory.csv rows (step,time,body,px,py,pz,qw,qx,qy,qz,...) at steps 0, 2, ..., 60.
  const auto traj = readCsv(out / "trajectory.csv");
  ASSERT_EQ(glb.json["animations"].size(), 1u);
  const auto& anim = glb.json["animations"][0];
  EXPECT_EQ(anim["name"], "simulation");
  ASSERT_EQ(anim["channels"].size(), 4u) << "two moving bodies x (translation, rotation)";
  for (const auto& channel : anim["channels"]) {
    const int node = channel["target"]["node"];
    const auto& sampler = anim["samplers"][channel["sampler"].get<int>()];
    const std::vector<double> times = accessorValues(glb, sampler["input"]);
    const std::vector<double> values = accessorValues(glb, sampler["output"]);
    ASSERT_EQ(times.size(), 31u);
    const bool rotation = channel["target"]["path"] == "rotation";
    for (std::size_t f = 0; f < times.size(); ++f) {
      const auto& row = traj.at((2 * f) * nodes.size() + std::size_t(node));  // rows: step-major, body order
      ASSERT_EQ(std::stoul(row[0]), 2 * f);
      ASSERT_EQ(row[2], nodes[node]["name"]);
      EXPECT_NEAR(times[f], std::stod(row[1]), 1e-6);  // float time, < 1 s
      if (!rotation) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(values[3 * f + c], std::stod(row[3 + c]), 1e-6);
      } else {
        // File order x y z w; csv order w x y z; same rotation up to sign.
        const double dot = values[4 * f + 3] * std::stod(row[6]) + values[4 * f] * std::stod(row[7]) +
                           values[4 * f + 1] * std::stod(row[8]) + values[4 * f + 2] * std::stod(row[9]);
        EXPECT_NEAR(std::abs(dot), 1.0, 1e-6);
      }
    }
  }

  // layers.json frames and contacts against contacts.csv
  // (step,body_a,body_b,px,py,pz,nx,ny,nz,depth,level).
  const nlohmann::json layers = nlohmann::json::parse(readAll(out / "layers.json"));
  EXPECT_EQ(layers["format"], "clod-layers");
  EXPECT_EQ(layers["version"], 1);
  const auto& frames = layers["frames"];
  ASSERT_EQ(frames["time"].size(), 31u);
  for (const char* key : {"kinetic_energy", "potential_energy", "total_energy", "contacts", "tests_spent", "tests_budget"})
    EXPECT_EQ(frames[key].size(), 31u) << key;
  const auto contacts = readCsv(out / "contacts.csv");
  const auto& offsets = layers["contacts"]["frame_offsets"];
  const auto& data = layers["contacts"]["data"];
  ASSERT_EQ(offsets.size(), 32u);
  std::size_t seen = 0;
  for (std::size_t f = 0; f < 31; ++f) {
    const std::uint32_t step = frames["step"][f];
    EXPECT_EQ(step, 2 * f);
    if (step > 0) {  // summary.json's energy[s - 1] is after step s; printed with ~15 digits
      const double e = summary["energy"][step - 1].get<double>();
      EXPECT_NEAR(frames["total_energy"][f].get<double>(), e, 1e-9 * std::abs(e) + 1e-12);
    }
    std::vector<const std::vector<std::string>*> rows;
    for (const auto& row : contacts)
      if (std::stoul(row[0]) == step) rows.push_back(&row);
    const std::size_t begin = offsets[f], end = offsets[f + 1];
    ASSERT_EQ(end - begin, rows.size()) << "frame " << f;
    EXPECT_EQ(frames["contacts"][f], rows.size());
    for (std::size_t c = 0; c < rows.size(); ++c)
      for (int k = 0; k < 7; ++k)  // px..nz, depth; coordinates < 3 m, float storage
        EXPECT_NEAR(data[7 * (begin + c) + k].get<double>(), std::stod((*rows[c])[3 + k]), 1e-6);
    seen += rows.size();
  }
  EXPECT_GT(seen, 0u) << "the boxes land, so some frames have contacts";

  // Per body: sphere-tree levels (depth 2 below the root for the boxes: 3 levels) and CFM samples
  // with unit normals; no contact tree (the cfm model does not build one).
  ASSERT_EQ(layers["bodies"].size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& b = layers["bodies"][i];
    EXPECT_EQ(b["name"], summary["bodies"][i]["name"]);
    EXPECT_EQ(b["node"], i);
    ASSERT_TRUE(b.contains("sphere_tree"));
    EXPECT_EQ(b["sphere_tree"]["levels"][0].size(), 4u) << "one root sphere";
    EXPECT_FALSE(b.contains("contact_tree"));
    ASSERT_TRUE(b.contains("cfm_samples"));
    for (const auto& level : b["cfm_samples"]) {
      ASSERT_EQ(level["points"].size(), level["normals"].size());
      for (std::size_t k = 0; k < level["normals"].size(); k += 3) {
        const double n = std::hypot(level["normals"][k].get<double>(), level["normals"][k + 1].get<double>(),
                                    level["normals"][k + 2].get<double>());
        EXPECT_NEAR(n, 1.0, 1e-6);
      }
    }
  }
  EXPECT_EQ(layers["bodies"][1]["sphere_tree"]["levels"].size(), 3u);
}

TEST_F(CliExport, SimulateGltfLayersNoneKeepsFramesOnlyAndBadLayerNamesAreUsageErrors) {
  std::ofstream(dir_ / "scene.json") << kScene;
  const fs::path out = dir_ / "out";
  CliRun run = runCli("simulate " + quoted(dir_ / "scene.json") + " -o " + quoted(out) + " --gltf --gltf-layers none");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const nlohmann::json layers = nlohmann::json::parse(readAll(out / "layers.json"));
  EXPECT_TRUE(layers.contains("frames"));
  for (const auto& b : layers["bodies"]) EXPECT_EQ(b.size(), 2u) << "only name and node: " << b.dump();

  const fs::path out2 = dir_ / "out2";
  run = runCli("simulate " + quoted(dir_ / "scene.json") + " -o " + quoted(out2) + " --gltf --gltf-layers spheres,bogus");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("bogus"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out2 / "scene.glb"));
  EXPECT_FALSE(fs::exists(out2 / "summary.json"));
  // --gltf-layers without --gltf is a usage error, not silently ignored.
  EXPECT_EQ(runCli("simulate " + quoted(dir_ / "scene.json") + " -o " + quoted(out2) + " --gltf-layers none").exitCode, 2);
  EXPECT_FALSE(fs::exists(out2 / "summary.json"));
}

// The vertices of an OBJ file ('v x y z' lines), read here independently of the library.
std::array<std::array<double, 3>, 2> objBounds(const fs::path& path) {
  std::array<std::array<double, 3>, 2> box{};
  box[0].fill(std::numeric_limits<double>::infinity());
  box[1].fill(-std::numeric_limits<double>::infinity());
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 2 || line[0] != 'v' || line[1] != ' ') continue;
    std::istringstream fields(line.substr(2));
    double v[3];
    fields >> v[0] >> v[1] >> v[2];
    for (int c = 0; c < 3; ++c) {
      box[0][c] = std::min(box[0][c], v[c]);
      box[1][c] = std::max(box[1][c], v[c]);
    }
  }
  return box;
}

TEST_F(CliExport, ExportOfARealBakeMatchesTheBakeReportAndTheMesh) {
  const fs::path mesh = fs::path(CLOD_SHARED_MESH_DIR) / "bunny-1500.obj";
  const fs::path bake = dir_ / "bunny.clod";
  const CliRun baked = runCli("bake " + quoted(mesh) + " -o " + quoted(bake) +
                              " --sphere-tree octree --levels 3 --sdf-error 1e-2 --sdf-depth 6 --json");
  ASSERT_EQ(baked.exitCode, 0) << baked.err;
  const nlohmann::json report = nlohmann::json::parse(baked.out);
  const fs::path out = dir_ / "view";
  const CliRun run = runCli("export " + quoted(bake) + " -o " + quoted(out));
  ASSERT_EQ(run.exitCode, 0) << run.err;

  const auto glb = parseGlb(readAll(out / "scene.glb"));
  ASSERT_EQ(glb.json["nodes"].size(), 1u);
  EXPECT_FALSE(glb.json.contains("animations"));
  const auto& prim = glb.json["meshes"][0]["primitives"][0];
  EXPECT_EQ(glb.json["accessors"][prim["indices"].get<int>()]["count"], 3 * 1499);  // README: 1,499 triangles
  // POSITION min/max = the OBJ's bounding box (float rounding of coordinates < 1).
  const auto box = objBounds(mesh);
  const auto& pos = glb.json["accessors"][prim["attributes"]["POSITION"].get<int>()];
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(pos["min"][c].get<double>(), box[0][c], 1e-6);
    EXPECT_NEAR(pos["max"][c].get<double>(), box[1][c], 1e-6);
  }
  double diag = 0;
  for (int c = 0; c < 3; ++c) diag += (box[1][c] - box[0][c]) * (box[1][c] - box[0][c]);
  diag = std::sqrt(diag);

  const nlohmann::json layers = nlohmann::json::parse(readAll(out / "layers.json"));
  EXPECT_FALSE(layers.contains("frames"));
  EXPECT_FALSE(layers.contains("contacts"));
  ASSERT_EQ(layers["bodies"].size(), 1u);
  const auto& body = layers["bodies"][0];
  EXPECT_EQ(body["node"], 0);
  // Sphere counts per level as `clod bake --json` reports them.
  ASSERT_EQ(body["sphere_tree"]["levels"].size(), report["levels"].size());
  for (std::size_t l = 0; l < report["levels"].size(); ++l)
    EXPECT_EQ(body["sphere_tree"]["levels"][l].size(), 4 * report["levels"][l]["spheres"].get<std::size_t>()) << "level " << l;
  // CFM samples: the root level at least, unit normals.
  ASSERT_GE(body["cfm_samples"].size(), 1u);
  EXPECT_EQ(body["cfm_samples"][0]["level"], 0);
  for (const auto& level : body["cfm_samples"])
    for (std::size_t k = 0; k < level["normals"].size(); k += 3)
      EXPECT_NEAR(std::hypot(level["normals"][k].get<double>(), level["normals"][k + 1].get<double>(),
                             level["normals"][k + 2].get<double>()),
                  1.0, 1e-6);
  // Contact-tree cells: as many as the bake reports surface cells (under the default cap), each
  // near the surface (below), at most the depth reached, with the cell size halving per depth
  // from one root cube.
  const auto& cells = body["contact_tree"]["cells"];
  const auto& halfspaces = body["contact_tree"]["halfspaces"];
  ASSERT_EQ(cells.size() % 5, 0u);
  EXPECT_EQ(cells.size() / 5, report["sdf_surface_cells"].get<std::size_t>());
  EXPECT_EQ(halfspaces.size() / 4, cells.size() / 5);
  const double rootHalf = cells[3].get<double>() * std::pow(2.0, cells[4].get<double>());
  for (std::size_t i = 0; i < cells.size(); i += 5) {
    const double half = cells[i + 3], depth = cells[i + 4];
    EXPECT_LE(depth, report["sdf_depth_reached"].get<double>());
    EXPECT_NEAR(half * std::pow(2.0, depth), rootHalf, 1e-6 * diag);
    // A surface cell has the surface within half its diagonal of its centre
    // (docs/contact-tree.md), so that ball meets the mesh's bounding box.
    double outside = 0;
    for (int c = 0; c < 3; ++c) {
      const double x = cells[i + c].get<double>();
      const double gap = std::max({box[0][c] - x, x - box[1][c], 0.0});
      outside += gap * gap;
    }
    EXPECT_LE(std::sqrt(outside), std::sqrt(3.0) * half + 1e-6 * diag) << "cell " << i / 5;  // float storage
    const std::size_t h = i / 5 * 4;
    EXPECT_NEAR(std::hypot(halfspaces[h].get<double>(), halfspaces[h + 1].get<double>(), halfspaces[h + 2].get<double>()), 1.0,
                1e-5);
  }
}

TEST_F(CliExport, BadBakeExitsOneWithTheLoadersMessageAndBadArgumentsExitTwo) {
  const fs::path out = dir_ / "out";
  std::ofstream(dir_ / "garbage.clod") << "this is not a bake file at all, just text that is long enough";
  CliRun run = runCli("export " + quoted(dir_ / "garbage.clod") + " -o " + quoted(out));
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("garbage.clod"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("bake_corrupt"), std::string::npos) << run.err;
  run = runCli("export " + quoted(dir_ / "missing.clod") + " -o " + quoted(out));
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("missing.clod"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out / "scene.glb"));
  EXPECT_FALSE(fs::exists(out / "layers.json"));

  EXPECT_EQ(runCli("export " + quoted(dir_ / "garbage.clod")).exitCode, 2);  // no -o
  EXPECT_EQ(runCli("export " + quoted(dir_ / "garbage.clod") + " -o " + quoted(out) + " --max-cells 0").exitCode, 2);
  run = runCli("export " + quoted(dir_ / "garbage.clod") + " -o " + quoted(out) + " --layers spheres,nope");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("nope"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
