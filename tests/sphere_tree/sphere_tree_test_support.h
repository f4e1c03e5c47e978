#pragma once
// Helpers shared by the sphere-tree tests: test-side oracles that do not use the builders' code.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "clod/mesh.h"
#include "clod/sphere_tree.h"
#include "support/test_scale.h"

namespace clod::test {

/// Test name for a mesh file parameter: "rocker-arm.obj" -> "rocker_arm".
inline std::string meshParamName(const ::testing::TestParamInfo<const char*>& param) {
  std::string n = param.param;
  n = n.substr(0, n.find('.'));
  std::replace(n.begin(), n.end(), '-', '_');
  return n;
}

/// Uniform area-weighted random points on the surface, plus every vertex and edge midpoint.
inline std::vector<Vec3> sampleSurfaceUniformly(const TriangleMesh& mesh, std::size_t count, std::uint32_t seed) {
  std::vector<double> cumulative(mesh.triangleCount());
  double total = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) cumulative[t] = (total += mesh.triangleArea(t));
  std::vector<Vec3> points(mesh.vertices.begin(), mesh.vertices.end());
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) points.push_back(0.5 * (mesh.corner(t, k) + mesh.corner(t, (k + 1) % 3)));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (std::size_t i = 0; i < count && total > 0.0; ++i) {
    const double pick = uniform(rng) * total;
    const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), pick);
    const auto t = static_cast<std::uint32_t>(std::min<std::ptrdiff_t>(it - cumulative.begin(), mesh.triangleCount() - 1));
    // Uniform point in a triangle: sqrt-warped barycentrics (Osada et al. 2002).
    const double r1 = std::sqrt(uniform(rng)), r2 = uniform(rng);
    points.push_back((1.0 - r1) * mesh.corner(t, 0) + r1 * (1.0 - r2) * mesh.corner(t, 1) + r1 * r2 * mesh.corner(t, 2));
  }
  return points;
}

/// Spheres of one level binned in a uniform grid, so that "is p inside some sphere of the level"
/// is a handful of direct |p - c| <= r checks instead of a scan of the whole level.
class LevelSphereIndex {
public:
  LevelSphereIndex(const SphereTree& tree, std::uint32_t level) : tree_(tree) {
    Aabb box;
    for (std::uint32_t s = tree.levelBegin(level); s < tree.levelEnd(level); ++s) {
      box.extend(Vec3(tree.center(s).array() - tree.radius[s]));
      box.extend(Vec3(tree.center(s).array() + tree.radius[s]));
    }
    lo_ = box.min;
    const int res = 24;
    cell_ = std::max(box.extent().maxCoeff() / res, 1e-300);
    for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, static_cast<int>(box.extent()[a] / cell_) + 1);
    bins_.resize(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2]);
    for (std::uint32_t s = tree.levelBegin(level); s < tree.levelEnd(level); ++s) {
      int a0[3], a1[3];
      for (int a = 0; a < 3; ++a) {
        a0[a] = clampCell(a, (tree.center(s)[a] - tree.radius[s] - lo_[a]) / cell_);
        a1[a] = clampCell(a, (tree.center(s)[a] + tree.radius[s] - lo_[a]) / cell_);
      }
      for (int z = a0[2]; z <= a1[2]; ++z)
        for (int y = a0[1]; y <= a1[1]; ++y)
          for (int x = a0[0]; x <= a1[0]; ++x) bins_[index(x, y, z)].push_back(s);
    }
  }

  /// Whether p lies inside (or on) at least one sphere of the level.
  bool covers(const Vec3& p) const {
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const double f = (p[a] - lo_[a]) / cell_;
      if (f < 0.0 || f >= dims_[a]) return false;  // outside every sphere's box
      c[a] = clampCell(a, f);
    }
    for (std::uint32_t s : bins_[index(c[0], c[1], c[2])])
      if ((p - tree_.center(s)).norm() <= tree_.radius[s]) return true;
    return false;
  }

private:
  int clampCell(int axis, double f) const { return std::clamp(static_cast<int>(std::floor(f)), 0, dims_[axis] - 1); }
  std::size_t index(int x, int y, int z) const { return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x; }

  const SphereTree& tree_;
  Vec3 lo_;
  double cell_;
  int dims_[3];
  std::vector<std::vector<std::uint32_t>> bins_;
};

}  // namespace clod::test
