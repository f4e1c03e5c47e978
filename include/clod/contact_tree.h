#pragma once
// Contact trees (Kaufman, Sueda & Pai, "Contact Trees: Adaptive Contact Sampling for Robust
// Dynamics", SIGGRAPH 2007 sketch): an adaptively sampled signed distance field (Frisken et al.
// 2000) on an octree, whose cells double as a sphere bounding-volume hierarchy, with a per-node
// interpolation error bound and, for cells the surface crosses, a half-space approximating the
// zero level set inside the cell.
//
// This header holds the built, immutable structure and its queries. Building it is in
// contact_tree_builder.h, contact generation between two trees in contact_sampling.h, and the
// bake-file encoding in contact_tree_codec.h. Design choices the paper leaves open (refinement
// test, error definition, band, half-space fit) are written up in docs/contact-tree.md.
//
// Frames and units: everything is in the body frame of the mesh the tree was built from, in the
// mesh's length unit. Signed distance is negative inside.
//
// Layout (flat arrays, 32-bit indices, breadth-first):
//  * Node 0 is the root cell, the cube [origin, origin + rootSize]^3. The eight children of an
//    interior node are contiguous, starting at firstChild[node]; child k covers octant k, where
//    bit 0 of k selects the upper half in x, bit 1 in y and bit 2 in z. Leaves have firstChild 0
//    (no node has the root as a child). Nodes of depth d are [levelOffsets[d], levelOffsets[d+1]).
//  * Corner values are shared: the root's 8 corner distances are in rootCorners; an interior
//    node splitting its cell introduces the 3x3x3 lattice of its children's corners, of which the
//    8 cell corners are already known, so it stores only the 19 new values, once, however many
//    children share them (values lattice[19*b .. 19*b+19), b = (firstChild - 1) / 8, in lattice
//    order i + 3j + 9k with the 8 even-even-even points left out). A query inherits a cell's
//    corners from its parent while descending: 8 float loads per level, no indirection table.
//  * errorBound, halfSpaceIndex: one entry per node. halfSpaces: one entry per surface cell.
//
// Cells are half-open: a point on a face shared by two cells belongs to the upper one, except
// on the root cube's upper faces, which belong to the root.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "clod/math.h"

namespace clod {

/// halfSpaceIndex value of a node the surface does not cross.
inline constexpr std::uint32_t kNoHalfSpace = 0xffffffffu;
/// Pass as maxDepth to descend to the leaf.
inline constexpr std::uint32_t kContactTreeLeafDepth = 0xffffffffu;
/// Number of lattice values an interior node stores (27 lattice points minus its 8 corners).
inline constexpr std::uint32_t kContactTreeLatticePerNode = 19;

/// Plane approximating the zero level set inside one cell, to first order, in the body frame
/// relative to the cell centre c: the plane is {x : normal . (x - c) = offset}, the body is on
/// the side normal . (x - c) < offset. normal is a unit vector (outward).
struct ContactHalfSpace {
  std::array<float, 3> normal;
  float offset;
  /// Largest |plane distance - exact signed distance| over the cell's 3x3x3 lattice points
  /// within one cell diagonal of the surface: how planar the surface is in the cell. 0 for a
  /// flat face; of the order of the cell size where an edge or corner crosses the cell.
  float fitError;
};

/// A node together with the geometry a traversal derives on the way down (nothing of this is
/// stored per node). Obtain from ContactTree::rootCell() / childCell().
struct ContactCell {
  std::uint32_t node = 0;
  std::uint32_t depth = 0;
  /// Integer position of the cell among the 2^depth cells per axis of its depth.
  std::array<std::uint32_t, 3> index{0, 0, 0};
  /// Signed distances at the 8 corners (corner k: bit 0 = +x, bit 1 = +y, bit 2 = +z).
  std::array<float, 8> corners{};
};

/// Result of ContactTree::sample().
struct ContactFieldSample {
  /// Trilinear interpolation of the corner distances of the cell the query stopped in
  /// (negative inside).
  double distance = 0.0;
  /// Gradient of that trilinear interpolant (body frame; not normalised, length ~1 near the
  /// surface). Zero only where the interpolant is flat.
  Vec3 gradient = Vec3::Zero();
  /// The stopping node's error bound (see ContactTree::errorBound); outside the root cube it
  /// also includes twice the distance to the cube.
  double errorBound = 0.0;
  std::uint32_t node = 0;
  std::uint32_t depth = 0;
  /// False when the query point lay outside the root cube (see ContactTree::sample).
  bool insideRoot = true;
};

/// A built contact tree. Plain data: the builder fills it, the bake file stores it as is, and
/// any number of threads may query it concurrently (every query is const and allocation-free).
struct ContactTree {
  // --- Geometry of the root cube and the build parameters (body frame, mesh units) ---------
  Vec3 origin = Vec3::Zero();  ///< lower corner of the root cube
  double rootSize = 0.0;       ///< side length of the root cube
  double meshDiagonal = 0.0;   ///< bounding-box diagonal of the mesh it was built from
  double errorAbs = 0.0;       ///< eps_s: the refinement target for the interpolation error
  double bandAbs = 0.0;        ///< half-width of the band around the surface where eps_s holds
  std::uint32_t maxDepth = 0;  ///< the depth limit the builder was given

  // --- Per node (breadth-first) ------------------------------------------------------------
  std::array<float, 8> rootCorners{};
  std::vector<std::uint32_t> firstChild;  ///< 0 for a leaf
  /// Interpolation error bound of the node's cell: the largest |trilinear - exact| measured at
  /// the cell's test points (docs/contact-tree.md: 3x3x3 lattice + 8 octant centres), or, for a
  /// cell the builder proved far from the surface without measuring, the Lipschitz bound of
  /// half the cell diagonal, which holds everywhere in the cell for any 1-Lipschitz field.
  /// This is what a query stopped at this node reports, and what graceful degradation uses.
  std::vector<float> errorBound;
  std::vector<std::uint32_t> halfSpaceIndex;  ///< into halfSpaces, or kNoHalfSpace
  std::vector<std::uint32_t> levelOffsets;    ///< size depthCount() + 1

  // --- Shared pools ------------------------------------------------------------------------
  std::vector<float> lattice;                ///< 19 values per interior node, see above
  std::vector<ContactHalfSpace> halfSpaces;  ///< one per surface cell

  // --- Derived lookup grid (an accelerator; not stored in the bake file) ----------------------
  // A dense grid over the cells of depth gridDepth lets sample() start its descent there
  // instead of at the root, skipping gridDepth dependent loads per query. It is derived from
  // the arrays above by buildLookupGrid(), which buildContactTree and decodeContactTree call;
  // without it (gridDepth 0) queries descend from the root and return the same values.
  std::uint32_t gridDepth = 0;
  /// (2^gridDepth)^3 entries, x fastest: the node of depth gridDepth covering the grid cell, or
  /// 0 where the tree ends above gridDepth (such queries descend from the root).
  std::vector<std::uint32_t> gridNode;
  /// (2^gridDepth + 1)^3 corner values of the grid cells that exist as nodes (x fastest);
  /// entries no such node touches are 0 and never read.
  std::vector<float> gridCorners;
  /// (Re)derives gridDepth, gridNode and gridCorners from the node arrays: gridDepth is the
  /// largest d <= 3 with d < depthCount() and 8^d <= nodeCount() / 8 (a deeper grid measured
  /// slower: it falls out of the L1 cache), so the grid costs at most ~5 KiB.
  /// O(8^gridDepth). Precondition: a valid tree.
  void buildLookupGrid();

  // --- Size ---------------------------------------------------------------------------------
  std::uint32_t nodeCount() const { return static_cast<std::uint32_t>(firstChild.size()); }
  /// Number of depths present (the deepest leaf's depth + 1); 0 for an empty tree.
  std::uint32_t depthCount() const {
    return levelOffsets.empty() ? 0 : static_cast<std::uint32_t>(levelOffsets.size() - 1);
  }
  bool isLeaf(std::uint32_t node) const { return firstChild[node] == 0; }
  /// Bytes held by the arrays, lookup grid included (excluding vector capacity slack and the
  /// struct itself).
  std::size_t memoryBytes() const;

  // --- Cell geometry (O(1)) -----------------------------------------------------------------
  /// Side length of cells at `depth`.
  double cellSize(std::uint32_t depth) const { return rootSize / static_cast<double>(1ull << depth); }
  /// Lower corner of a cell.
  Vec3 cellMin(const ContactCell& cell) const {
    const double h = cellSize(cell.depth);
    return origin + h * Vec3(cell.index[0], cell.index[1], cell.index[2]);
  }
  /// Centre of the cell: also the centre of its bounding sphere.
  Vec3 cellCenter(const ContactCell& cell) const {
    return cellMin(cell) + Vec3::Constant(0.5 * cellSize(cell.depth));
  }
  /// Radius of the cell's bounding sphere: half the cell diagonal, the tightest sphere that
  /// contains the cube (docs/contact-tree.md says why the sphere bounds the cell, not the
  /// surface patch).
  double cellRadius(std::uint32_t depth) const { return 0.8660254037844386 * cellSize(depth); }

  // --- Navigation (O(1)) --------------------------------------------------------------------
  /// The root cell with its corner values. Precondition: nodeCount() > 0.
  ContactCell rootCell() const;
  /// Child `octant` (0..7) of an interior cell, with its corner values.
  /// Precondition: !isLeaf(cell.node), octant < 8.
  ContactCell childCell(const ContactCell& cell, std::uint32_t octant) const;
  /// The half-space of a surface cell, or nullptr if the surface does not cross the cell.
  const ContactHalfSpace* halfSpace(std::uint32_t node) const {
    const std::uint32_t i = halfSpaceIndex[node];
    return i == kNoHalfSpace ? nullptr : &halfSpaces[i];
  }
  /// Lower bound of the true signed distance anywhere in the cell: the smallest corner value
  /// minus the node's error bound (the trilinear interpolant is never below its smallest
  /// corner). A cell with minDistance(cell) > m holds no point of the body or of its m-band.
  double minDistance(const ContactCell& cell) const;
  /// Upper bound counterpart of minDistance: largest corner plus the error bound.
  double maxDistance(const ContactCell& cell) const;

  // --- Field queries --------------------------------------------------------------------------
  /// Signed distance and gradient at p (body frame) by trilinear interpolation in the cell that
  /// contains p at depth min(leaf depth, maxDepth): pass a small maxDepth to stop early and get
  /// a coarser answer with its (larger) error bound. O(depth), no allocation.
  ///
  /// Inside the root cube, |distance - exact| <= errorBound wherever the builder measured it
  /// (docs/contact-tree.md: within the band it is <= errorAbs at the leaves by construction).
  /// Outside the root cube (the mesh is strictly inside it), p is clamped to the cube at q,
  /// and the result is distance(q) + |p - q| -- an upper bound of the exact distance -- with
  /// errorBound(q) + 2|p - q|, the gradient at q, and insideRoot = false. Never NaN for
  /// finite p; a non-finite p is a precondition violation.
  ContactFieldSample sample(const Vec3& p, std::uint32_t maxDepth = kContactTreeLeafDepth) const;

  /// The cell that sample(p, maxDepth) interpolates in, with its corner values (p clamped to
  /// the root cube first). O(depth), no allocation. Precondition: p finite.
  ContactCell cellAt(const Vec3& p, std::uint32_t maxDepth = kContactTreeLeafDepth) const;

  /// Just the signed distance of sample(p).
  double distance(const Vec3& p) const { return sample(p).distance; }
};

/// Trilinear interpolation of corner values at local coordinates t in [0,1]^3 within a cell;
/// returns the value and writes the gradient with respect to t (divide by the cell size for
/// the body-frame gradient).
double interpolateTrilinear(const std::array<float, 8>& corners, const Vec3& t, Vec3* gradientLocal) noexcept;

}  // namespace clod
