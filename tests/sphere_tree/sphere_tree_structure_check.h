#pragma once
// Structural invariants every sphere-tree must satisfy, checked with GoogleTest expectations.

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "clod/mesh.h"
#include "clod/sphere_tree.h"
#include "clod/sphere_tree_builder.h"

namespace clod::test {

inline void expectWellFormedTree(const SphereTree& tree, const TriangleMesh& mesh, const SphereTreeSettings& settings) {
  const std::uint32_t n = tree.sphereCount();
  ASSERT_EQ(tree.levelCount(), settings.depth + 1);
  ASSERT_EQ(tree.centerX.size(), n);
  ASSERT_EQ(tree.centerY.size(), n);
  ASSERT_EQ(tree.centerZ.size(), n);
  ASSERT_EQ(tree.parent.size(), n);
  ASSERT_EQ(tree.firstChild.size(), n);
  ASSERT_EQ(tree.childCount.size(), n);
  ASSERT_EQ(tree.triangleOffsets.size(), n + 1);
  ASSERT_EQ(tree.levelOffsets.front(), 0u);
  ASSERT_EQ(tree.levelOffsets.back(), n);
  ASSERT_EQ(tree.levelEnd(0), 1u) << "one root";
  EXPECT_EQ(tree.parent[0], kNoSphere);

  std::vector<std::uint32_t> level(n);
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    ASSERT_LT(tree.levelBegin(l), tree.levelEnd(l)) << "level " << l << " is empty";
    for (std::uint32_t s = tree.levelBegin(l); s < tree.levelEnd(l); ++s) level[s] = l;
  }
  std::vector<std::uint32_t> claimedBy(n, kNoSphere);
  for (std::uint32_t s = 0; s < n; ++s) {
    EXPECT_TRUE(std::isfinite(tree.radius[s]) && tree.radius[s] > 0.0) << "sphere " << s;
    const bool deepest = level[s] + 1 == tree.levelCount();
    if (deepest) {
      EXPECT_EQ(tree.childCount[s], 0u) << "sphere " << s;
    } else {
      // Every level must cover everything, so no sphere above the deepest level is childless.
      EXPECT_GE(tree.childCount[s], 1u) << "sphere " << s;
      EXPECT_LE(tree.childCount[s], settings.branching) << "sphere " << s;
      for (std::uint32_t c = tree.firstChild[s]; c < tree.firstChild[s] + tree.childCount[s]; ++c) {
        ASSERT_LT(c, n);
        EXPECT_EQ(level[c], level[s] + 1) << "child " << c << " of " << s;
        EXPECT_EQ(tree.parent[c], s) << "child " << c << " of " << s;
        EXPECT_EQ(claimedBy[c], kNoSphere) << "child " << c << " claimed twice";
        claimedBy[c] = s;
      }
    }
    const auto tris = tree.triangles(s);
    EXPECT_FALSE(tris.empty()) << "sphere " << s;
    EXPECT_TRUE(std::is_sorted(tris.begin(), tris.end()) && std::adjacent_find(tris.begin(), tris.end()) == tris.end())
        << "sphere " << s << ": triangle list not sorted and unique";
    for (std::uint32_t t : tris) ASSERT_LT(t, mesh.triangleCount());
    if (!deepest) {
      // A parent is responsible for exactly the union of its children's triangles.
      std::set<std::uint32_t> unionOfChildren;
      for (std::uint32_t c = tree.firstChild[s]; c < tree.firstChild[s] + tree.childCount[s]; ++c)
        for (std::uint32_t t : tree.triangles(c)) unionOfChildren.insert(t);
      EXPECT_TRUE(std::equal(tris.begin(), tris.end(), unionOfChildren.begin(), unionOfChildren.end()))
          << "sphere " << s;
    }
  }
  for (std::uint32_t s = 1; s < n; ++s) EXPECT_NE(claimedBy[s], kNoSphere) << "sphere " << s << " has no parent";
  // Every triangle is assigned on every level.
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    std::vector<bool> seen(mesh.triangleCount(), false);
    for (std::uint32_t s = tree.levelBegin(l); s < tree.levelEnd(l); ++s)
      for (std::uint32_t t : tree.triangles(s)) seen[t] = true;
    EXPECT_EQ(std::count(seen.begin(), seen.end(), false), 0) << "level " << l << " misses triangles";
  }
}

}  // namespace clod::test
