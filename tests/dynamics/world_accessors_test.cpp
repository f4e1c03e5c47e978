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

}  // namespace
}  // namespace clod
