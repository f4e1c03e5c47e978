// World's accessors by body id: an id out of range is bad input in every build type.
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/world.h"

namespace clod {
namespace {

// The error an accessor call throws (kInvalidArgument expected), or "no error".
template <class F>
std::string accessorError(F&& call) {
  try {
    call();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    return e.what();
  }
  return "no error";
}

TEST(WorldAccessors, IdOutOfRangeThrowsNamingTheIdAndTheBodyCount) {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;  // the fastest: only the id checks matter here
  settings.sphereTree.depth = 1;
  settings.measureFit = false;
  settings.buildClosestFeatureMap = false;
  settings.buildContactTree = false;
  RigidBodyDesc box;
  box.shape = std::make_shared<const CollisionBody>(
      CollisionBody::fromBake(bakeMesh(makeBox(Vec3(0.5, 0.5, 0.5)), settings).contents));
  World world;
  ASSERT_EQ(world.addBody(box), 0u);

  EXPECT_EQ(accessorError([&] { world.state(99); }),
            "World::state: body id 99 out of range (the world has 1 bodies)");
  EXPECT_EQ(accessorError([&] { world.desc(1); }), "World::desc: body id 1 out of range (the world has 1 bodies)");
  EXPECT_EQ(accessorError([&] { world.type(4000000000u); }),
            "World::type: body id 4000000000 out of range (the world has 1 bodies)");
  EXPECT_EQ(accessorError([&] { world.mass(1); }), "World::mass: body id 1 out of range (the world has 1 bodies)");
  EXPECT_EQ(accessorError([&] { world.state(0); }), "no error");
  EXPECT_EQ(World().bodyCount(), 0u);
  EXPECT_EQ(accessorError([] { World().state(0); }), "World::state: body id 0 out of range (the world has 0 bodies)");
}

std::shared_ptr<const CollisionBody> sphereBody() {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 3;
  settings.measureFit = false;
  settings.buildContactTree = false;
  return std::make_shared<const CollisionBody>(
      CollisionBody::fromBake(bakeMesh(makeIcosphere(0.1, 2), settings).contents));
}

// Memory limits (WorldSettings::maxPairs): n bodies piled at one point, far above anything else,
// make exactly n(n-1)/2 pairs; a limit of that many steps, one less is a resource_limit error
// naming the setting, thrown before the pairs' state exists (the world still steps afterwards
// with a larger limit... it is a limit, not corruption).
TEST(WorldLimits, MorePairsThanMaxPairsIsAResourceLimitError) {
  const auto sphere = sphereBody();
  constexpr int kBodies = 12;
  for (std::uint64_t maxPairs : {std::uint64_t{kBodies * (kBodies - 1) / 2}, std::uint64_t{kBodies * (kBodies - 1) / 2 - 1}}) {
    WorldSettings ws;
    ws.model = ContactModel::kCfm;
    ws.maxPairs = maxPairs;
    World world(ws);
    for (int i = 0; i < kBodies; ++i) {
      RigidBodyDesc d;
      d.shape = sphere;
      d.position = Vec3(0.0, 0.0, 5.0);
      world.addBody(d);
    }
    std::string error = "no error";
    try {
      world.step(1.0 / 60.0);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kResourceLimit);
      error = e.what();
    }
    if (maxPairs == kBodies * (kBodies - 1) / 2) {
      EXPECT_EQ(error, "no error");
    } else {
      EXPECT_NE(error.find("WorldSettings::maxPairs"), std::string::npos) << error;
    }
  }
}

// WorldSettings::maxCachedNodePairs drops the coherence caches of coincident bodies (thousands
// of leaf pairs each). At an unlimited budget a query's answer does not depend on its cache (it
// finishes from the roots or from the cache at the same leaves), so a world that keeps no cache
// steps exactly as one that keeps them all.
TEST(WorldLimits, DroppingTheCoherenceCachesLeavesUnlimitedStepsUnchanged) {
  const auto sphere = sphereBody();
  std::vector<Vec3> end[2];
  for (int run = 0; run < 2; ++run) {
    WorldSettings ws;
    ws.model = ContactModel::kExact;
    ws.maxCachedNodePairs = run == 0 ? std::uint64_t{1} << 40 : 0;
    ws.reuseMotionRel = 0.0;  // query every substep, so the caches would be used
    World world(ws);
    for (int i = 0; i < 4; ++i) {
      RigidBodyDesc d;
      d.shape = sphere;
      d.position = Vec3(0.01 * i, 0.0, 5.0);
      world.addBody(d);
    }
    for (int k = 0; k < 5; ++k) world.step(1.0 / 60.0);
    for (BodyId id = 0; id < world.bodyCount(); ++id) end[run].push_back(world.state(id).position);
  }
  for (std::size_t i = 0; i < end[0].size(); ++i) EXPECT_EQ(end[0][i], end[1][i]) << "body " << i;
}

}  // namespace
}  // namespace clod
