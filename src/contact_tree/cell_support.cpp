#include "clod/cell_support.h"

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "geometry/convex_hull.h"

namespace clod {
namespace {

// Directions of a 9 x 9 grid on each face of the cube [-1, 1]^3, without repeats (386): no
// direction is farther than ~4.5 degrees from one of them, so the support point found for the
// nearest one lies within r (1 - cos 4.5 deg) ~ 0.3 % of the local radius of curvature r below
// the true one. (Unnormalised: only the order of points along each matters.)
std::vector<Vec3> supportDirections() {
  std::vector<Vec3> dirs;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0})
      for (int i = -4; i <= 4; ++i)
        for (int j = -4; j <= 4; ++j) {
          Vec3 d;
          d[axis] = sign;
          d[(axis + 1) % 3] = 0.25 * i;
          d[(axis + 2) % 3] = 0.25 * j;
          bool repeat = false;
          for (const Vec3& e : dirs) repeat = repeat || e == d;
          if (!repeat) dirs.push_back(d);
        }
  return dirs;
}

// Clips polygon `poly` (in place) to the half-space sign * (p[axis] - bound) <= 0.
void clipPolygon(std::vector<Vec3>& poly, std::vector<Vec3>& scratch, int axis, double bound, double sign) {
  scratch.clear();
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& p = poly[i];
    const Vec3& q = poly[(i + 1) % n];
    const double dp = sign * (p[axis] - bound), dq = sign * (q[axis] - bound);
    if (dp <= 0.0) scratch.push_back(p);
    if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) {
      Vec3 x = p + (dp / (dp - dq)) * (q - p);
      x[axis] = bound;  // exactly on the face, whatever the rounding
      scratch.push_back(x);
    }
  }
  poly.swap(scratch);
}

// Appends p unless `out` holds it already (the few hundred points of a cell keep their order).
void appendUnique(std::vector<Vec3>& out, const Vec3& p) {
  for (const Vec3& q : out)
    if (q == p) return;
  out.push_back(p);
}

// A cell whose clipped surface's hull has more vertices keeps the grid's extremes alone.
constexpr std::size_t kMaxCellHullVertices = 4096;

struct Builder {
  const ContactTree& tree;
  const TriangleMesh& mesh;
  std::uint32_t maxDepth;
  std::vector<std::vector<Vec3>>& perNode;
  std::vector<Vec3> dirs;
  std::vector<Vec3> poly, scratch;
  std::vector<double> best;
  std::vector<Vec3> arg;
  std::vector<Vec3> clipped;  // the corners of the cell's clipped triangles
  std::vector<std::uint32_t> hull;

  void visit(const ContactCell& cell, const std::vector<std::uint32_t>& triangles) {
    const Vec3 lo = tree.cellMin(cell);
    const Vec3 hi = lo + Vec3::Constant(tree.cellSize(cell.depth));
    best.assign(dirs.size(), -std::numeric_limits<double>::infinity());
    arg.resize(dirs.size());
    std::vector<std::uint32_t> inside;
    inside.reserve(triangles.size());
    clipped.clear();
    for (std::uint32_t t : triangles) {
      poly.assign({mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)});
      for (int axis = 0; axis < 3 && !poly.empty(); ++axis) {
        clipPolygon(poly, scratch, axis, hi[axis], 1.0);
        if (!poly.empty()) clipPolygon(poly, scratch, axis, lo[axis], -1.0);
      }
      if (poly.empty()) continue;
      inside.push_back(t);
      clipped.insert(clipped.end(), poly.begin(), poly.end());
      for (const Vec3& p : poly)
        for (std::size_t k = 0; k < dirs.size(); ++k) {
          const double s = dirs[k].dot(p);
          if (s > best[k]) best[k] = s, arg[k] = p;
        }
    }
    if (inside.empty()) return;
    std::vector<Vec3>& out = perNode[cell.node];
    for (const Vec3& p : arg) appendUnique(out, p);
    // Plus the vertices of the clipped surface's convex hull: every point extreme in some
    // direction, not only in the 386 of the grid. Near a floor's normal the grid's directions
    // picked the rim of each of spot's hooves, 4 mm above its lowest point (a nearly flat sole
    // tilted by less than the grid's 4.5 degrees), and an interrupted answer missed a front foot
    // 0.3 mm into the floor: spot toppled at 60 Hz (docs/contact-tree.md, "Support points").
    if (detail::convexHullVertices(clipped, kMaxCellHullVertices, hull))
      for (std::uint32_t id : hull) appendUnique(out, clipped[id]);
    if (cell.depth >= maxDepth || tree.isLeaf(cell.node)) return;
    for (std::uint32_t octant = 0; octant < 8; ++octant) visit(tree.childCell(cell, octant), inside);
  }
};

}  // namespace

void deriveCellSupports(ContactTree& tree, const TriangleMesh& mesh, std::uint32_t maxDepth) {
  tree.supportOffsets.clear();
  tree.supportPoints.clear();
  if (tree.nodeCount() == 0 || mesh.triangleCount() == 0) return;
  const std::uint32_t depths = std::min<std::uint32_t>(maxDepth + 1, tree.depthCount());
  const std::uint32_t nodes = tree.levelOffsets[depths];
  std::vector<std::vector<Vec3>> perNode(nodes);
  std::vector<std::uint32_t> all(mesh.triangleCount());
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) all[t] = t;
  Builder builder{tree, mesh, maxDepth, perNode, supportDirections(), {}, {}, {}, {}, {}, {}};
  builder.visit(tree.rootCell(), all);
  tree.supportOffsets.reserve(nodes + 1);
  tree.supportOffsets.push_back(0);
  for (const std::vector<Vec3>& points : perNode) {
    tree.supportPoints.insert(tree.supportPoints.end(), points.begin(), points.end());
    tree.supportOffsets.push_back(static_cast<std::uint32_t>(tree.supportPoints.size()));
  }
}

}  // namespace clod
