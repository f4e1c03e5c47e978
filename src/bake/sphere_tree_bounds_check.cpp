#include "sphere_tree_bounds_check.h"

#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace clod::detail {
namespace {

std::string str(std::uint64_t value) { return std::to_string(value); }

std::string num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

// How far `p` lies outside sphere i (negative inside).
double outside(const SphereTree& tree, std::uint32_t i, const Vec3& p) { return (p - tree.center(i)).norm() - tree.radius[i]; }

}  // namespace

void checkSphereTreeBoundsMesh(const SphereTree& tree, const TriangleMesh& mesh, const Complaint& complain) {
  const double tolerance = kSphereBoundsToleranceRel * mesh.bounds().diagonal();
  const std::uint32_t triangleCount = mesh.triangleCount();
  auto describe = [&](std::uint32_t sphere, std::uint32_t level, std::uint32_t t, int k, double by) {
    return "sphere " + str(sphere) + " (level " + str(level) + ") does not contain vertex " + str(mesh.triangles[t][k]) +
           " of triangle " + str(t) + ": it lies " + num(by) + " outside the radius " + num(tree.radius[sphere]) +
           " (tolerance " + num(tolerance) + "); the tree does not bound the mesh";
  };

  // The root alone, over every triangle: the check a moved root fails, with the plainest message.
  for (std::uint32_t t = 0; t < triangleCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      const double by = outside(tree, 0, mesh.corner(t, k));
      if (!(by <= tolerance)) complain(describe(0, 0, t, k, by));
    }
  }

  // Per level: stamp each triangle corner with the level on which some listing sphere contains
  // it, and each triangle with the level that lists it; stamps avoid clearing between levels.
  constexpr std::uint32_t kNever = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> cornerCovered(std::size_t{3} * triangleCount, kNever), listed(triangleCount, kNever);
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    const std::uint32_t begin = tree.levelBegin(l), end = tree.levelEnd(l);
    for (std::uint32_t i = begin; i < end; ++i) {
      for (std::uint32_t k = tree.triangleOffsets[i]; k < tree.triangleOffsets[i + 1]; ++k) {
        const std::uint32_t t = tree.triangleList[k];
        listed[t] = l;
        for (int c = 0; c < 3; ++c)
          if (outside(tree, i, mesh.corner(t, c)) <= tolerance) cornerCovered[3 * std::size_t{t} + c] = l;
      }
    }
    for (std::uint32_t t = 0; t < triangleCount; ++t) {
      if (listed[t] != l) complain("no sphere of level " + str(l) + " lists triangle " + str(t) + ": the level does not cover the mesh");
      for (int c = 0; c < 3; ++c) {
        if (cornerCovered[3 * std::size_t{t} + c] == l) continue;
        // Failure path only: name the listing sphere that comes nearest.
        std::uint32_t nearest = begin;
        double best = std::numeric_limits<double>::infinity();
        for (std::uint32_t i = begin; i < end; ++i) {
          for (std::uint32_t k = tree.triangleOffsets[i]; k < tree.triangleOffsets[i + 1]; ++k) {
            if (tree.triangleList[k] != t) continue;
            const double by = outside(tree, i, mesh.corner(t, c));
            if (by < best) {
              best = by;
              nearest = i;
            }
          }
        }
        complain(describe(nearest, l, t, c, best));
      }
    }
  }
}

}  // namespace clod::detail
