#pragma once
// The part both builders share: grow a sphere-tree top-down, level by level, from a root node
// that holds the whole surface as pieces. A method only says how to split one node's pieces
// into at most `branching` children, each with a sphere; this driver then makes every sphere
// contain all corners of its pieces (exact coverage), lays the levels out breadth-first and
// fills the per-sphere triangle lists.

#include <cstdint>
#include <functional>
#include <vector>

#include "clod/mesh.h"
#include "clod/sphere_tree.h"
#include "min_sphere.h"
#include "surface_piece.h"

namespace clod::detail {

struct BuildNode {
  Sphere sphere;
  std::vector<SurfacePiece> pieces;
  /// The octree cell of the node (octree builder only).
  Vec3 cellLo = Vec3::Zero();
  Vec3 cellHi = Vec3::Zero();
};

/// Splits `parent` (on level `level`, position `indexInLevel`) into 1..branching children,
/// each with at least one piece; every piece of the parent (or a sub-piece of it after further
/// clipping) must go to some child. Must be safe to call concurrently for different parents.
using SplitNode = std::function<void(const BuildNode& parent, std::uint32_t level, std::uint32_t indexInLevel,
                                     std::vector<BuildNode>& children)>;

/// Relative radius inflation that absorbs rounding in the containment of piece corners:
/// radii are grown by kCoverageSlackRel * (bounding-box diagonal) after the exact fit.
inline constexpr double kCoverageSlackRel = 1e-9;

/// Builds `depth` levels below `root`. The root sphere is taken as given and then also grown to
/// contain every corner of its pieces.
SphereTree buildTopDown(const TriangleMesh& mesh, BuildNode root, std::uint32_t depth, std::uint32_t branching,
                        const SplitNode& split);

}  // namespace clod::detail
