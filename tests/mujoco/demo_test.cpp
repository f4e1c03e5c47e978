// The MuJoCo demos of scenes/mujoco/: each a case where colliding through the convex hull is
// visibly wrong. The outcomes are asserted for MuJoCo's own collider (expected to be wrong: the
// test asserts that it is) and for clod's, against the scenes' geometry (the analytic oracle:
// where the parts must end up), not eyeballed.
#include <gtest/gtest.h>

#if CLOD_HAVE_MUJOCO

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "clod/part_meshes.h"
#include "clod/thread_meshes.h"
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

// Nut on a bolt (scenes/mujoco/nut_bolt.xml, thread_meshes.h): an M16 x 2 nut started on the
// bolt's first thread, turned by 1 mN m with gravity and friction 0.1. Oracles: the pitch (2 mm),
// the helix the nut must follow (its height against its turn) and the thread's play from the
// generator's clearance. The nut's body frame is its mesh file's frame (MuJoCo moves the geom,
// not the mesh, to the centroid: checked first), so its body pose is the nut's placement.
struct ScrewRun {
  double turns = 0.0;                    // about z, unwrapped; negative = screwing down
  double advancePerTurn = 0.0;           // after the first 0.1 s (settling onto the flank)
  double helixLow = 0.0, helixHigh = 0.0;// height minus pitch x turns, from the start
  double lateral = 0.0, tilt = 0.0;      // max distance of the nut's axis from the bolt's; max tilt
  Vec3 final = Vec3::Zero();             // the nut's body position at the end
  mujoco::StepStats totals;
};

ScrewRun screwNut(const mujoco::ColliderSettings* settings) {
  mujoco::ModelPtr m = mujoco::loadModel(kScenes / "nut_bolt.xml");
  mujoco::DataPtr d(mj_makeData(m.get()));
  const int id = mj_name2id(m.get(), mjOBJ_NUMERIC, "clod_duration");
  const double duration = m->numeric_data[m->numeric_adr[id]];
  std::unique_ptr<mujoco::Collider> collider;
  if (settings) {
    collider = std::make_unique<mujoco::Collider>(*settings);
    collider->addModel(m.get());
    collider->install();
  }
  const int body = mj_name2id(m.get(), mjOBJ_BODY, "nut"), geom = mj_name2id(m.get(), mjOBJ_GEOM, "nut");
  mj_forward(m.get(), d.get());
  const double pitch = NutBoltParts{}.thread.pitch;
  const double z0 = d->xpos[3 * body + 2];
  {  // MuJoCo moved the geom to the mesh's centroid and principal axes, and the stored
     // vertices with it: every vertex must still land where the file puts it in the body frame.
    const TriangleMesh nut = nutBoltMeshes()[1].mesh;
    const int mesh = m->geom_dataid[geom];
    // (MuJoCo's OBJ reader gives every face its own corners: compare face by face.)
    EXPECT_EQ(m->mesh_facenum[mesh], int(nut.triangleCount()));
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation(d->geom_xmat + 9 * geom);
    const Vec3 origin(d->geom_xpos[3 * geom], d->geom_xpos[3 * geom + 1], d->geom_xpos[3 * geom + 2]);
    double worst = 0.0;
    for (int f = 0; f < std::min<int>(m->mesh_facenum[mesh], int(nut.triangleCount())); ++f)
      for (int k = 0; k < 3; ++k) {
        const float* local = m->mesh_vert + 3 * (m->mesh_vertadr[mesh] + m->mesh_face[3 * (m->mesh_faceadr[mesh] + f) + k]);
        const Vec3 world = origin + rotation * Vec3(local[0], local[1], local[2]);
        worst = std::max(worst, (world - (test::bodyPosition(d.get(), body) + nut.corner(std::uint32_t(f), k))).norm());
      }
    EXPECT_LT(worst, 1e-6);  // MuJoCo keeps vertices in single precision: ~1e-9 m at 0.02 m, plus the turn
  }
  ScrewRun run;
  double previous = 0.0, turnsAtSettle = 0.0, zAtSettle = z0;
  const int steps = int(std::lround(duration / m->opt.timestep)), settle = int(std::lround(0.1 / m->opt.timestep));
  for (int i = 1; i <= steps; ++i) {
    mj_step(m.get(), d.get());
    const Quat q(d->xquat[4 * body], d->xquat[4 * body + 1], d->xquat[4 * body + 2], d->xquat[4 * body + 3]);
    const double angle = 2.0 * std::atan2(q.z(), q.w());
    double delta = angle - previous;
    delta -= 2.0 * std::numbers::pi * std::round(delta / (2.0 * std::numbers::pi));
    run.turns += delta / (2.0 * std::numbers::pi);
    previous = angle;
    const Vec3 p = test::bodyPosition(d.get(), body);
    const double offHelix = (p.z() - z0) - pitch * run.turns;
    run.helixLow = std::min(run.helixLow, offHelix);
    run.helixHigh = std::max(run.helixHigh, offHelix);
    run.lateral = std::max(run.lateral, p.head<2>().norm());
    run.tilt = std::max(run.tilt, std::acos(std::clamp((q * Vec3::UnitZ()).z(), -1.0, 1.0)));
    if (i == settle) turnsAtSettle = run.turns, zAtSettle = p.z();
    run.final = p;
  }
  run.advancePerTurn = (run.final.z() - zAtSettle) / (run.turns - turnsAtSettle);
  if (collider) {
    run.totals = collider->totals(d.get());
    EXPECT_EQ(run.totals.pairsFallback, 0u) << collider->lastError();
  }
  return run;
}

// Through the hulls the nut (a solid hexagonal prism) overlaps the bolt (a solid cylinder) and
// is pushed off: it ends more than the thread's depth (1.08 mm) off the axis, or below the
// bolt's bottom. With clod it screws down: at least one turn in 0.5 s (1.5 measured), the pitch
// per turn within 5 % (the bound), on the helix within the axial play (c tan 30 deg =
// 87 um) plus 15 um of MuJoCo's soft penetration (0.75 % of the pitch; measured 11 um with solref
// 2 ms), its axis within the radial clearance (0.15 mm) of the bolt's, tilted less than 1 degree.
TEST(MujocoDemos, NutScrewsDownTheBoltWithClodAndIsPushedOffWithTheHull) {
  const ScrewRun own = screwNut(nullptr);
  EXPECT_TRUE(own.lateral > 1.08e-3 || own.final.z() < 0.0)
      << "MuJoCo's hull collider was expected to push the nut off the bolt";
  mujoco::ColliderSettings settings = exactSettings();
  settings.sphereTree.depth = 4;  // as the scene's clod_sphere_tree_depth
  const ScrewRun clod = screwNut(&settings);
  const NutBoltParts parts{};
  const double pitch = parts.thread.pitch, axialPlay = parts.radialClearance * std::tan(std::numbers::pi / 6);
  EXPECT_LT(clod.turns, -1.0);
  EXPECT_NEAR(clod.advancePerTurn, pitch, 0.05 * pitch);
  EXPECT_GT(clod.helixLow, -axialPlay - 15e-6);
  EXPECT_LT(clod.helixHigh, axialPlay + 15e-6);
  EXPECT_LT(clod.lateral, parts.radialClearance);
  EXPECT_LT(clod.tilt, std::numbers::pi / 180.0);
  std::printf("nut on bolt (clod exact): %.3f turns, %.4f mm per turn, helix offset [%.1f, %.1f] um, lateral %.1f um, "
              "tilt %.3f deg, %.1f contacts per step\n",
              clod.turns, clod.advancePerTurn * 1e3, clod.helixLow * 1e6, clod.helixHigh * 1e6, clod.lateral * 1e6,
              clod.tilt * 180 / std::numbers::pi, double(clod.totals.contacts) / std::max(1u, clod.totals.pairs));
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
