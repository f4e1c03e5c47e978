// The degradation scenarios (degradation.h) as scenes: the geometry the issue describes (boxes
// touching face on face, 2 cm pyramid gaps, a box flush on the slope, meshes of ~0.75 m dropped
// from 25 cm), the shipped JSON files in scenes/ describing the same scenes, names, and the
// monotone rule. The physics outcomes are in tests/degradation/.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "clod/degradation.h"
#include "clod/error.h"
#include "clod/mesh_io.h"

namespace clod {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::filesystem::path scenesDir() { return std::filesystem::path(CLOD_TEST_DATA_DIR) / ".." / ".." / "scenes"; }

ScenarioSettings defaults() {
  ScenarioSettings s;
  s.meshDir = CLOD_SHARED_MESH_DIR;
  return s;
}

TEST(DegradationScenarios, NamesRoundTripAndUnknownNamesAreRejected) {
  for (ScenarioKind k : kAllScenarios) EXPECT_EQ(parseScenarioKind(scenarioName(k)), k);
  EXPECT_EQ(scenarioName(ScenarioKind::kStack5Twisted), "stack5-twisted");
  EXPECT_EQ(scenarioName(ScenarioKind::kDropFandisk), "drop-fandisk");
  try {
    parseScenarioKind("stack6");
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("pyramid10"), std::string::npos) << e.what();
  }
}

TEST(DegradationScenarios, SettingsReachTheWorldAndBadRatesThrow) {
  ScenarioSettings s = defaults();
  s.model = ContactModel::kCfm;
  s.budgetTests = 64;
  s.budgetMicros = 200.0;
  s.rateHz = 240.0;
  const SceneDescription scene = makeScenario(ScenarioKind::kStack5, s);
  EXPECT_EQ(scene.world.model, ContactModel::kCfm);
  EXPECT_EQ(scene.world.budgetTests, 64u);
  EXPECT_EQ(scene.world.budgetMicros, 200.0);
  EXPECT_DOUBLE_EQ(scene.dt, 1.0 / 240.0);
  EXPECT_EQ(scene.steps, 2400u);  // 10 s at 240 Hz
  s.seconds = 0.5;
  EXPECT_EQ(makeScenario(ScenarioKind::kSlide, s).steps, 120u);
  s.rateHz = 0.0;
  EXPECT_THROW(makeScenario(ScenarioKind::kSlide, s), Error);
  s.rateHz = 60.0;
  s.budgetMicros = -1.0;
  EXPECT_THROW(makeScenario(ScenarioKind::kSlide, s), Error);
}

TEST(DegradationScenarios, StacksTouchFaceOnFaceAndTheTwistGrowsByTenDegrees) {
  for (ScenarioKind k : {ScenarioKind::kStack5, ScenarioKind::kStack5Twisted}) {
    const SceneDescription s = makeScenario(k, defaults());
    ASSERT_EQ(s.bodies.size(), 6u);
    EXPECT_EQ(s.bodies[0].type, BodyType::kStatic);
    EXPECT_NEAR(s.bodies[0].position.z() + s.bodies[0].halfExtents.z(), 0.0, 1e-12);  // ground top at z = 0
    for (int i = 1; i <= 5; ++i) {
      const SceneBody& b = s.bodies[static_cast<std::size_t>(i)];
      EXPECT_EQ(b.halfExtents, Vec3::Constant(0.5));
      EXPECT_NEAR(b.position.z(), i - 0.5, 1e-12);  // 1 m cubes resting on each other
      EXPECT_EQ(b.friction, 0.6);
      const double twistDeg = std::abs(Eigen::AngleAxisd(b.orientation).angle()) * 180.0 / kPi;
      EXPECT_NEAR(twistDeg, k == ScenarioKind::kStack5Twisted ? 10.0 * (i - 1) : 0.0, 1e-9);
    }
  }
}

TEST(DegradationScenarios, PyramidRowsHaveTwoCentimetreGapsAndRestOnTheGapsBelow) {
  const SceneDescription s = makeScenario(ScenarioKind::kPyramid10, defaults());
  ASSERT_EQ(s.bodies.size(), 11u);
  std::size_t i = 1;
  for (int row = 0; row < 4; ++row) {
    for (int k = 0; k < 4 - row; ++k, ++i) {
      const SceneBody& b = s.bodies[i];
      EXPECT_NEAR(b.position.z(), row + 0.5, 1e-12);
      if (k > 0) {
        EXPECT_NEAR(b.position.x() - s.bodies[i - 1].position.x(), 1.02, 1e-12);  // 2 cm gap
      }
      if (row > 0) {
        // Centred over the gap between the two boxes below (4 - row + 1 boxes back).
        const SceneBody& left = s.bodies[i - static_cast<std::size_t>(5 - row)];
        const SceneBody& right = s.bodies[i - static_cast<std::size_t>(4 - row)];
        EXPECT_NEAR(b.position.x(), 0.5 * (left.position.x() + right.position.x()), 1e-12);
      }
    }
  }
}

TEST(DegradationScenarios, SlopeBoxesRestFlushOnTheTiltedTopFace) {
  for (auto [k, deg, mu] : {std::tuple{ScenarioKind::kSlopeRest, 20.0, 0.6}, std::tuple{ScenarioKind::kSlopeSlide, 35.0, 0.3}}) {
    const SceneDescription s = makeScenario(k, defaults());
    ASSERT_EQ(s.bodies.size(), 2u);
    const SceneBody& ground = s.bodies[0];
    const SceneBody& box = s.bodies[1];
    const Vec3 normal = ground.orientation * Vec3::UnitZ();
    EXPECT_NEAR(std::acos(normal.z()) * 180.0 / kPi, deg, 1e-9);
    EXPECT_GT(normal.x(), 0.0);  // tilted about y: +x runs downhill
    EXPECT_NEAR(normal.y(), 0.0, 1e-12);
    // Box centre half a box above the top face, same orientation, inside the face.
    EXPECT_NEAR((box.position - ground.position).dot(normal), ground.halfExtents.z() + 0.5, 1e-12);
    EXPECT_NEAR(box.orientation.angularDistance(ground.orientation), 0.0, 1e-12);
    const Vec3 local = ground.orientation.conjugate() * (box.position - ground.position);
    EXPECT_LT(std::abs(local.x()) + 0.5, ground.halfExtents.x());
    EXPECT_EQ(ground.friction, mu);
    EXPECT_EQ(box.friction, mu);
  }
}

TEST(DegradationScenarios, SlideStartsAtTwoMetresPerSecondOnFlatGround) {
  const SceneDescription s = makeScenario(ScenarioKind::kSlide, defaults());
  ASSERT_EQ(s.bodies.size(), 2u);
  EXPECT_EQ(s.bodies[1].velocity, Vec3(2.0, 0.0, 0.0));
  EXPECT_NEAR(s.bodies[1].position.z(), 0.5, 1e-12);
  // v^2 / (2 mu g) = 0.68 m of travel stays on the ground.
  EXPECT_LT(s.bodies[1].position.x() + 0.5 + 4.0 / (2 * 0.3 * 9.81), s.bodies[0].halfExtents.x());
}

TEST(DegradationScenarios, DroppedMeshesAreScaledToThreeQuarterMetreAndStartAboveTheGround) {
  for (ScenarioKind k : {ScenarioKind::kDropBunny, ScenarioKind::kDropSpot, ScenarioKind::kDropFandisk}) {
    const SceneDescription s = makeScenario(k, defaults());
    ASSERT_EQ(s.bodies.size(), 2u);
    const SceneBody& b = s.bodies[1];
    ASSERT_EQ(b.shape, SceneShapeKind::kMesh);
    const TriangleMesh mesh = loadMesh(b.meshPath).mesh;
    Aabb local, world;
    for (const Vec3& v : mesh.vertices) {
      local.extend(v * b.scale);
      world.extend(b.orientation * (v * b.scale) + b.position);
    }
    EXPECT_NEAR((local.max - local.min).norm(), 0.75, 1e-9) << scenarioName(k);
    EXPECT_NEAR(world.min.z(), 0.25, 1e-9) << scenarioName(k);
  }
}

// The height offset (the experiment's perturbed references) moves the drop and nothing else.
TEST(DegradationScenarios, DropHeightOffsetRaisesOnlyTheDroppedMesh) {
  ScenarioSettings s = defaults();
  const SceneDescription plain = makeScenario(ScenarioKind::kDropFandisk, s);
  s.dropHeightOffset = 1e-5;
  const SceneDescription raised = makeScenario(ScenarioKind::kDropFandisk, s);
  // (1e-15: the rounding of adding 1e-5 to a height of ~0.3 m.)
  EXPECT_LT((raised.bodies[1].position - plain.bodies[1].position - Vec3(0.0, 0.0, 1e-5)).norm(), 1e-15);
  EXPECT_EQ(raised.bodies[0].position, plain.bodies[0].position);
  s.dropHeightOffset = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(makeScenario(ScenarioKind::kDropFandisk, s), Error);
}

// scenes/<name>.json are the scenarios at their defaults (exact, unlimited, 60 Hz) for
// `clod simulate`; they must describe the same bodies.
TEST(DegradationScenarios, ShippedSceneFilesMatchTheScenarios) {
  const std::pair<ScenarioKind, const char*> files[] = {
      {ScenarioKind::kStack5, "stack_5"},         {ScenarioKind::kStack5Twisted, "stack_5_twisted"},
      {ScenarioKind::kPyramid10, "pyramid_10"},   {ScenarioKind::kSlide, "slide"},
      {ScenarioKind::kSlopeRest, "slope_rest"},   {ScenarioKind::kSlopeSlide, "slope_slide"},
      {ScenarioKind::kDropBunny, "drop_bunny"},   {ScenarioKind::kDropSpot, "drop_spot"},
      {ScenarioKind::kDropFandisk, "drop_fandisk"}};
  for (const auto& [kind, name] : files) {
    SCOPED_TRACE(name);
    SceneDescription file;
    ASSERT_NO_THROW(file = loadScene(scenesDir() / (std::string(name) + ".json")));
    const SceneDescription code = makeScenario(kind, defaults());
    EXPECT_EQ(file.world.model, ContactModel::kExact);
    EXPECT_EQ(file.world.budgetTests, 0u);
    EXPECT_DOUBLE_EQ(file.dt, code.dt);
    EXPECT_EQ(file.steps, code.steps);
    EXPECT_EQ(file.world.minSubsteps, code.world.minSubsteps);
    ASSERT_EQ(file.bodies.size(), code.bodies.size());
    for (std::size_t i = 0; i < code.bodies.size(); ++i) {
      const SceneBody& f = file.bodies[i];
      const SceneBody& c = code.bodies[i];
      EXPECT_EQ(f.name, c.name);
      EXPECT_EQ(f.shape, c.shape);
      EXPECT_EQ(f.type, c.type);
      EXPECT_EQ(f.friction, c.friction);
      // Meshes are placed from their vertices, which the loader keeps in single precision.
      const double tolerance = c.shape == SceneShapeKind::kMesh ? 1e-6 : 1e-9;
      EXPECT_LT((f.position - c.position).norm(), tolerance) << f.name;
      EXPECT_LT(f.orientation.normalized().angularDistance(c.orientation), 1e-9) << f.name;
      EXPECT_EQ(f.velocity, c.velocity) << f.name;
      if (c.shape == SceneShapeKind::kBox) {
        EXPECT_EQ(f.halfExtents, c.halfExtents) << f.name;
      }
      if (c.shape == SceneShapeKind::kMesh) {
        EXPECT_NEAR(f.scale, c.scale, tolerance * c.scale);
        EXPECT_EQ(f.meshPath.filename(), c.meshPath.filename());
        EXPECT_TRUE(std::filesystem::exists(f.meshPath)) << f.meshPath;
      }
    }
  }
}

TEST(DegradationScenarios, MonotoneRuleAllowsTenPercentOrTwoMillimetres) {
  EXPECT_TRUE(degradesMonotonically(0.100, 0.050));   // better
  EXPECT_TRUE(degradesMonotonically(0.100, 0.109));   // within 10 % worse
  EXPECT_FALSE(degradesMonotonically(0.100, 0.111));  // more than 10 % (and > 2 mm)
  EXPECT_TRUE(degradesMonotonically(0.001, 0.0029));  // within 2 mm worse
  EXPECT_FALSE(degradesMonotonically(0.001, 0.0031));
  EXPECT_FALSE(degradesMonotonically(NAN, 0.0));
  EXPECT_FALSE(degradesMonotonically(0.0, NAN));
}

}  // namespace
}  // namespace clod
