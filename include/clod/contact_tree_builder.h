#pragma once
// Building a contact tree (contact_tree.h) from the exact signed distance of a mesh.
//
// The octree covers the mesh's bounding box enlarged by cubeMarginRel * diagonal on every side,
// made cubic. A cell is refined while the trilinear interpolation of its corner values differs
// from the exact signed distance by more than errorRel * diagonal at any of its test points that
// lie in the band |d| <= bandRel * diagonal (+ half the cell size, so every band point is near
// a counted test point), and maxDepth is not reached. Cells whose corners prove (by the
// 1-Lipschitz property of a distance) that no point of the cell is within the band are not
// measured and not refined. docs/contact-tree.md has the argument for every threshold.
//
// The build runs level by level; each level's cells are processed in parallel with TBB, and
// the result does not depend on the number of threads (breadth-first order, deterministic).

#include <cstdint>

#include "clod/contact_tree.h"

namespace clod {

class MeshDistance;

struct ContactTreeSettings {
  /// eps_s, relative to the mesh's bounding-box diagonal. Must be finite and >= 1e-6 (the
  /// stored values are integers of steps of eps_s / 8 or finer, see ContactTree::valueStep).
  double errorRel = 1e-3;
  /// Deepest allowed node (the root has depth 0). 1..20.
  std::uint32_t maxDepth = 12;
  /// Half-width of the band around the surface in which eps_s must hold, relative to the
  /// diagonal. Contact margins and penetrations live there. Finite, >= 0.
  double bandRel = 0.01;
  /// Margin between the mesh's bounding box and the root cube, relative to the diagonal.
  /// Must be > bandRel so that the whole band lies inside the root cube.
  double cubeMarginRel = 0.02;
  /// Where the exact field is not 1-Lipschitz (the sign of an open mesh flips across the
  /// generalised-winding-number membrane that spans a hole, or a pseudonormal sign tie), no
  /// refinement can reach eps_s; such cells are refined only while their diagonal exceeds
  /// discontinuityStopRel * diagonal, and keep their (large, measured) error bound.
  double discontinuityStopRel = 0.004;
  /// At most this many nodes (0: no limit). The builder checks it before it adds each cell's
  /// children and throws Error(kResourceLimit) naming it; building takes ~175 bytes per node at
  /// its peak (measured on bunny-1500 at 0.4-3.5 M nodes). bakeMesh derives it from
  /// BakeSettings::maxMemoryBytes.
  std::uint64_t maxNodes = 0;
};

/// What the builder did; for logs, tests and benchmarks.
struct ContactTreeBuildStats {
  std::uint64_t nodes = 0;
  std::uint64_t leaves = 0;
  std::uint64_t surfaceCells = 0;        ///< nodes with a half-space
  std::uint64_t measuredCells = 0;       ///< cells whose error was measured at test points
  std::uint64_t distanceQueries = 0;     ///< exact signed-distance evaluations
  std::uint64_t leavesAboveError = 0;    ///< band leaves that hit maxDepth with error > eps_s
  std::uint64_t discontinuousCells = 0;  ///< measured cells where the field is not 1-Lipschitz
  double maxBandLeafError = 0.0;         ///< largest measured band error of any leaf (abs)
};

/// Builds the contact tree of the mesh held by `distance` (its signMethod() decides the sign:
/// pseudonormals for closed meshes, winding numbers for open ones). For an open mesh or one of
/// several parts the field is the signed distance to the solid's boundary: faces with the solid
/// on both sides (walls where parts overlap) are left out (solidBoundary), and where
/// any is, the sign is the winding number's (overlapping parts defeat pseudonormals). O(cells * test points *
/// exact-query cost); parallel. Throws clod::Error(kInvalidArgument) naming the setting when a
/// setting is out of range. The mesh itself was validated when `distance` was built.
ContactTree buildContactTree(const MeshDistance& distance, const ContactTreeSettings& settings = {},
                             ContactTreeBuildStats* stats = nullptr);

}  // namespace clod
