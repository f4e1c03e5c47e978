#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/scene.h"

namespace clod {
namespace {

std::string sceneError(const std::string& json) {
  try {
    parseScene(json, ".", "t.json");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kSceneError) << e.what();
    return e.what();
  }
  return "no error";
}

TEST(SceneParse, WrongTypeNamesTheKeyPath) {
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1]}, {"box": [1,1,1]}, {"box": [1,1,1]},
                                      {"box": [1,1,1], "velocity": [0, "x", 0]}]})"),
            "t.json: bodies[3].velocity[1]: expected a number");
}

TEST(SceneParse, UnknownKeysAreErrors) {
  EXPECT_EQ(sceneError(R"({"bodies": [], "gravty": [0,0,0]})"), "t.json: gravty: unknown key");
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1], "colour": 1}]})"), "t.json: bodies[0].colour: unknown key");
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1], "bake": {"depht": 2}}]})"),
            "t.json: bodies[0].bake.depht: unknown key");
}

TEST(SceneParse, OutOfRangeAndConflictingValuesAreErrors) {
  EXPECT_NE(sceneError(R"({"bodies": [{"box": [1,1,1], "restitution": 1.5}]})").find("bodies[0].restitution"),
            std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [{"box": [1,1,1], "sphere": 1}]})").find("exactly one of"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [{"box": [1,1,1], "mass": 1, "density": 2}]})").find("not both"),
            std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [{"box": [1,1]}]})").find("bodies[0].box: expected 3 numbers"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "contact_model": "magic"})").find("contact_model"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "dt": -1})").find("dt: expected a number > 0"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [{"box": [1,1,1], "orientation": [0,0,0,0]}]})").find("bodies[0].orientation"),
            std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "frontier_pair_cost": 2000})").find("frontier_pair_cost"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "budget_us": -5})").find("budget_us: expected a number >= 0"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "budget_us": "fast"})").find("budget_us"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "min_substep_iterations": 21})").find("min_substep_iterations"),
            std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "max_pairs": 0})").find("max_pairs"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "max_substeps": 0})").find("max_substeps"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "max_substeps": 4097})").find("max_substeps"), std::string::npos);
  // min_substeps is bounded by the scene's own max_substeps, not the default.
  EXPECT_NE(sceneError(R"({"bodies": [], "max_substeps": 4, "min_substeps": 5})").find("min_substeps"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "max_cached_node_pairs": -1})").find("max_cached_node_pairs"), std::string::npos);
  EXPECT_NE(sceneError(R"({"bodies": [], "mesh_limits": {"max_triangles": 0}})").find("mesh_limits.max_triangles"),
            std::string::npos);
  EXPECT_EQ(sceneError(R"({"bodies": [], "mesh_limits": {"max_faces": 9}})"), "t.json: mesh_limits.max_faces: unknown key");
  EXPECT_NE(sceneError("{not json").find("not valid JSON"), std::string::npos);
  EXPECT_NE(sceneError(R"({"dt": 0.01})").find("bodies: missing"), std::string::npos);
}

TEST(SceneParse, ReadsEveryFieldAsWritten) {
  const SceneDescription s = parseScene(R"({"gravity": [0, 0, -1], "dt": 0.01, "duration": 0.5,
      "contact_model": "exact", "budget": 64, "budget_us": 1500, "max_contacts": 4, "max_substeps": 32, "min_substeps": 3,
      "min_substep_iterations": 7, "frontier_pair_cost": 5, "max_pairs": 1000, "max_cached_node_pairs": 0,
      "mesh_limits": {"max_vertices": 11, "max_triangles": 22, "max_polygon_vertices": 33},
      "bodies": [{"name": "a", "box": [1, 2, 3], "static": true},
                 {"name": "b", "sphere": 0.25, "position": [1, 2, 3], "orientation": [0, 0, 0, 2],
                  "velocity": [4, 5, 6], "angular_velocity": [7, 8, 9], "torque": [1, -2, 3], "mass": 3, "restitution": 0.5,
                  "friction": 0.1, "bake": {"depth": 2, "method": "medial"}},
                 {"mesh": "m/x.obj", "scale": 2}]})",
                                        "/base", "t.json");
  EXPECT_EQ(s.world.gravity, Vec3(0, 0, -1));
  EXPECT_EQ(s.steps, 50u);  // 0.5 s / 0.01 s
  EXPECT_EQ(s.world.model, ContactModel::kExact);
  EXPECT_EQ(s.world.budgetTests, 64u);
  EXPECT_EQ(s.world.budgetMicros, 1500.0);
  EXPECT_EQ(s.world.maxContacts, 4u);
  EXPECT_EQ(s.world.maxSubsteps, 32u);
  EXPECT_EQ(s.world.minSubsteps, 3u);
  EXPECT_EQ(s.world.minSubstepIterations, 7u);
  EXPECT_EQ(s.world.frontierPairCost, 5u);
  EXPECT_EQ(s.world.maxPairs, 1000u);
  EXPECT_EQ(s.world.maxCachedNodePairs, 0u);
  EXPECT_EQ(s.meshLoad.maxVertices, 11u);
  EXPECT_EQ(s.meshLoad.maxTriangles, 22u);
  EXPECT_EQ(s.meshLoad.maxPolygonVertices, 33u);
  ASSERT_EQ(s.bodies.size(), 3u);
  EXPECT_EQ(s.bodies[0].type, BodyType::kStatic);
  EXPECT_EQ(s.bodies[0].halfExtents, Vec3(1, 2, 3));
  EXPECT_EQ(s.bodies[1].shape, SceneShapeKind::kSphere);
  EXPECT_DOUBLE_EQ(s.bodies[1].radius, 0.25);
  EXPECT_DOUBLE_EQ(s.bodies[1].orientation.z(), 1.0);  // normalised [w,x,y,z] = [0,0,0,1]
  EXPECT_EQ(s.bodies[1].angularVelocity, Vec3(7, 8, 9));
  EXPECT_EQ(s.bodies[1].torque, Vec3(1, -2, 3));
  EXPECT_EQ(s.bodies[0].torque, Vec3::Zero());
  EXPECT_DOUBLE_EQ(*s.bodies[1].mass, 3.0);
  EXPECT_EQ(s.bodies[1].bake.depth, 2u);
  EXPECT_EQ(s.bodies[2].meshPath, std::filesystem::path("/base/m/x.obj"));
  EXPECT_EQ(s.bodies[2].name, "body2");
}

TEST(SceneBuild, GivenMassAndAnalyticBoxInertiaReachTheWorld) {
  const SceneDescription s = parseScene(
      R"({"bodies": [{"box": [0.5, 1.0, 1.5], "mass": 6, "bake": {"depth": 1}}]})", ".", "t.json");
  const World world = buildWorld(s, {});
  EXPECT_NEAR(world.mass(0), 6.0, 1e-12);
  // Solid box: I_xx = m/3 (hy^2 + hz^2) = 2 * (1 + 2.25) = 6.5 (half extents).
  EXPECT_NEAR(world.desc(0).inertia(0, 0), 6.5, 1e-9);
  EXPECT_NEAR(world.desc(0).inertia(2, 2), 2.0 * (0.25 + 1.0), 1e-9);
}

// An orientation is a direction: [0, 0, 1e300, 1e300], whose norm overflows, is the half turn
// about (0, 1, 1) / sqrt 2 -- it was normalised to zero and refused by the world -- and
// [1e-10, 0, 0, 0] is the identity (refused as zero before). Oracle: the unit quaternions by hand.
TEST(SceneParse, OrientationsOfAnyFiniteNonzeroMagnitudeAreTheirRotation) {
  const SceneDescription s = parseScene(
      R"({"bodies": [{"box": [1,1,1], "orientation": [0, 0, 1e300, 1e300]}, {"box": [1,1,1], "orientation": [1e-10, 0, 0, 0]}]})",
      ".", "t.json");
  ASSERT_EQ(s.bodies.size(), 2u);
  EXPECT_NEAR(s.bodies[0].orientation.w(), 0.0, 1e-15);
  EXPECT_NEAR(s.bodies[0].orientation.y(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(s.bodies[0].orientation.z(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(s.bodies[1].orientation.w(), 1.0, 1e-15);
}

TEST(SceneParse, TorqueMustBeThreeNumbers) {
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1], "torque": [0, 0]}]})").rfind("t.json: bodies[0].torque", 0), 0u);
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1], "torque": [0, "x", 0]}]})"),
            "t.json: bodies[0].torque[1]: expected a number");
}

TEST(SceneBuild, ConstantTorqueSpinsAFreeBodyAsIAlphaEqualsTau) {
  // Zero gravity, a 1 x 2 x 3 box of 6 kg (I_zz = m/3 (hx^2 + hy^2) = 2 x 1.25 = 2.5 kg m2 with
  // half extents 0.5, 1), torque 5 N m about z for 10 steps of 0.01 s: w_z = tau t / I_zz = 0.2
  // rad/s (analytic; nothing touches it).
  const SceneDescription s = parseScene(
      R"({"gravity": [0, 0, 0], "dt": 0.01, "bodies": [{"box": [0.5, 1.0, 1.5], "mass": 6, "torque": [0, 0, 5],
          "bake": {"depth": 1}}]})",
      ".", "t.json");
  World world = buildWorld(s, {});
  for (int i = 0; i < 10; ++i) {
    applyConstantTorques(s, world);
    world.step(s.dt);
  }
  EXPECT_NEAR(world.state(0).angularVelocity.z(), 0.2, 1e-9);
  EXPECT_NEAR(world.state(0).angularVelocity.head<2>().norm(), 0.0, 1e-12);
}

// The scene's mesh limits reach the loader: box.obj has 8 vertices and 12 triangles, so a limit
// of 11 triangles refuses it (kUnsupportedMesh, naming the limit) and 12 loads it.
TEST(SceneBuild, MeshLimitsOfTheSceneRefuseALargerMeshFile) {
  const std::string mesh = std::string(CLOD_TEST_DATA_DIR) + "/good/box.obj";
  auto scene = [&](int maxTriangles) {
    return parseScene(R"({"mesh_limits": {"max_triangles": )" + std::to_string(maxTriangles) + R"(},
                          "bodies": [{"mesh": ")" + mesh + R"(", "bake": {"depth": 1}}]})",
                      ".", "t.json");
  };
  try {
    buildWorld(scene(11), {});
    ADD_FAILURE() << "a 12-triangle mesh loaded under max_triangles 11";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kUnsupportedMesh) << e.what();
    EXPECT_NE(std::string(e.what()).find("maxTriangles"), std::string::npos) << e.what();
  }
  EXPECT_EQ(buildWorld(scene(12), {}).bodyCount(), 1u);
}

TEST(SceneBuild, SecondBuildLoadsShapesFromTheCache) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "clod_scene_cache_test";
  std::filesystem::remove_all(dir);
  const SceneDescription s = parseScene(
      R"({"bodies": [{"box": [0.5, 0.5, 0.5], "bake": {"depth": 1}}, {"box": [0.5, 0.5, 0.5], "bake": {"depth": 1}},
                     {"sphere": 0.3, "bake": {"depth": 1}}]})", ".", "t.json");
  SceneBuildReport first, second;
  buildWorld(s, dir, &first);
  buildWorld(s, dir, &second);
  EXPECT_EQ(first.shapesBaked, 2u);  // the two equal boxes share one shape
  EXPECT_EQ(first.shapesFromCache, 0u);
  EXPECT_EQ(second.shapesBaked, 0u);
  EXPECT_EQ(second.shapesFromCache, 2u);
  std::filesystem::remove_all(dir);
}

TEST(SceneBuild, ShippedScenesParse) {
  for (const char* name : {"box_on_box", "bunny_on_box", "cubes_zero_g", "bunnies_zero_g", "stack_10", "bin_200"}) {
    const std::filesystem::path p = std::filesystem::path(CLOD_TEST_DATA_DIR) / ".." / ".." / "scenes" / (std::string(name) + ".json");
    SceneDescription s;
    EXPECT_NO_THROW(s = loadScene(p)) << name;
    for (const SceneBody& b : s.bodies) {
      if (b.shape == SceneShapeKind::kMesh) {
        EXPECT_TRUE(std::filesystem::exists(b.meshPath)) << b.meshPath;
      }
    }
  }
}

}  // namespace
}  // namespace clod
