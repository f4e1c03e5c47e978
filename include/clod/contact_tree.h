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
// Layout (flat arrays, 32-bit indices, breadth-first; docs/contact-tree.md has the byte counts):
//  * Node 0 is the root cell, the cube [origin, origin + rootSize]^3. The eight children of an
//    interior node are contiguous; child k covers octant k, where bit 0 of k selects the upper
//    half in x, bit 1 in y and bit 2 in z. Nodes of depth d are [levelOffsets[d],
//    levelOffsets[d+1]).
//  * Tree shape as a bitmap with rank counts (nodeWords): bit i of the interior bitmap is set
//    when node i is split. Because the layout is breadth-first, the children of the k-th
//    interior node (counting from 0 in node order) start at node 1 + 8k, so firstChild(i) is a
//    rank query -- one 24-byte word per 64 nodes (3 bits per node) instead of a 32-bit child
//    index. A second bitmap marks surface cells, whose half-space is halfSpaces[rank].
//  * Corner values are shared: the root's 8 corner distances are in rootCorners; an interior
//    node splitting its cell introduces the 3x3x3 lattice of its children's corners, of which the
//    8 cell corners are already known, so it stores only the 19 new values, once, however many
//    children share them (values lattice[19*k .. 19*k+19) for the k-th interior node, in lattice
//    order i + 3j + 9k with the 8 even-even-even points left out). A query inherits a cell's
//    corners from its parent while descending: no indirection table.
//  * errorCode: one 16-bit entry per node, the node's error bound as a fraction of its cell's
//    bounding-sphere radius, rounded up (see errorBound()).
//
// Cells are half-open: a point on a face shared by two cells belongs to the upper one, except
// on the root cube's upper faces, which belong to the root.

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "clod/bit_count.h"
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

/// 64 nodes' worth of the tree shape (see the layout comment of ContactTree): bit b of
/// `interior` / `surface` is node 64w + b; the counts are the set bits in all earlier words.
struct ContactTreeNodeWord {
  std::uint64_t interior = 0;
  std::uint64_t surface = 0;
  std::uint32_t interiorBefore = 0;
  std::uint32_t surfaceBefore = 0;
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

/// A built contact tree. Plain data: the builder fills it, the bake file stores its arrays, and
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
  /// Shape and surface bitmaps with rank counts, one word per 64 nodes (see the layout above).
  std::vector<ContactTreeNodeWord> nodeWords;
  /// Per node: its error bound divided by cellRadius(depth), as the upper 16 bits of an IEEE
  /// float (sign 0, 8-bit exponent, 7-bit mantissa) rounded up to kErrorMantissaBits mantissa
  /// bits (the low bits zero), so that the decoded bound is never below the builder's and at
  /// most 2^-3 (12.5 %) above it; or farErrorCode(depth) (just above 1.0, all 7 mantissa bits),
  /// the Lipschitz bound of half the cell diagonal plus the value rounding q/2, which caps
  /// every bound except in cells where the builder found the field discontinuous (open meshes,
  /// docs/contact-tree.md). Use errorBound().
  std::vector<std::uint16_t> errorCode;
  std::vector<std::uint32_t> levelOffsets;  ///< size depthCount() + 1

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
  /// largest d <= depthCap with d < depthCount() and 8^d <= nodeCount() / 8, so the grid's
  /// node entries never outnumber an eighth of the nodes; the default cap 5 costs at most
  /// 268 KiB (docs/benchmarks/contact_tree.md compares depths: with the 3-bit-per-node shape
  /// bitmap the descent below the grid stays in L2, and depth 5 was the fastest).
  /// O(8^gridDepth). Precondition: a valid tree, depthCap <= 8.
  void buildLookupGrid(std::uint32_t depthCap = 5);

  /// Derived bitmap (not stored in the bake file), one bit per node: the surface crossing the
  /// cell is one plane, the cell's half-space, within errorAbs. A leaf is flat when its
  /// half-space's fitError <= errorAbs; an inner cell when it has a half-space, at least one
  /// surface child, and every surface child is flat and lies on its plane (normals within
  /// errorAbs / cell size, plane points within errorAbs). A traversal may stop at such a cell
  /// as at a leaf: its children would only sample the same plane. Filled by
  /// deriveFlatSurfaces(), which buildContactTree and decodeContactTree call.
  std::vector<std::uint64_t> flatSurface;
  void deriveFlatSurfaces();

  /// Derived from the mesh (not stored in the bake file; cell_support.h): the support points
  /// (body frame) of node n's part of the surface are supportPoints[supportOffsets[n] ..
  /// supportOffsets[n + 1]) for n + 1 < supportOffsets.size(); empty when not derived.
  std::vector<std::uint32_t> supportOffsets;
  std::vector<Vec3> supportPoints;
  /// The support points of `node` (empty beyond the derived depths). O(1).
  std::span<const Vec3> cellSupports(std::uint32_t node) const {
    if (std::size_t{node} + 1 >= supportOffsets.size()) return {};
    return {supportPoints.data() + supportOffsets[node], supportPoints.data() + supportOffsets[node + 1]};
  }
  /// True when deriveFlatSurfaces() marked `node` flat (false before it ran). O(1).
  bool isFlatSurface(std::uint32_t node) const {
    return (node >> 6) < flatSurface.size() && ((flatSurface[node >> 6] >> (node & 63)) & 1u) != 0;
  }

  // --- Quantisation (docs/contact-tree.md, "Compact storage") -------------------------------
  /// Step q of the stored lattice values: the largest power of two <= errorAbs / 8 (split
  /// cells larger than 32 errorAbs use finer steps, and half-space offsets steps of 1/1024 of
  /// their cell's, docs/contact-tree.md "Compact storage"). A lattice
  /// value is stored as its trilinear prediction from the cell's corners plus an integer
  /// number of q (the bake file stores the integer), so it differs from the exact distance by
  /// at most q / 2 <= errorAbs / 16, and a field that trilinear interpolation reproduces (a
  /// flat face) keeps its float precision. The builder measures its interpolation errors with
  /// these values, so the refinement test and the stored bounds include the rounding. The
  /// root corners are exact floats. Derived from errorAbs; 0 for a default-constructed tree.
  double valueStep() const;
  /// True when the corner values (of a cell of the given depth) prove, by the 1-Lipschitz
  /// property of a distance and allowing q/2 of rounding per corner, that no point of the cell
  /// lies within bandAbs of the surface. Such cells are never measured or split: they are
  /// leaves without a half-space whose bound is farErrorCode(depth). Both the builder and the
  /// decoder evaluate it (the bake file does not store what it decides). O(1).
  bool provenFar(const std::array<float, 8>& corners, std::uint32_t depth) const;
  /// errorCode of a proven-far leaf: the Lipschitz bound of a 1-Lipschitz field interpolated
  /// from values rounded by at most q/2, (D/2 + q/2) / (D/2), rounded up. Measured cells are
  /// capped by it too, except where the field is discontinuous. O(1).
  std::uint16_t farErrorCode(std::uint32_t depth) const;

  // --- Size ---------------------------------------------------------------------------------
  std::uint32_t nodeCount() const { return levelOffsets.empty() ? 0 : levelOffsets.back(); }
  /// Number of depths present (the deepest leaf's depth + 1); 0 for an empty tree.
  std::uint32_t depthCount() const {
    return levelOffsets.empty() ? 0 : static_cast<std::uint32_t>(levelOffsets.size() - 1);
  }
  /// True when `node` is not split. O(1). Precondition: node < nodeCount().
  bool isLeaf(std::uint32_t node) const { return ((nodeWords[node >> 6].interior >> (node & 63)) & 1u) == 0; }
  /// Index of the first of the eight children of `node`, or 0 for a leaf (no node has the
  /// root as a child). O(1): a rank query on the interior bitmap.
  std::uint32_t firstChild(std::uint32_t node) const {
    const ContactTreeNodeWord& w = nodeWords[node >> 6];
    const std::uint64_t upTo = w.interior & (~std::uint64_t{0} >> (63 - (node & 63)));
    if (((w.interior >> (node & 63)) & 1u) == 0) return 0;
    return 1 + 8 * (w.interiorBefore + detail::popcount64(upTo) - 1);
  }
  /// Index into halfSpaces of a surface cell's half-space, or kNoHalfSpace. O(1).
  std::uint32_t halfSpaceIndex(std::uint32_t node) const {
    const ContactTreeNodeWord& w = nodeWords[node >> 6];
    if (((w.surface >> (node & 63)) & 1u) == 0) return kNoHalfSpace;
    const std::uint64_t below = w.surface & ((std::uint64_t{1} << (node & 63)) - 1);
    return w.surfaceBefore + detail::popcount64(below);
  }
  /// Interpolation error bound of the node's cell, in mesh units: the largest |trilinear -
  /// exact| measured at the cell's test points times the gap factor (docs/contact-tree.md:
  /// 3x3x3 lattice + 8 octant centres), or, for a cell the builder proved far from the surface
  /// without measuring, the Lipschitz bound of half the cell diagonal (plus the value rounding
  /// q/2, see valueStep()), which holds everywhere in the cell for any 1-Lipschitz field;
  /// never more than that, except in cells where the field
  /// is discontinuous (open meshes: the measured bound, uncapped). Rounded up by at most 12.5 %
  /// (errorCode; the Lipschitz cap by at most 0.8 %). This is what a query stopped at this
  /// node reports, and what graceful degradation uses. `depth` must be the node's depth. O(1).
  double errorBound(std::uint32_t node, std::uint32_t depth) const {
    return decodeErrorRatio(errorCode[node]) * cellRadius(depth);
  }
  /// Mantissa bits an error code keeps (of a bfloat16's 7). Every measured bound is rounded
  /// up to them: the bake file then spends ~4 bits less per node, for bounds at most 12.5 %
  /// looser (docs/contact-tree.md, "Error bounds").
  static constexpr int kErrorMantissaBits = 3;
  /// The largest finite code with kErrorMantissaBits mantissa bits (~3.2e38).
  static constexpr std::uint16_t kMaxErrorCode = 0x7f70;
  /// The 16-bit code of a ratio bound / cell radius (upper half of its float), rounded up to
  /// `mantissaBits` (1..7) mantissa bits so that decodeErrorRatio(code) >= ratio; ratios
  /// beyond the range map to the largest finite code with those bits. Precondition:
  /// ratio >= 0, not NaN.
  static std::uint16_t encodeErrorRatio(double ratio, int mantissaBits = kErrorMantissaBits);
  /// True when `code` is one encodeErrorRatio makes with kErrorMantissaBits bits.
  static constexpr bool isCoarseErrorCode(std::uint16_t code) {
    return code <= kMaxErrorCode && (code & ((1u << (7 - kErrorMantissaBits)) - 1)) == 0;
  }
  /// Inverse of encodeErrorRatio: a float whose upper 16 bits are `code`.
  static float decodeErrorRatio(std::uint16_t code) {
    return std::bit_cast<float>(static_cast<std::uint32_t>(code) << 16);
  }
  /// Fills nodeWords from per-node flags (1 = split / surface cell), both nodeCount() long.
  /// O(nodeCount()).
  void assignNodeBits(const std::vector<std::uint8_t>& interior, const std::vector<std::uint8_t>& surface);
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
    const std::uint32_t i = halfSpaceIndex(node);
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
