// Support points of contact-tree cells (cell_support.h) against brute force: every point lies
// on the mesh surface inside its (closed) cell, and along each of the grid directions and along
// random directions between them no point of the surface inside the cell -- sampled densely,
// independently of the clipping that builds the supports -- reaches farther than the supports do.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "clod/cell_support.h"
#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "tree_cache.h"

namespace clod {
namespace {

ContactTree treeWithSupports(const TriangleMesh& mesh) {
  ContactTreeSettings settings;
  settings.maxDepth = 6;
  ContactTree tree = buildContactTree(MeshDistance(mesh), settings);
  deriveCellSupports(tree, mesh);
  return tree;
}

// Cells of depth <= maxDepth, with their node ids, by walking the tree from the root.
std::vector<ContactCell> cellsDownTo(const ContactTree& tree, std::uint32_t maxDepth) {
  std::vector<ContactCell> cells{tree.rootCell()}, stack{tree.rootCell()};
  while (!stack.empty()) {
    const ContactCell c = stack.back();
    stack.pop_back();
    if (c.depth >= maxDepth || tree.isLeaf(c.node)) continue;
    for (std::uint32_t o = 0; o < 8; ++o) {
      cells.push_back(tree.childCell(c, o));
      stack.push_back(cells.back());
    }
  }
  return cells;
}

TEST(CellSupport, ABoxRootCellsSupportsAreItsEightCorners) {
  const Vec3 half(0.5, 0.3, 0.2);
  const TriangleMesh box = makeBox(half);
  const ContactTree tree = treeWithSupports(box);
  const std::span<const Vec3> supports = tree.cellSupports(tree.rootCell().node);
  ASSERT_EQ(supports.size(), 8u);
  for (const Vec3& p : supports) {
    // Exact: the corners are mesh vertices, and no clipping touches them (the root cube holds the box).
    EXPECT_EQ(p.cwiseAbs(), half) << p.transpose();
  }
  std::vector<Vec3> sorted(supports.begin(), supports.end());
  std::sort(sorted.begin(), sorted.end(), [](const Vec3& a, const Vec3& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  EXPECT_TRUE(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end()) << "a corner twice";
}

TEST(CellSupport, SupportPointsAreSurfacePointsOfTheirCellThatReachFarthestAlongAnyDirection) {
  const test::BuiltTree& built = test::sharedTree("bunny-1500.obj");
  const TriangleMesh& mesh = built.exact->mesh();
  ContactTree tree = built.tree;
  deriveCellSupports(tree, mesh);
  const double diag = mesh.bounds().diagonal();
  // Dense surface samples: area-weighted points on the triangles plus every vertex.
  std::vector<double> areaPrefix;
  double total = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) areaPrefix.push_back(total += 0.5 * mesh.triangleCross(t).norm());
  std::mt19937_64 rng(5);
  std::vector<Vec3> samples(mesh.vertices);
  const int count = test::sanitizerRun() ? 20000 : 200000;  // sanitizers: ~10x slower
  for (int i = 0; i < count; ++i) samples.push_back(test::randomBandPoint(mesh, areaPrefix, 0.0, rng));
  // Grid directions: a 9 x 9 grid on each face of the cube (cell_support.cpp), here the 26 of
  // the coarse 3 x 3 grid and a few in between, all members of that grid.
  std::vector<Vec3> directions;
  for (int x = -4; x <= 4; x += 2)
    for (int y = -4; y <= 4; y += 2)
      for (int z : {-4, 4}) directions.push_back(Vec3(0.25 * x, 0.25 * y, 0.25 * z));
  for (int x : {-4, 4})
    for (int y = -4; y <= 4; y += 4)
      for (int z = -4; z <= 4; z += 4) directions.push_back(Vec3(0.25 * x, 0.25 * y, 0.25 * z));
  // And random ones, off the grid: the hull's vertices reach as far as the surface in every
  // direction (the grid's extremes alone fall short between its directions -- on spot's hooves
  // by 4 mm near the floor's normal).
  std::normal_distribution<double> gauss;
  for (int k = 0; k < 40; ++k) directions.push_back(Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized());
  // 1e-9 of the diagonal: rounding of the clipped points and of the cell bounds.
  const double tol = 1e-9 * diag;
  int checkedCells = 0;
  for (const ContactCell& cell : cellsDownTo(tree, test::sanitizerRun() ? 1 : 2)) {
    const std::span<const Vec3> supports = tree.cellSupports(cell.node);
    const Vec3 lo = tree.cellMin(cell), hi = lo + Vec3::Constant(tree.cellSize(cell.depth));
    std::vector<Vec3> inCell;
    for (const Vec3& s : samples)
      if ((s.array() >= lo.array()).all() && (s.array() <= hi.array()).all()) inCell.push_back(s);
    if (inCell.empty()) continue;
    ASSERT_FALSE(supports.empty()) << "node " << cell.node << " holds surface but no support point";
    ++checkedCells;
    for (const Vec3& p : supports) {
      EXPECT_TRUE((p.array() >= lo.array() - tol).all() && (p.array() <= hi.array() + tol).all()) << p.transpose();
      double nearest = std::numeric_limits<double>::infinity();
      for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t)
        nearest = std::min(nearest, std::sqrt(closestPointOnTriangle(p, mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)).distanceSquared));
      EXPECT_LE(nearest, tol) << "support point off the surface: " << p.transpose();
    }
    for (const Vec3& d : directions) {
      double reach = -std::numeric_limits<double>::infinity(), sampled = reach;
      for (const Vec3& p : supports) reach = std::max(reach, d.dot(p));
      for (const Vec3& s : inCell) sampled = std::max(sampled, d.dot(s));
      EXPECT_GE(reach, sampled - tol) << "node " << cell.node << " direction " << d.transpose();
    }
  }
  EXPECT_GT(checkedCells, test::sanitizerRun() ? 4 : 20);
}

}  // namespace
}  // namespace clod
