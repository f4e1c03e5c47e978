#include "clod/mesh_weld.h"

#include <random>

#include <gtest/gtest.h>

#include "clod/primitives.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

// The weld rule written the slow, obvious way: for each vertex in order, the first earlier
// output vertex within tolerance (smallest index), else a new output vertex.
std::vector<std::uint32_t> bruteForceWeld(const std::vector<Vec3>& points, double tolerance,
                                          std::vector<Vec3>& kept) {
  std::vector<std::uint32_t> remap(points.size());
  kept.clear();
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint32_t match = UINT32_MAX;
    for (std::uint32_t j = 0; j < kept.size(); ++j)
      if ((kept[j] - points[i]).norm() <= tolerance) {
        match = j;
        break;
      }
    if (match == UINT32_MAX) {
      match = static_cast<std::uint32_t>(kept.size());
      kept.push_back(points[i]);
    }
    remap[i] = match;
  }
  return remap;
}

TEST(WeldVertices, SplitTriangleSoupOfABoxWeldsToEightVertices) {
  const TriangleMesh box = makeBox(Vec3(1, 2, 3));
  TriangleMesh soup;
  for (const Triangle& t : box.triangles) {
    const std::uint32_t base = soup.vertexCount();
    for (int k = 0; k < 3; ++k) soup.vertices.push_back(box.vertices[t[k]]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  const WeldResult result = weldVertices(soup, 0.0);
  EXPECT_EQ(soup.vertexCount(), 8u);
  EXPECT_EQ(result.mergedCount, 36u - 8u);
  EXPECT_EQ(result.collapsedTriangles, 0u);
  // Same triangles as the box, corner for corner (positions, since indices may be renumbered).
  for (std::uint32_t t = 0; t < box.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(soup.corner(t, k), box.corner(t, k));
}

TEST(WeldVertices, MatchesBruteForceOnRandomClusters) {
  std::mt19937 rng(1234);
  const int rounds = test::sanitizerRun() ? 5 : 30;
  for (int round = 0; round < rounds; ++round) {
    // Clusters of points with jitter around the tolerance, so some pairs are just inside and some
    // just outside, in a box of diagonal ~1.7.
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double tolerance = 1e-3 * (1 + round % 5);
    std::vector<Vec3> points;
    const int clusters = 50 + round * 10;
    for (int c = 0; c < clusters; ++c) {
      const Vec3 centre(unit(rng), unit(rng), unit(rng));
      const int members = 1 + int(unit(rng) * 5);
      for (int m = 0; m < members; ++m) {
        Vec3 offset(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
        points.push_back(centre + offset * (2.0 * tolerance * unit(rng)));
      }
    }
    std::shuffle(points.begin(), points.end(), rng);
    TriangleMesh mesh;
    mesh.vertices = points;
    for (std::uint32_t i = 0; i + 2 < points.size(); i += 3) mesh.triangles.push_back({i, i + 1, i + 2});

    std::vector<Vec3> expectedKept;
    const std::vector<std::uint32_t> expectedRemap = bruteForceWeld(points, tolerance, expectedKept);
    const WeldResult result = weldVertices(mesh, tolerance);
    // Contract: output vertices pairwise farther apart than the tolerance, every input within
    // tolerance of its output vertex, output in order of first appearance.
    ASSERT_EQ(mesh.vertices.size(), expectedKept.size()) << "round " << round;
    for (std::size_t i = 0; i < points.size(); ++i)
      EXPECT_LE((mesh.vertices[result.remap[i]] - points[i]).norm(), tolerance);
    for (std::size_t a = 0; a < mesh.vertices.size(); ++a) {
      EXPECT_EQ(mesh.vertices[a], expectedKept[a]);
      for (std::size_t b = a + 1; b < mesh.vertices.size(); ++b)
        EXPECT_GT((mesh.vertices[a] - mesh.vertices[b]).norm(), tolerance);
    }
    EXPECT_EQ(result.remap, expectedRemap);
    EXPECT_EQ(result.mergedCount, points.size() - expectedKept.size());
  }
}

TEST(WeldVertices, ZeroToleranceMergesOnlyIdenticalPositions) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(std::nextafter(1.0, 2.0), 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0)};
  mesh.triangles = {{0, 1, 3}, {0, 2, 4}};
  const WeldResult result = weldVertices(mesh, 0.0);
  EXPECT_EQ(mesh.vertexCount(), 4u);
  EXPECT_EQ(result.remap, (std::vector<std::uint32_t>{0, 1, 2, 3, 1}));
  EXPECT_EQ(mesh.triangles[1], (Triangle{0, 2, 1}));
  EXPECT_EQ(result.collapsedTriangles, 0u);
}

TEST(WeldVertices, CountsTrianglesThatCollapse) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1e-9, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  const WeldResult result = weldVertices(mesh, 1e-6);
  EXPECT_EQ(mesh.vertexCount(), 3u);
  EXPECT_EQ(result.collapsedTriangles, 1u);
  EXPECT_EQ(mesh.triangleCount(), 2u);  // kept, not removed
}

}  // namespace
}  // namespace clod
