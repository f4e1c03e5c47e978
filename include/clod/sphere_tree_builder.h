#pragma once
// Building sphere-trees (sphere_tree.h) from a mesh, and measuring how well they fit.

#include <cstdint>
#include <vector>

#include "clod/mesh.h"
#include "clod/sphere_tree.h"

namespace clod {

class MeshDistance;

enum class SphereTreeMethod : std::uint8_t {
  kOctree = 0,  ///< Hubbard's basic method: spheres around occupied octree cells, shrunk to fit
  kMedial = 1,  ///< medial-axis approximation (Hubbard; Bradshaw & O'Sullivan)
};

/// "octree" or "medial".
const char* sphereTreeMethodName(SphereTreeMethod method) noexcept;

struct SphereTreeSettings {
  SphereTreeMethod method = SphereTreeMethod::kMedial;
  std::uint32_t branching = 8;  ///< maximum children per sphere
  std::uint32_t depth = 4;      ///< levels below the root (the tree has depth + 1 levels)
};

/// Builds a sphere-tree. Throws clod::Error(kInvalidArgument) for out-of-range settings.
SphereTree buildSphereTree(const MeshDistance& mesh, const SphereTreeSettings& settings);

/// Fit of one level: for every sphere, the greatest distance from its surface to the
/// surface it bounds ("overshoot"), in units of the mesh's bounding-box diagonal.
struct SphereTreeLevelFit {
  std::uint32_t spheres = 0;
  double fitMean = 0.0;
  double fitMax = 0.0;
};

std::vector<SphereTreeLevelFit> measureSphereTreeFit(const SphereTree& tree, const MeshDistance& mesh);

}  // namespace clod
