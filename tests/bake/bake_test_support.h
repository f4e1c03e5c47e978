#pragma once
// Shared fixtures for the bake tests: a small mesh and a sphere-tree built here by brute force,
// independent of the library's builders, so the container and codecs are tested on their own.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "clod/bake.h"
#include "clod/primitives.h"
#include "support/test_scale.h"

namespace clod::test {

/// A three-level tree: the root around everything, one sphere per occupied octant of the
/// bounding box (by triangle centroid), one sphere per triangle. Spheres enclose their
/// triangles' corners, so the tree is a valid bounding hierarchy.
inline SphereTree buildBruteForceTree(const TriangleMesh& mesh) {
  SphereTree tree;
  auto addSphere = [&](const std::vector<std::uint32_t>& triangles, std::uint32_t parent) {
    Aabb box;
    for (std::uint32_t t : triangles)
      for (int k = 0; k < 3; ++k) box.extend(mesh.corner(t, k));
    const Vec3 c = box.center();
    double r = 0.0;
    for (std::uint32_t t : triangles)
      for (int k = 0; k < 3; ++k) r = std::max(r, (mesh.corner(t, k) - c).norm());
    tree.centerX.push_back(c.x());
    tree.centerY.push_back(c.y());
    tree.centerZ.push_back(c.z());
    tree.radius.push_back(r);
    tree.parent.push_back(parent);
    tree.firstChild.push_back(0);
    tree.childCount.push_back(0);
    tree.triangleOffsets.push_back(static_cast<std::uint32_t>(tree.triangleList.size()));
    tree.triangleList.insert(tree.triangleList.end(), triangles.begin(), triangles.end());
    return static_cast<std::uint32_t>(tree.radius.size() - 1);
  };
  std::vector<std::uint32_t> all(mesh.triangleCount());
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) all[t] = t;
  const Vec3 middle = mesh.bounds().center();
  std::vector<std::vector<std::uint32_t>> octants(8);
  for (std::uint32_t t : all) {
    const Vec3 centroid = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
    const int octant = (centroid.x() > middle.x()) | (centroid.y() > middle.y()) << 1 | (centroid.z() > middle.z()) << 2;
    octants[octant].push_back(t);
  }
  std::erase_if(octants, [](const auto& group) { return group.empty(); });

  tree.levelOffsets.push_back(0);
  addSphere(all, kNoSphere);
  tree.levelOffsets.push_back(1);
  tree.firstChild[0] = 1;
  tree.childCount[0] = static_cast<std::uint32_t>(octants.size());
  for (const auto& group : octants) addSphere(group, 0);
  tree.levelOffsets.push_back(static_cast<std::uint32_t>(tree.radius.size()));
  for (std::uint32_t g = 0; g < octants.size(); ++g) {
    const std::uint32_t sphere = 1 + g;
    tree.firstChild[sphere] = static_cast<std::uint32_t>(tree.radius.size());
    tree.childCount[sphere] = static_cast<std::uint32_t>(octants[g].size());
    for (std::uint32_t t : octants[g]) addSphere({t}, sphere);
  }
  tree.levelOffsets.push_back(static_cast<std::uint32_t>(tree.radius.size()));
  tree.triangleOffsets.push_back(static_cast<std::uint32_t>(tree.triangleList.size()));
  return tree;
}

/// Contents built without the library's builders: an 80-triangle icosphere, shifted off the
/// origin so coordinates are not symmetric, with the brute-force tree above.
inline BakeContents makeTestContents() {
  BakeContents contents;
  contents.mesh = makeIcosphere(1.5, 1);
  for (Vec3& v : contents.mesh.vertices) v += Vec3(0.25, -3.0, 7.125);
  contents.meshHash = meshContentHash(contents.mesh);
  contents.sourceName = "icosphere-test.obj";
  contents.sphereTree = buildBruteForceTree(contents.mesh);
  contents.sphereTreeSettings = {SphereTreeMethod::kOctree, 8, 2};
  return contents;
}

/// Bitwise equality of two contact trees, one assertion per field.
inline void expectSameContactTree(const ContactTree& a, const ContactTree& b) {
  auto sameBits = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof(x)) == 0; };
  EXPECT_TRUE(sameBits(a.origin.x(), b.origin.x()) && sameBits(a.origin.y(), b.origin.y()) &&
              sameBits(a.origin.z(), b.origin.z()));
  EXPECT_TRUE(sameBits(a.rootSize, b.rootSize));
  EXPECT_TRUE(sameBits(a.meshDiagonal, b.meshDiagonal));
  EXPECT_TRUE(sameBits(a.errorAbs, b.errorAbs));
  EXPECT_TRUE(sameBits(a.bandAbs, b.bandAbs));
  EXPECT_EQ(a.maxDepth, b.maxDepth);
  EXPECT_TRUE(sameBits(a.rootCorners, b.rootCorners));
  EXPECT_TRUE(a.nodeWords.size() == b.nodeWords.size() &&
              std::memcmp(a.nodeWords.data(), b.nodeWords.data(), a.nodeWords.size() * sizeof(ContactTreeNodeWord)) == 0);
  EXPECT_EQ(a.errorCode, b.errorCode);
  EXPECT_EQ(a.levelOffsets, b.levelOffsets);
  EXPECT_TRUE(a.lattice.size() == b.lattice.size() &&
              std::memcmp(a.lattice.data(), b.lattice.data(), a.lattice.size() * sizeof(float)) == 0);
  EXPECT_TRUE(a.halfSpaces.size() == b.halfSpaces.size() &&
              std::memcmp(a.halfSpaces.data(), b.halfSpaces.data(), a.halfSpaces.size() * sizeof(ContactHalfSpace)) == 0);
}

/// How sphere values of a decoded tree relate to the tree that was encoded.
enum class SphereValues : std::uint8_t {
  kExact,      ///< bit for bit: the tree was already on the file's grid (bakeMesh, a decoded file)
  kContained,  ///< a tree from elsewhere: each decoded ball contains the original, grown by little
};

/// Each decoded sphere `d` contains its original ball `o` (|c_d - c_o| + r_o <= r_d) and grows by
/// at most the documented (1 + sqrt(3)/2) 2^-kSphereGridBits of its decoded parent's radius
/// (sphere_tree_section.h; the root is stored exactly). Structure must match exactly.
inline void expectDecodedSpheresContainOriginals(const SphereTree& o, const SphereTree& d) {
  ASSERT_EQ(o.radius.size(), d.radius.size());
  ASSERT_EQ(o.parent, d.parent);
  for (std::uint32_t i = 0; i < o.sphereCount(); ++i) {
    const double shift = (d.center(i) - o.center(i)).norm();
    // 4 ulps of the radius: the test's own |c_d - c_o| and sum round; the codec rounds up by more.
    const double ulps = 4.0 * std::numeric_limits<double>::epsilon() * d.radius[i];
    ASSERT_LE(shift + o.radius[i], d.radius[i] + ulps) << "sphere " << i << " lost part of its original ball";
    if (i == 0) {
      EXPECT_EQ(shift, 0.0);
      EXPECT_EQ(o.radius[0], d.radius[0]);
      continue;
    }
    const double growthBound = (1.0 + std::sqrt(3.0) / 2.0) * std::ldexp(d.radius[d.parent[i]], -11);
    EXPECT_LE(d.radius[i] - o.radius[i], growthBound * (1.0 + 1e-12)) << "sphere " << i << " grew more than documented";
  }
}

/// Field-by-field equality, with one assertion per field so a failure names it.
inline void expectSameContents(const BakeContents& a, const BakeContents& b, SphereValues values = SphereValues::kExact) {
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  for (std::size_t i = 0; i < a.mesh.vertices.size(); ++i) {
    // Bitwise, not ==: a round trip must preserve every bit (and -0.0 vs +0.0).
    ASSERT_EQ(std::memcmp(a.mesh.vertices[i].data(), b.mesh.vertices[i].data(), sizeof(Vec3)), 0) << "vertex " << i;
  }
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.meshHash, b.meshHash);
  EXPECT_EQ(a.sourceName, b.sourceName);
  EXPECT_EQ(a.sphereTreeSettings.method, b.sphereTreeSettings.method);
  EXPECT_EQ(a.sphereTreeSettings.branching, b.sphereTreeSettings.branching);
  EXPECT_EQ(a.sphereTreeSettings.depth, b.sphereTreeSettings.depth);
  EXPECT_EQ(a.sphereTreeSettings.medialSamples, b.sphereTreeSettings.medialSamples);
  EXPECT_EQ(a.sphereTreeSettings.medialReduction, b.sphereTreeSettings.medialReduction);
  const SphereTree& s = a.sphereTree;
  const SphereTree& t = b.sphereTree;
  if (values == SphereValues::kExact) {
    EXPECT_EQ(s.centerX, t.centerX);
    EXPECT_EQ(s.centerY, t.centerY);
    EXPECT_EQ(s.centerZ, t.centerZ);
    EXPECT_EQ(s.radius, t.radius);
  } else {
    expectDecodedSpheresContainOriginals(s, t);
  }
  EXPECT_EQ(s.parent, t.parent);
  EXPECT_EQ(s.firstChild, t.firstChild);
  EXPECT_EQ(s.childCount, t.childCount);
  EXPECT_EQ(s.triangleOffsets, t.triangleOffsets);
  EXPECT_EQ(s.triangleList, t.triangleList);
  EXPECT_EQ(s.levelOffsets, t.levelOffsets);
  EXPECT_EQ(a.closestFeatureMap.has_value(), b.closestFeatureMap.has_value());
  ASSERT_EQ(a.contactTree.has_value(), b.contactTree.has_value());
  if (a.contactTree) expectSameContactTree(*a.contactTree, *b.contactTree);
}

/// Runs `f` and returns the clod::Error code it threw; fails the test if it threw nothing.
template <class F>
ErrorCode thrownCode(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  ADD_FAILURE() << "expected a clod::Error";
  return static_cast<ErrorCode>(0);  // no such code: never matches an expectation
}

}  // namespace clod::test
