// SimulationRecorder against the world it watches: the test steps the world itself, keeps every
// step's state and report, and checks that the recorder picked the right frames (the stride
// rule worked out by hand) and copied their poses, energies and contacts.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/simulation_recorder.h"

namespace clod {
namespace {

std::shared_ptr<const CollisionBody> boxShape(const Vec3& half) {
  BakeSettings s;
  s.sphereTree.method = SphereTreeMethod::kOctree;
  s.sphereTree.depth = 2;
  s.measureFit = false;
  s.buildContactTree = false;
  return std::make_shared<CollisionBody>(CollisionBody::fromBake(bakeMesh(makeBox(half), s).contents));
}

World dropWorld() {
  World world;
  RigidBodyDesc floor;
  floor.name = "floor";
  floor.shape = boxShape(Vec3(2, 2, 0.2));
  floor.type = BodyType::kStatic;
  floor.position = Vec3(0, 0, -0.2);
  world.addBody(floor);
  RigidBodyDesc box;
  box.name = "box";
  box.shape = boxShape(Vec3(0.2, 0.2, 0.2));
  box.mass = 1.0;
  box.inertia = Mat3::Identity() * (1.0 / 3.0 * 2 * 0.04);  // solid cube, m/3 (hy^2 + hz^2)
  box.position = Vec3(0, 0, 0.25);  // 5 cm above the floor: lands within the run
  box.orientation = Quat(Eigen::AngleAxisd(0.2, Vec3(1, 0, 0)));
  box.angularVelocity = Vec3(0, 0, 2);
  world.addBody(box);
  return world;
}

TEST(SimulationRecorder, FrameStrideKeepsAtMostSixtyFramesPerSecond) {
  World world = dropWorld();
  // stride = ceil(1 / (60 dt)): 1/60 -> 1, 1/30 -> 1, 1/100 -> 2 (50 fps), 1/240 -> 4, 1/1000 -> 17.
  EXPECT_EQ(SimulationRecorder(world, {"a", "b"}, 1.0 / 60.0, 10).frameStride(), 1u);
  EXPECT_EQ(SimulationRecorder(world, {"a", "b"}, 1.0 / 30.0, 10).frameStride(), 1u);
  EXPECT_EQ(SimulationRecorder(world, {"a", "b"}, 1.0 / 100.0, 10).frameStride(), 2u);
  EXPECT_EQ(SimulationRecorder(world, {"a", "b"}, 1.0 / 240.0, 10).frameStride(), 4u);
  EXPECT_EQ(SimulationRecorder(world, {"a", "b"}, 1.0 / 1000.0, 10).frameStride(), 17u);
}

TEST(SimulationRecorder, BadNamesOrTimeStepThrowInvalidArgument) {
  World world = dropWorld();
  try {
    SimulationRecorder(world, {"only one"}, 0.01, 10);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  }
  EXPECT_THROW(SimulationRecorder(world, {"a", "b"}, 0.0, 10), Error);
  EXPECT_THROW(SimulationRecorder(world, {"a", "b"}, std::nan(""), 10), Error);
}

TEST(SimulationRecorder, RecordsTheDecimatedFramesPosesEnergiesAndContactsOfTheWorld) {
  World world = dropWorld();
  const double dt = 1.0 / 240.0;
  const std::uint32_t steps = 50;  // stride 4: frames at steps 0, 4, ..., 48 and the last, 50
  SimulationRecorder recorder(world, {"floor", "box"}, dt, steps);
  std::vector<RigidBodyState> boxStates{world.state(1)};
  std::vector<StepReport> reports(1);
  std::vector<double> energy{world.kineticEnergy() + world.potentialEnergy()};
  for (std::uint32_t s = 1; s <= steps; ++s) {
    const StepReport& r = world.step(dt);
    recorder.recordStep(s, r);
    boxStates.push_back(world.state(1));
    reports.push_back(r);
    energy.push_back(world.kineticEnergy() + world.potentialEnergy());
  }
  const std::vector<std::uint32_t> frameSteps{0, 4, 8, 12, 16, 20, 24, 28, 32, 36, 40, 44, 48, 50};
  ASSERT_EQ(recorder.frameCount(), frameSteps.size());

  const GltfScene scene = recorder.gltfScene();
  ASSERT_EQ(scene.bodies.size(), 2u);
  EXPECT_TRUE(scene.bodies[0].isStatic);
  EXPECT_TRUE(scene.bodies[0].keyframes.empty());
  EXPECT_FALSE(scene.bodies[1].isStatic);
  EXPECT_EQ(scene.bodies[1].name, "box");
  EXPECT_EQ(scene.bodies[1].mesh, &world.desc(1).shape->mesh());
  ASSERT_EQ(scene.keyTimes.size(), frameSteps.size());
  ASSERT_EQ(scene.bodies[1].keyframes.size(), frameSteps.size());
  for (std::size_t f = 0; f < frameSteps.size(); ++f) {
    EXPECT_DOUBLE_EQ(scene.keyTimes[f], frameSteps[f] * dt);
    const RigidBodyState& s = boxStates[frameSteps[f]];
    EXPECT_EQ(scene.bodies[1].keyframes[f].translation, s.position);
    EXPECT_EQ(scene.bodies[1].keyframes[f].rotation.coeffs(), s.orientation.coeffs());
  }
  EXPECT_EQ(scene.bodies[1].initialPose.translation, Vec3(0, 0, 0.25));

  const DebugLayers layers = recorder.debugLayers();
  ASSERT_TRUE(layers.frames);
  const FrameSeries& fr = *layers.frames;
  std::size_t contactFrames = 0;
  for (std::size_t f = 0; f < frameSteps.size(); ++f) {
    const StepReport& r = reports[frameSteps[f]];
    EXPECT_EQ(fr.step[f], frameSteps[f]);
    EXPECT_DOUBLE_EQ(fr.kineticEnergy[f] + fr.potentialEnergy[f], energy[frameSteps[f]]);
    EXPECT_EQ(fr.testsSpent[f], r.testsSpent);
    EXPECT_EQ(fr.contacts[f], r.contacts.size());
    ASSERT_EQ(fr.contactOffsets[f + 1] - fr.contactOffsets[f], r.contacts.size());
    for (std::size_t c = 0; c < r.contacts.size(); ++c) {
      const float* d = &fr.contactData[7 * (fr.contactOffsets[f] + c)];
      EXPECT_FLOAT_EQ(d[2], float(r.contacts[c].point.z()));
      EXPECT_FLOAT_EQ(d[5], float(r.contacts[c].normal.z()));
      EXPECT_FLOAT_EQ(d[6], float(r.contacts[c].depth));
    }
    contactFrames += !r.contacts.empty();
  }
  EXPECT_GT(contactFrames, 0u) << "the box lands within the run, so some frames show contacts";
  // Both bodies have sphere-trees and maps (no contact trees were built).
  ASSERT_EQ(layers.bodies.size(), 2u);
  for (const BodyDebugLayers& b : layers.bodies) {
    EXPECT_TRUE(b.sphereTree);
    EXPECT_TRUE(b.cfmSamples);
    EXPECT_FALSE(b.contactTree);
  }
  // A float cap below the first body's layers leaves every body without layers (scene order).
  BodyLayerOptions tight;
  tight.maxBodyLayerFloats = 1;
  for (const BodyDebugLayers& b : recorder.debugLayers(tight).bodies) {
    EXPECT_FALSE(b.sphereTree);
    EXPECT_FALSE(b.cfmSamples);
  }
}

}  // namespace
}  // namespace clod
