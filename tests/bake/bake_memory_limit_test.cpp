// BakeSettings::maxMemoryBytes and ContactTreeSettings::maxNodes: a bake that would pass its
// memory limit stops with kResourceLimit naming it; one within the limit is the unlimited bake.
#include <gtest/gtest.h>

#include "bake_test_support.h"
#include "clod/contact_tree_builder.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

namespace clod {
namespace {

using test::thrownCode;

// The code and message of the clod::Error that f throws.
template <class F>
ErrorCode thrownCode(F&& f, std::string* message) {
  try {
    f();
  } catch (const Error& e) {
    *message = e.what();
    return e.code();
  }
  ADD_FAILURE() << "expected a clod::Error";
  return static_cast<ErrorCode>(0);
}

BakeSettings quickSettings() {
  BakeSettings settings;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 2;
  settings.measureFit = false;
  settings.contactTree.maxDepth = 6;
  return settings;
}

// The triangles' share is checked before anything is built: a limit below
// triangles x kBakeBytesPerTriangle refuses at once, whatever the rest would have needed.
TEST(BakeMemoryLimit, AMeshWhoseTrianglesAloneNeedMoreIsRefusedBeforeBuilding) {
  const TriangleMesh mesh = makeIcosphere(1.0, 3);  // 1,280 triangles
  BakeSettings settings = quickSettings();
  settings.maxMemoryBytes = mesh.triangles.size() * kBakeBytesPerTriangle;
  std::string message;
  EXPECT_EQ(thrownCode([&] { bakeMesh(mesh, settings); }, &message), ErrorCode::kResourceLimit);
  EXPECT_NE(message.find("BakeSettings::maxMemoryBytes"), std::string::npos) << message;
}

// The contact tree's node limit: a tree of N nodes builds under maxNodes = N (the same tree as
// without a limit) and stops with kResourceLimit under N - 1 (its last level's 8 children
// cannot be added).
TEST(BakeMemoryLimit, TheContactTreeStopsAtItsNodeLimitAndBuildsTheSameTreeWithin) {
  const TriangleMesh mesh = makeIcosphere(1.0, 3);
  const MeshDistance distance(mesh);
  ContactTreeSettings settings;
  settings.maxDepth = 6;
  const ContactTree unlimited = buildContactTree(distance, settings);
  const std::uint64_t nodes = unlimited.nodeCount();
  ASSERT_GT(nodes, 9u);
  settings.maxNodes = nodes;
  EXPECT_EQ(buildContactTree(distance, settings).nodeCount(), nodes);
  settings.maxNodes = nodes - 1;
  std::string message;
  EXPECT_EQ(thrownCode([&] { buildContactTree(distance, settings); }, &message), ErrorCode::kResourceLimit);
  EXPECT_NE(message.find("ContactTreeSettings::maxNodes"), std::string::npos) << message;
}

// bakeMesh hands the contact tree what the triangles leave of maxMemoryBytes.
TEST(BakeMemoryLimit, BakeMeshGivesTheContactTreeWhatTheTrianglesLeave) {
  const TriangleMesh mesh = makeIcosphere(1.0, 3);
  BakeSettings settings = quickSettings();
  settings.maxMemoryBytes = 0;  // no limit
  const BakeResult free = bakeMesh(mesh, settings);
  const std::uint64_t nodes = free.contactTreeStats.nodes;
  settings.maxMemoryBytes = mesh.triangles.size() * kBakeBytesPerTriangle + nodes * kBakeBytesPerContactTreeNode;
  EXPECT_EQ(bakeMesh(mesh, settings).contactTreeStats.nodes, nodes);
  settings.maxMemoryBytes -= kBakeBytesPerContactTreeNode;
  EXPECT_EQ(thrownCode([&] { bakeMesh(mesh, settings); }), ErrorCode::kResourceLimit);
}

}  // namespace
}  // namespace clod
