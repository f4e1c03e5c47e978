// Issue 17's scene categories against their analytic outcomes (include/clod/degradation.h): a
// cut of the matrix that `clod experiment degradation` runs whole. The box categories (5-box
// stack, twisted stack, 10-box pyramid, a box sliding to rest, a box resting on a 20 deg slope, a
// box sliding down a 35 deg slope) with cfm, exact and contact-tree at 16, 256 tests per frame and unlimited,
// 60 Hz, full durations: every criterion of the issue's point 1 (plausible), point 2 (the error
// at more budget never worse beyond 10 % or 2 mm); point 3 (real time) is a benchmark
// (`clod experiment degradation`, BENCHMARKS.md). Oracle: the analytic
// answers (rest, v^2 / 2 mu g, a t^2 / 2 with a = g (sin - mu cos)), in runScenario.
// The mesh drops (bunny-1500, spot, fandisk onto a box) with the same models and budgets at 60
// and 240 Hz: plausible (never more than 1 % of the diagonal below the ground, no NaN, never
// through it; oracle: the ground's top face and the mesh's own vertices). Not monotone: where a
// landing mesh comes to rest depends on its bounces (docs/dynamics.md).
// Under the sanitizers: the stack and the slide with cfm at 16 tests, 1 s; one drop, 1 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "clod/degradation.h"
#include "clod/scene.h"
#include "clod/world.h"
#include "support/test_scale.h"

namespace clod {
namespace {

struct Cell {
  ScenarioKind kind;
  ContactModel model;
};

std::string cellName(const testing::TestParamInfo<Cell>& info) {
  std::string name = std::string(scenarioName(info.param.kind)) + "_" + std::string(contactModelName(info.param.model));
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

std::vector<Cell> cells() {
  std::vector<Cell> out;
  if (test::sanitizerRun()) {
    return {{ScenarioKind::kStack5, ContactModel::kCfm}, {ScenarioKind::kSlide, ContactModel::kCfm}};
  }
  for (ScenarioKind kind : {ScenarioKind::kStack5, ScenarioKind::kStack5Twisted, ScenarioKind::kPyramid10,
                            ScenarioKind::kSlide, ScenarioKind::kSlopeRest, ScenarioKind::kSlopeSlide})
    for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree})
      out.push_back({kind, model});
  return out;
}

class Degradation : public testing::TestWithParam<Cell> {};

TEST_P(Degradation, PlausibleAtEveryBudgetAndNeverWorseWithMore) {
  const Cell cell = GetParam();
  const bool light = test::sanitizerRun();
  const std::vector<std::uint64_t> budgets = light ? std::vector<std::uint64_t>{16} : std::vector<std::uint64_t>{16, 256, 0};
  std::vector<double> errors;
  for (std::uint64_t budget : budgets) {
    ScenarioSettings s;
    s.model = cell.model;
    s.budgetTests = budget;
    s.rateHz = 60.0;
    s.seconds = light ? 1.0 : 0.0;  // 0: the scenario's own duration (10 s stacks, 4 s slopes)
    const ScenarioOutcome o = runScenario(cell.kind, s, std::filesystem::path());
    const std::string what = std::string(scenarioName(cell.kind)) + " " + std::string(contactModelName(cell.model)) +
                             " budget " + std::to_string(budget);
    EXPECT_FALSE(o.diverged) << what;
    EXPECT_FALSE(o.fellThrough) << what;
    if (!light) {
      EXPECT_TRUE(o.plausible) << what << ": " << (o.failures.empty() ? std::string() : o.failures.front());
      // (Real time, issue 17's point 3, is a performance goal: `clod experiment degradation`
      // reports it per run and BENCHMARKS.md tabulates it. Asserted here it failed whenever the
      // shared machine was loaded -- the contact tree's slope-slide at an unlimited budget takes
      // ~1.0 CPU s per simulated s.)
    }
    errors.push_back(o.error);
  }
  // Budgets in increasing order (unlimited last): each step up may not be worse.
  for (std::size_t i = 0; i + 1 < errors.size(); ++i)
    EXPECT_TRUE(degradesMonotonically(errors[i], errors[i + 1]))
        << scenarioName(cell.kind) << " " << contactModelName(cell.model) << ": error " << errors[i] << " at budget "
        << budgets[i] << ", " << errors[i + 1] << " at " << budgets[i + 1];
}

INSTANTIATE_TEST_SUITE_P(BoxScenes, Degradation, testing::ValuesIn(cells()), cellName);

// The sphere models (dos, average), the papers' straw men, on the box scenes at budgets that
// interrupt their queries: their coarse contacts' normals (the big spheres' centre lines, the mean
// normals of their triangles) take the supporting body's box direction there (docs/dynamics.md,
// "Sphere models' interrupted contacts"); without that the average model's 10-box pyramid sank
// into the ground, its slide stopped after 1 % of the distance and its slope slide went through
// the slope. Plausible by issue 17's criteria; not monotone, and not at an unlimited budget, where
// each model's own normals stand (a box on a slope rests on leaf spheres' centre lines).
TEST(SphereModels, BoxScenesArePlausibleWhereTheBudgetInterruptsThem) {
  if (test::sanitizerRun()) GTEST_SKIP() << "Release only: the interrupted-pair rule runs in the world tests too";
  for (ScenarioKind kind : {ScenarioKind::kStack5, ScenarioKind::kPyramid10, ScenarioKind::kSlide, ScenarioKind::kSlopeRest,
                            ScenarioKind::kSlopeSlide})
    for (ContactModel model : {ContactModel::kDos, ContactModel::kAverage})
      for (std::uint64_t budget : {16, 256}) {
        ScenarioSettings s;
        s.model = model;
        s.budgetTests = budget;
        s.rateHz = 60.0;
        const ScenarioOutcome o = runScenario(kind, s, std::filesystem::path());
        EXPECT_TRUE(o.plausible) << scenarioName(kind) << " " << contactModelName(model) << " budget " << budget << ": "
                                 << (o.failures.empty() ? std::string() : o.failures.front());
      }
}

std::vector<Cell> dropCells() {
  if (test::sanitizerRun()) return {{ScenarioKind::kDropBunny, ContactModel::kCfm}};
  std::vector<Cell> out;
  for (ScenarioKind kind : {ScenarioKind::kDropBunny, ScenarioKind::kDropSpot, ScenarioKind::kDropFandisk})
    for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree})
      out.push_back({kind, model});
  return out;
}

class MeshDrop : public testing::TestWithParam<Cell> {};

TEST_P(MeshDrop, ComesToRestWithoutSinkingAtEveryBudget) {
  const Cell cell = GetParam();
  const bool light = test::sanitizerRun();
  const std::vector<std::uint64_t> budgets = light ? std::vector<std::uint64_t>{16} : std::vector<std::uint64_t>{16, 256, 0};
  const std::vector<double> rates = light ? std::vector<double>{60.0} : std::vector<double>{60.0, 240.0};
  for (double rate : rates)
    for (std::uint64_t budget : budgets) {
      ScenarioSettings s;
      s.model = cell.model;
      s.budgetTests = budget;
      s.rateHz = rate;
      s.seconds = light ? 1.0 : 0.0;
      s.meshDir = CLOD_SHARED_MESH_DIR;
      const ScenarioOutcome o = runScenario(cell.kind, s, std::filesystem::path());
      const std::string what = std::string(scenarioName(cell.kind)) + " " + std::string(contactModelName(cell.model)) +
                               " budget " + std::to_string(budget) + " at " + std::to_string(int(rate)) + " Hz";
      EXPECT_FALSE(o.diverged) << what;
      EXPECT_FALSE(o.fellThrough) << what;
      // The issue's limit: the lowest vertex never more than 1 % of the diagonal below the ground.
      EXPECT_LE(o.maxSinkRel, 0.01) << what;
      if (!light) {
        EXPECT_TRUE(o.plausible) << what << ": " << (o.failures.empty() ? std::string() : o.failures.front());
      }
    }
}

INSTANTIATE_TEST_SUITE_P(MeshDrops, MeshDrop, testing::ValuesIn(dropCells()), cellName);

// Spot dropped on a box lands on its four hooves and stands: the exact model at an unlimited
// budget ends tilted 0.3 deg. At 60 Hz it lands on its back feet first; in that substep the
// contact tree's interrupted answer had no contact at its front feet, 0.3 mm into the floor,
// because the coarse cells' support points along 386 grid directions lay on each hoof's rim,
// 4 mm above its lowest point, and spot pitched over onto its side (58 deg) at 16-1,024 tests.
// With the cells' hull vertices among the support points it stands. Oracle: the exact run's
// pose (a topple is a tilt of ~58 deg; 5 deg is far from both).
TEST(MeshDropAtSixtyHertz, SpotStandsOnItsFourFeetWithTheContactTreeAtLowBudgets) {
  const bool light = test::sanitizerRun();
  for (std::uint64_t budget : light ? std::vector<std::uint64_t>{16} : std::vector<std::uint64_t>{16, 64, 256}) {
    ScenarioSettings s;
    s.model = ContactModel::kContactTree;
    s.budgetTests = budget;
    s.rateHz = 60.0;
    s.seconds = light ? 1.5 : 0.0;
    s.meshDir = CLOD_SHARED_MESH_DIR;
    const ScenarioOutcome o = runScenario(ScenarioKind::kDropSpot, s, std::filesystem::path());
    EXPECT_LT(o.tiltDeg, 5.0) << "budget " << budget;
    EXPECT_LE(o.maxSinkRel, 0.01) << "budget " << budget;
  }
}

// A drop drawn by scripts/probe-random-scenes.py: the mesh at its scale, position, orientation
// (w, x, y, z) and friction over the probe's 4 x 4 x 0.5 m ground box, as the scene it wrote.
// `groundScale` scales that box (scripts/probe-scaled-drops.py: 4 x 4 x 0.5 of the mesh's diagonal).
struct ProbeDrop {
  const char* mesh;
  double scale;
  std::array<double, 3> position;
  std::array<double, 4> orientation;
  double friction;
};

std::string probeDropScene(const ProbeDrop& d, const char* model, int budget, double groundScale = 1.0) {
  const double g = groundScale;
  std::ostringstream json;
  json << std::setprecision(17) << R"({"duration": 5.0, "contact_model": ")" << model << R"(", "budget": )" << budget
       << R"(, "bodies": [{"name": "ground", "box": [)" << 2 * g << ", " << 2 * g << ", " << 0.25 * g
       << R"(], "position": [0, 0, )" << -0.25 * g << R"(], "static": true, "friction": 0.6},)"
       << R"({"name": "mesh", "mesh": ")" << d.mesh << R"(", "scale": )" << d.scale << R"(, "position": [)" << d.position[0]
       << ", " << d.position[1] << ", " << d.position[2] << R"(], "orientation": [)" << d.orientation[0] << ", "
       << d.orientation[1] << ", " << d.orientation[2] << ", " << d.orientation[3] << R"(], "friction": )" << d.friction
       << "}]}";
  return json.str();
}

// Seed 22's drop: a 0.59 m bunny-1500 that lands on its round back.
constexpr ProbeDrop kSeed22Bunny = {"bunny-1500.obj", 2.3693665718084795,
                                    {-0.20751049181587605, 0.08020049437480856, 0.971647600681705},
                                    {0.18950184256577957, -0.6792264641085994, -0.5844594919280118, -0.40143189262184253},
                                    0.33982872602247255};

// How deep any vertex of body 1 (the dropped mesh) went below z = 0 (the ground's top face) over
// `seconds` at `rateHz`, as fractions of the mesh's diagonal: at any step, and at steps after
// which the solver had no contact between the ground and the mesh.
struct DropSink {
  double deepest = 0.0;
  double deepestWithoutContacts = 0.0;
};

DropSink traceDrop(const std::string& json, double rateHz, double seconds) {
  SceneDescription scene = parseScene(json, CLOD_SHARED_MESH_DIR, "drop.json");
  scene.dt = 1.0 / rateHz;
  World world = buildWorld(scene, std::filesystem::path());
  const BodyId mesh = 1;
  const std::vector<Vec3>& vertices = world.desc(mesh).shape->mesh().vertices;
  const double diagonal = world.desc(mesh).shape->diagonal();
  DropSink sink;
  const int steps = static_cast<int>(seconds * rateHz);
  for (int step = 0; step < steps; ++step) {
    const StepReport& report = world.step(scene.dt);
    const RigidBodyState st = world.state(mesh);
    const Mat3 r = st.orientation.toRotationMatrix();
    double lowest = std::numeric_limits<double>::infinity();
    for (const Vec3& v : vertices) lowest = std::min(lowest, r.row(2).dot(v));
    const double depth = -(lowest + st.position.z()) / diagonal;
    sink.deepest = std::max(sink.deepest, depth);
    std::uint32_t contacts = 0;
    for (const PairReport& pr : report.pairs) contacts += pr.contacts;
    if (contacts == 0) sink.deepestWithoutContacts = std::max(sink.deepestWithoutContacts, depth);
  }
  return sink;
}

// One of the random drops of scripts/probe-random-scenes.py (seed 24): a 0.76 m fandisk dropped
// tumbling from 2.3 m lands on a corner. With the contact tree at 16 tests per frame it sank
// 1.1-1.7 % of its diagonal while every sample's depth was corrected to S's surface, near its
// corners too (docs/contact-tree.md, "Depth at S's surface"). Oracle: the ground's top face and
// the mesh's own vertices; the issue's limit is 1 % of the diagonal at any frame.
TEST(RandomDrop, TumblingFandiskLandsOnACornerWithoutSinkingWithTheContactTree) {
  const std::string json = probeDropScene({"fandisk.obj", 0.0997208256665481,
                                           {-0.5323411219360095, 0.13384411551138947, 2.4584619492842554},
                                           {0.4794792653787865, -0.6993393515523344, -0.400521028034588, 0.3472852020232022},
                                           0.7993715403649966},
                                          "contact-tree", 16);
  const bool light = test::sanitizerRun();
  for (double rate : light ? std::vector<double>{240.0} : std::vector<double>{60.0, 240.0})
    EXPECT_LE(traceDrop(json, rate, light ? 1.0 : 5.0).deepest, 0.01) << "at " << rate << " Hz";
}

// Another (seed 46): a 0.78 m bunny-1500 dropped from 1.5 m rocks on the box after it lands. With
// the contact tree at 16 tests per frame and 60 Hz it sank 1.21 % of its diagonal over steps
// 76-85 while every fresh answer said 4-9 mm deep (error bound 0.3 mm): each fresh contact was
// matched to a previous one and kept that one's anchors, which the solver held together while the
// bunny pivoted about them, so they said 0. A matched anchor pair that the fresh depth refutes is
// now re-anchored (docs/dynamics.md, "Persistent, body-anchored contacts"); measured 0.66 %, at
// the landing. Oracle: the ground's top face and the mesh's own vertices, the issue's 1 % limit.
TEST(RandomDrop, RockingBunnyDoesNotSinkOnItsMatchedAnchorsWithTheContactTree) {
  const std::string json = probeDropScene({"bunny-1500.obj", 3.126312771910703,
                                           {-0.05776429421104168, 0.011349759198360506, 1.497946631227646},
                                           {0.6082663808441775, -0.6715967986901956, -0.41808530352643014, 0.06460982045339235},
                                           0.31609069492813385},
                                          "contact-tree", 16);
  // (Release only: its code paths are the anchors' every substep, and its bake of the bunny's
  // contact tree costs ~25 s under the sanitizers.)
  if (test::sanitizerRun()) GTEST_SKIP() << "the sanitizer pass runs the interrupted-answer case below";
  EXPECT_LE(traceDrop(json, 60.0, 1.6).deepest, 0.01);
}

// Another (seed 22): a 0.59 m bunny-1500 rolling on the box after it lands, with the contact tree
// at 16 tests per frame and 240 Hz, i.e. its roots' answer (two tests a substep). Some of those
// answers found no contact -- interrupted, not a proof that the bodies are apart -- and the world
// dropped the pair's manifold, so the bunny fell freely for three frames with 5.6 mm of it (0.95
// % of its diagonal) inside the floor. An interrupted empty answer now keeps the manifold's
// contacts that are still pressed (docs/dynamics.md, "Graceful degradation"). Oracle: the
// ground's top face and the mesh's vertices: a body deeper than the slop (0.2 % of its diagonal)
// in the floor has contacts.
TEST(RandomDrop, RollingBunnyKeepsItsContactsThroughInterruptedEmptyAnswers) {
  const std::string json = probeDropScene(kSeed22Bunny, "contact-tree", 16);
  const DropSink sink = traceDrop(json, 240.0, 1.6);
  EXPECT_LE(sink.deepestWithoutContacts, 0.002);
  EXPECT_LE(sink.deepest, 0.01);
}

// One of the random drops of scripts/probe-random-scenes.py (seed 22): a 0.59 m bunny-1500 lands
// on its round back. A rigid body rolling on a curve without slip loses no energy, so it rocked
// back and forth at up to 3 rad/s for 5 s and more with every model and budget, exact at an
// unlimited budget too (0.07 m/s at 5 s). With rolling resistance (WorldSettings::
// rollingResistanceRel, docs/dynamics.md) it comes to rest. Oracle: the issue's "come to rest",
// the probe's 5 cm/s after 5 s (measured: 6e-12 m/s); control: without rolling resistance the
// same run is still rocking at 5 s, above 5 mm/s, a billion times the resisted run's speed (so the
// scene does rock; measured 8.9 mm/s, since a fresh answer that contradicts a kept anchor's depth
// re-anchors it; 4.2 cm/s before that, docs/dynamics.md).
TEST(RandomDrop, BunnyLandedOnItsBackComesToRest) {
  const std::string json = probeDropScene(kSeed22Bunny, "exact", 0);
  auto finalSpeed = [&](double rolling) {
    SceneDescription scene = parseScene(json, CLOD_SHARED_MESH_DIR, "drop22.json");
    scene.dt = 1.0 / 240.0;
    scene.world.rollingResistanceRel = rolling;
    World world = buildWorld(scene, std::filesystem::path());
    for (int step = 0; step < 5 * 240; ++step) world.step(scene.dt);
    return world.state(1).velocity.norm();
  };
  EXPECT_LT(finalSpeed(WorldSettings{}.rollingResistanceRel), 0.05);
  if (!test::sanitizerRun()) {
    EXPECT_GT(finalSpeed(0.0), 0.005) << "the control: without rolling resistance it rocks";
  }
}

// Another (seed 603): a 0.77 m bunny-1500 that pivots on one ear tip as it lands, its other
// side coming down. With the contact tree at an unlimited budget and 240 Hz it sank 0.53 % of its
// diagonal, at 1,024 tests 0.05 %: more time made it worse. The pivot's first contact was a
// sample of error bound 0, and every later answer, finished but with its leaves' small bounds,
// counted as coarser, so the world kept the old contact for 12 steps while the fresh answers
// found the other side (docs/dynamics.md, "Graceful degradation": a finished answer always
// wins). Oracle: the ground's top face and the mesh's own vertices; issue 17's monotonicity,
// measured on the deepest sink as scripts/probe-random-scenes.py does (never worse with more
// budget beyond 10 % or 0.2 % of the diagonal).
TEST(RandomDrop, PivotingBunnySinksNoDeeperAtAnUnlimitedBudgetWithTheContactTree) {
  if (test::sanitizerRun()) GTEST_SKIP() << "Release only: the bunny's contact tree takes ~25 s to bake under the sanitizers";
  const ProbeDrop bunny = {"bunny-1500.obj", 3.852222726559992,
                           {-0.32814582816727117, 0.14765509462216908, 0.8845438208967418},
                           {0.39877496490718434, -0.057075786174260665, 0.11209528668781424, -0.9083807179251664},
                           0.5654151941574275};
  const double limited = traceDrop(probeDropScene(bunny, "contact-tree", 1024), 240.0, 0.6).deepest;
  const double unlimited = traceDrop(probeDropScene(bunny, "contact-tree", 0), 240.0, 0.6).deepest;
  EXPECT_LE(unlimited, limited + std::max(0.1 * limited, 0.002)) << "1,024 tests: " << limited;
}

// Millimetre bodies at 60 Hz: by Froude similarity a 1 mm body stepped at 60 Hz moves like a 1 m
// body stepped at 1.9 Hz, so the anti-tunnelling rule splits a frame of its tumbling landing into
// up to 128 substeps, far more than 16 tests per frame can query. When each of the first 16
// substeps got one test, the other 112 kept stale contacts while the fandisk turned at ~100
// rad/s, and it sank 21 % of its diagonal with cfm (the bunny 11 %); with the frame's tests
// spread evenly over its substeps (docs/dynamics.md, "Collision budget per frame") 0.66 %. The
// probe's scene (scripts/probe-scaled-drops.py): the fandisk scaled to a 1 mm diagonal, turned
// 45 deg about x, its lowest point 0.3 mm above a 4 x 4 x 0.5 mm box. Oracle: the box's top face
// and the mesh's own vertices; the issue's limit, 1 % of the diagonal at any frame.
TEST(MillimetreDrop, FandiskAtSixtyHertzAndSixteenTestsPerFrameDoesNotSink) {
  const std::string json = probeDropScene({"fandisk.obj", 0.0001313096111255228,
                                           {-0.0003169748357764557, -0.0014448763613275507, -0.000664042112639844},
                                           {0.9238795325112867, 0.3826834323650898, 0.0, 0.0},
                                           0.6},
                                          "cfm", 16, 0.001);
  EXPECT_LE(traceDrop(json, 60.0, test::sanitizerRun() ? 0.5 : 2.0).deepest, 0.01);
}

}  // namespace
}  // namespace clod
