// The MuJoCo demos of scenes/mujoco/: each a case where colliding through the convex hull is
// visibly wrong. The outcomes are asserted for MuJoCo's own collider (expected to be wrong: the
// test asserts that it is) and for clod's, against the scenes' geometry (the analytic oracle:
// where the parts must end up), not eyeballed.
#include <gtest/gtest.h>

#if CLOD_HAVE_MUJOCO

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "clod/part_meshes.h"
#include "mujoco_test_support.h"

namespace clod {
namespace {

const std::filesystem::path kScenes = std::filesystem::path(CLOD_SCENES_DIR) / "mujoco";

// Runs a scene for its clod_duration, with MuJoCo's collider (settings null) or clod's, and
// returns the final position of the named geom (its mesh's centroid: MuJoCo recentres meshes).
Vec3 finalPosition(const std::string& scene, const std::string& geom, const mujoco::ColliderSettings* settings) {
  mujoco::ModelPtr m = mujoco::loadModel(kScenes / scene);
  mujoco::DataPtr d(mj_makeData(m.get()));
  const int id = mj_name2id(m.get(), mjOBJ_NUMERIC, "clod_duration");
  EXPECT_GE(id, 0);
  const double duration = m->numeric_data[m->numeric_adr[id]];
  std::unique_ptr<mujoco::Collider> collider;
  if (settings) {
    collider = std::make_unique<mujoco::Collider>(*settings);
    collider->addModel(m.get());
    collider->install();
  }
  const int steps = int(std::lround(duration / m->opt.timestep));
  for (int i = 0; i < steps; ++i) mj_step(m.get(), d.get());
  if (collider) {
    EXPECT_EQ(collider->totals(d.get()).pairsFallback, 0u) << collider->lastError();
    EXPECT_GT(collider->totals(d.get()).contacts, 0u);
  }
  const int g = mj_name2id(m.get(), mjOBJ_GEOM, geom.c_str());
  EXPECT_GE(g, 0) << geom;
  return Vec3(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
}

mujoco::ColliderSettings exactSettings(std::uint64_t budget = 0) {
  mujoco::ColliderSettings s;
  s.model = ContactModel::kExact;
  s.budgetTests = budget;
  return s;
}

// Ring: peg top at z = 0.1 (radius 12 mm); the ring (hole radius 20 mm, tube radius 5 mm) rests
// on the peg's top at z ~ 0.105 through its hull, and around the peg on the floor (z ~ 0.005) if
// it slid down: "around" = its centre within hole radius - peg radius = 8 mm of the peg's axis.
TEST(MujocoDemos, RingSlidesDownAroundThePegWithClodAndStaysOnTopWithTheHull) {
  const Vec3 own = finalPosition("ring_on_peg.xml", "ring", nullptr);
  EXPECT_GT(own.z(), 0.1) << "MuJoCo's hull collider was expected to hold the ring on the peg's top";
  const mujoco::ColliderSettings settings = exactSettings();
  const Vec3 clod = finalPosition("ring_on_peg.xml", "ring", &settings);
  EXPECT_LT(clod.z(), 0.02) << "the ring should be down on the floor, below the peg's top (0.1)";
  EXPECT_LT(clod.head<2>().norm(), 0.008) << "the ring should be around the peg";
}

// Peg in hole: block top at z = 0.04; the peg (60 mm) stands on the block's top (centre 0.07)
// through the hull, and inserted through the hole onto the floor (centre 0.03) with clod;
// "inserted" = its bottom more than 20 mm below the block's top, its axis within the 0.5 mm
// radial clearance of the hole's.
TEST(MujocoDemos, PegGoesIntoTheHoleWithClodAndStandsOnTheBlockWithTheHull) {
  const Vec3 own = finalPosition("peg_in_hole.xml", "peg", nullptr);
  EXPECT_GT(own.z() - 0.03, 0.04 - 1e-3) << "MuJoCo's hull collider was expected to stand the peg on the block";
  const mujoco::ColliderSettings settings = exactSettings();
  const Vec3 clod = finalPosition("peg_in_hole.xml", "peg", &settings);
  EXPECT_LT(clod.z() - 0.03, 0.04 - 0.02) << "the peg should be inserted";
  EXPECT_LT(clod.head<2>().norm(), 0.0005 + 1e-4);
}

// Bunny in bowl: rim at z = 0.09. Through the hull (a solid half ball) the bunny lies on the
// rim's plane (its centre above it); with clod it is inside: its centre at least 20 mm below the
// rim and within the bowl's inner radius (84 mm) of the axis. A budget of 8192 tests per step
// keeps the run short (the unlimited exact model takes ~20 ms a step here).
TEST(MujocoDemos, BunnyFallsIntoTheBowlWithClodAndLiesOnTheHullsLid) {
  const Vec3 own = finalPosition("bunny_in_bowl.xml", "bunny", nullptr);
  EXPECT_GT(own.z(), 0.09) << "MuJoCo's hull collider was expected to hold the bunny above the rim";
  const mujoco::ColliderSettings settings = exactSettings(8192);
  const Vec3 clod = finalPosition("bunny_in_bowl.xml", "bunny", &settings);
  EXPECT_LT(clod.z(), 0.09 - 0.02) << "the bunny should be inside the bowl";
  EXPECT_LT(clod.head<2>().norm(), 0.084);
}

// The committed meshes are what `clod generate mujoco-demo` writes (byte for byte).
TEST(MujocoDemos, CommittedMeshesMatchTheGenerator) {
  for (const NamedMesh& part : demoPartMeshes()) {
    std::ifstream in(kScenes / "meshes" / (part.name + ".obj"), std::ios::binary);
    ASSERT_TRUE(in) << part.name;
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), encodeObj(part.mesh, "clod generate mujoco-demo: " + part.name + " (metres)"))
        << part.name << ".obj differs: run clod generate mujoco-demo -o scenes/mujoco/meshes";
  }
}

// `clod mujoco`: a bad model is bad data (exit 1) with the code named; a good one writes both runs.
TEST(MujocoCli, BadModelIsAnErrorAndAGoodOneWritesBothRuns) {
  const std::string cli = CLOD_CLI_PATH;
  if (cli.empty()) GTEST_SKIP() << "the CLI is not built (CLOD_BUILD_CLI=OFF)";
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "clod-mujoco-cli";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.xml") << "<mujoco><worldbody><geom type=\"mesh\" mesh=\"nope\"/></worldbody>";
  const std::string errFile = (dir / "err.txt").string();
  int rc = std::system((cli + " mujoco " + (dir / "bad.xml").string() + " -o " + (dir / "out").string() + " 2> " + errFile).c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 1);
  std::stringstream err;
  err << std::ifstream(errFile).rdbuf();
  EXPECT_NE(err.str().find("clod: error [parse_error]"), std::string::npos) << err.str();
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "clod" / "trajectory.csv"));
  rc = std::system((cli + " mujoco " + (kScenes / "peg_in_hole.xml").string() + " --duration 0.05 --gltf -o " +
                    (dir / "out").string() + " > /dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 0);
  for (const char* run : {"mujoco", "clod"})
    for (const char* file : {"trajectory.csv", "contacts.csv", "summary.json", "scene.glb", "layers.json"})
      EXPECT_TRUE(std::filesystem::exists(dir / "out" / run / file)) << run << "/" << file;
  rc = std::system((cli + " mujoco " + (kScenes / "peg_in_hole.xml").string() + " --budget -3 -o " +
                    (dir / "out").string() + " 2> /dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
}

}  // namespace
}  // namespace clod

#else

TEST(MujocoDemos, SkippedWithoutMujoco) {
  GTEST_SKIP() << "MuJoCo (libmujoco-dev) was not found at configure time (or this is the sanitizer build): "
                  "the MuJoCo demos are not run";
}

#endif
