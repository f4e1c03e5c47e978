// QuerySettings::maxLevel (the level cap the fidelity experiment resolves collisions at): the
// traversal stops at the given sphere-tree level, checked against the tree's own levels.
#include <gtest/gtest.h>

#include <algorithm>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/primitives.h"
#include "clod/query.h"

namespace clod {
namespace {

TEST(LevelCap, QueriesStopAtTheCappedSphereLevelAndExactIgnoresIt) {
  BakeSettings settings;
  settings.sphereTree.depth = 3;
  settings.measureFit = false;
  settings.buildContactTree = false;
  const CollisionBody cube = CollisionBody::fromBake(bakeMesh(makeBox(Vec3(0.5, 0.5, 0.5)), settings).contents);
  // Two unit cubes overlapping face to face by 0.05 (the sphere-trees overlap at every level).
  const Pose a;
  const Pose b{Quat::Identity(), Vec3(0.95, 0.1, 0.0)};
  QuerySettings qs;
  qs.model = ContactModel::kDos;
  const QueryResult free = queryContacts(cube, a, cube, b, qs);
  ASSERT_TRUE(free.colliding);
  ASSERT_EQ(free.maxLevel, 3u);  // depth-3 tree: leaves at level 3
  for (std::uint32_t cap = 0; cap < 3; ++cap) {
    for (ContactModel model : {ContactModel::kDos, ContactModel::kCfm, ContactModel::kAverage}) {
      qs.model = model;
      qs.maxLevel = cap;
      const QueryResult r = queryContacts(cube, a, cube, b, qs);
      ASSERT_TRUE(r.colliding) << cap;
      EXPECT_EQ(r.maxLevel, cap) << cap;  // the overlapping pairs reach the cap, never pass it
      EXPECT_TRUE(r.finished);            // the cap is an end, not an interruption
      for (const Contact& c : r.contacts) EXPECT_LE(c.level, cap);
      for (const FrontierPair& p : r.frontier) EXPECT_LE(std::max(p.levelA, p.levelB), cap);
    }
  }
  // Exact ignores the cap: the same contacts with and without it (two convex cubes: the
  // separating-axis answer, the face normal and the overlap's corners).
  qs.model = ContactModel::kExact;
  qs.maxLevel = UINT32_MAX;
  const QueryResult exactFree = queryContacts(cube, a, cube, b, qs);
  qs.maxLevel = 0;
  const QueryResult exactCapped = queryContacts(cube, a, cube, b, qs);
  ASSERT_FALSE(exactFree.contacts.empty());
  ASSERT_EQ(exactCapped.contacts.size(), exactFree.contacts.size());
  for (std::size_t i = 0; i < exactFree.contacts.size(); ++i) {
    EXPECT_EQ(exactCapped.contacts[i].point, exactFree.contacts[i].point);
    EXPECT_EQ(exactCapped.contacts[i].normal, exactFree.contacts[i].normal);
    EXPECT_EQ(exactCapped.contacts[i].depth, exactFree.contacts[i].depth);
    // B is A's twin moved 0.95 along +x: the contact normal (B toward A) is -x.
    EXPECT_NEAR(exactFree.contacts[i].normal.x(), -1.0, 1e-12);
    EXPECT_NEAR(exactFree.contacts[i].depth, 0.05, 1e-12);
  }
}

}  // namespace
}  // namespace clod
