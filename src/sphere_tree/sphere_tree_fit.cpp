// Fit metric of sphere-trees, after Bradshaw's toolkit: the overshoot of a sphere is estimated
// at points on its surface as the distance to the closest point of the geometry it bounds.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <tbb/parallel_for.h>

#include "clod/error.h"
#include "clod/proximity.h"
#include "clod/sphere_tree_builder.h"

namespace clod {
namespace {

void checkTree(const SphereTree& tree, std::uint32_t triangleCount) {
  const std::size_t n = tree.radius.size();
  auto bad = [](const std::string& what) { return Error(ErrorCode::kInvalidArgument, "sphere-tree: " + what); };
  if (tree.centerX.size() != n || tree.centerY.size() != n || tree.centerZ.size() != n || tree.parent.size() != n ||
      tree.firstChild.size() != n || tree.childCount.size() != n || tree.triangleOffsets.size() != n + 1)
    throw bad("per-sphere arrays have different lengths");
  if (tree.levelOffsets.empty() || tree.levelOffsets.front() != 0 || tree.levelOffsets.back() != n)
    throw bad("level offsets do not span the spheres");
  if (tree.triangleOffsets.front() != 0 || tree.triangleOffsets.back() != tree.triangleList.size())
    throw bad("triangle offsets do not span the triangle list");
  for (std::size_t i = 0; i < n; ++i) {
    if (tree.triangleOffsets[i + 1] <= tree.triangleOffsets[i])
      throw bad("sphere " + std::to_string(i) + " has no triangles");
    if (!std::isfinite(tree.radius[i]) || tree.radius[i] < 0.0)
      throw bad("sphere " + std::to_string(i) + " has radius " + std::to_string(tree.radius[i]));
  }
  for (std::size_t k = 0; k < tree.triangleList.size(); ++k)
    if (tree.triangleList[k] >= triangleCount)
      throw bad("triangle index " + std::to_string(tree.triangleList[k]) + " >= triangle count " +
                std::to_string(triangleCount));
}

}  // namespace

std::vector<double> measureSphereFits(const SphereTree& tree, const MeshDistance& mesh,
                                      const SphereFitSettings& settings) {
  if (settings.samplesPerSphere < 1 || settings.samplesPerSphere > 100000)
    throw Error(ErrorCode::kInvalidArgument, "sphere fit samplesPerSphere " +
                                                 std::to_string(settings.samplesPerSphere) +
                                                 " is out of range [1, 100000]");
  checkTree(tree, mesh.mesh().triangleCount());
  const double diagonal = mesh.mesh().bounds().diagonal();
  // Spherical Fibonacci points (Keinert et al. 2015): near-uniform, any count.
  const std::uint32_t count = settings.samplesPerSphere;
  std::vector<Vec3> directions(count);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (std::uint32_t i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    directions[i] = Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  std::vector<double> fits(tree.sphereCount(), 0.0);
  tbb::parallel_for(std::uint32_t{0}, tree.sphereCount(), [&](std::uint32_t s) {
    const Vec3 c = tree.center(s);
    double worst = 0.0;
    for (const Vec3& d : directions)
      worst = std::max(worst, mesh.closestPointAmong(c + tree.radius[s] * d, tree.triangles(s)).distance);
    fits[s] = diagonal > 0.0 ? worst / diagonal : 0.0;
  });
  return fits;
}

std::vector<SphereTreeLevelFit> measureSphereTreeFit(const SphereTree& tree, const MeshDistance& mesh,
                                                     const SphereFitSettings& settings) {
  const std::vector<double> fits = measureSphereFits(tree, mesh, settings);
  std::vector<SphereTreeLevelFit> levels(tree.levelCount());
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    SphereTreeLevelFit& level = levels[l];
    level.spheres = tree.levelEnd(l) - tree.levelBegin(l);
    double sum = 0.0;
    for (std::uint32_t s = tree.levelBegin(l); s < tree.levelEnd(l); ++s) {
      sum += fits[s];
      level.fitMax = std::max(level.fitMax, fits[s]);
    }
    level.fitMean = level.spheres > 0 ? sum / level.spheres : 0.0;
  }
  return levels;
}

std::vector<SphereTreeLevelFit> measureSphereTreeFit(const SphereTree& tree, const MeshDistance& mesh) {
  return measureSphereTreeFit(tree, mesh, SphereFitSettings{});
}

}  // namespace clod
