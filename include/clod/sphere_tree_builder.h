#pragma once
// Building sphere-trees (sphere_tree.h) from a mesh, and measuring how well they fit.
//
// Both builders guarantee coverage, not just sampled coverage: they partition the surface into
// pieces (triangles clipped to axis-aligned boxes, so convex polygons of at most 9 corners) and
// make every sphere contain every corner of every piece assigned to it. A sphere is convex, so
// it contains the whole piece, and each level's pieces together are the whole surface. Radii are
// finally grown by 1e-9 * (bounding-box diagonal) so that rounding in the containment test
// cannot open a gap. Degenerate (zero-area) triangles are covered too.
//
// Typical use:
//   clod::MeshDistance distance(clod::loadMesh("spot.obj").mesh);
//   clod::SphereTree tree = clod::buildSphereTree(distance, {});             // medial, 8-ary, 4 levels
//   std::vector<clod::SphereTreeLevelFit> fit = clod::measureSphereTreeFit(tree, distance);

#include <cstdint>
#include <string_view>
#include <vector>

#include "clod/mesh.h"
#include "clod/sphere_tree.h"

namespace clod {

class MeshDistance;

enum class SphereTreeMethod : std::uint8_t {
  /// Hubbard's basic method: the root cell is the cube around the bounding box; a sphere's
  /// children are the occupied cells of its cell's subdivision, each the smallest enclosing
  /// sphere (Welzl) of the surface clipped to the cell. With branching 8 a cell splits 2x2x2;
  /// other branching factors split into the grid nx*ny*nz <= branching that halves the longest
  /// extent first (2 -> 2x1x1, 4 -> 2x2x1, 27 -> 3x3x3). Empty cells get no sphere, so nodes
  /// often have fewer children than the branching factor.
  kOctree = 0,
  /// Medial-axis approximation (Hubbard 1996; Bradshaw & O'Sullivan 2004, ACM TOG 23(1)):
  /// surface samples -> qhull Delaunay tetrahedralisation -> interior Voronoi vertices = medial
  /// spheres; every sample gets its inner pole (largest interior medial sphere touching it).
  /// Top-down, each node's surface (pieces larger than a fifth of the node split first) is
  /// reduced to `branching` groups by SphereTreeSettings::medialReduction: by default the
  /// better of Bradshaw's merge / burst of medial spheres and k-means, or either alone. Each group then gets ("expand"), among
  /// five centres on the segment from its smallest enclosing sphere's centre to its mean
  /// medial-pole centre, the sphere of lowest estimated fit (Bradshaw's overshoot at 32 points
  /// of the sphere against the group's piece corners and centroids), grown to contain all its
  /// pieces. Nodes get exactly `branching` children unless they hold too little surface.
  kMedial = 1,
};

/// How the medial builder reduces a node's surface to `branching` child spheres.
enum class MedialReduction : std::uint8_t {
  /// The default: per node, both reductions below are run and the children of the one with the
  /// lower estimated fit (largest plus mean overshoot of the expanded children) are kept.
  /// Deterministic; costs the sum of the two.
  kBest = 0,
  /// Bradshaw & O'Sullivan's reduction alone: the node starts with one sphere per interior
  /// medial sphere (inner pole) its surface touches, or one per surface piece deep in the tree
  /// where it touches fewer than 2 * branching of them; then, from a priority queue with lazy
  /// updates, neighbouring spheres are merged (the pair whose sphere around both spheres'
  /// surface points has the least estimated fit first) or a sphere is burst (its surface handed
  /// to the neighbours it sticks out of least, when that costs less than any merge) until
  /// `branching` remain; each is finally expanded to cover its surface exactly, its centre
  /// chosen for the least estimated overshoot. Neighbours are spheres whose surface shares a
  /// mesh vertex (separate components are linked to their nearest spheres). Cost per node
  /// O(n * degree * log n) for n starting spheres. How this follows and departs from the
  /// paper: src/sphere_tree/medial_reduction.h.
  kMergeBurst = 1,
  /// The earlier clustering alone: area-weighted k-means of points pulled from the surface
  /// towards their inner poles (half-way at the root, a quarter at level 1, 0.15 deeper), best
  /// of four seedings by cluster sphere size, then the same expansion.
  kKMeans = 2,
};

/// "octree" or "medial".
const char* sphereTreeMethodName(SphereTreeMethod method) noexcept;

/// Parses "octree" or "medial". Throws clod::Error(kInvalidArgument) naming the text otherwise.
SphereTreeMethod parseSphereTreeMethod(std::string_view name);

struct SphereTreeSettings {
  SphereTreeMethod method = SphereTreeMethod::kMedial;
  std::uint32_t branching = 8;  ///< maximum children per sphere, in [2, 64]
  std::uint32_t depth = 4;      ///< levels below the root (the tree has depth + 1 levels), in [0, 8]
  /// Medial builder: about this many area-weighted surface samples for the medial axis (plus all
  /// vertices when there are no more than this many). In [100, 2,000,000]. Build time grows
  /// roughly linearly with it (qhull's Delaunay is O(n log n) in practice); 8,000 and 20,000
  /// give fits within a few per cent of each other on the shared meshes.
  std::uint32_t medialSamples = 10000;
  /// Medial builder: how a node is reduced to its children (see MedialReduction).
  MedialReduction medialReduction = MedialReduction::kBest;
};

/// Builds a sphere-tree of mesh.mesh() (see SphereTree for the layout and guarantees).
/// Deterministic: the same mesh and settings give the same tree, with any number of threads.
/// Runs in parallel with TBB over the nodes of a level.
/// Cost: octree O(T * depth) clipping plus Welzl per cell; medial adds O(S log S) for the
/// Delaunay of S samples, O(P * branching) k-means per level for P pieces and the merge/burst
/// reduction (see MedialReduction); about 6 s of one core for 69k triangles, 8-ary, 4 levels.
/// Throws clod::Error(kInvalidArgument) for out-of-range settings (the message names the
/// setting). Flat meshes (no volume, so no medial axis) build too: the medial builder then
/// clusters the surface itself.
SphereTree buildSphereTree(const MeshDistance& mesh, const SphereTreeSettings& settings);

/// Fit of one level: for every sphere, the greatest distance from its surface to the
/// surface it bounds ("overshoot"), in units of the mesh's bounding-box diagonal.
struct SphereTreeLevelFit {
  std::uint32_t spheres = 0;
  double fitMean = 0.0;  ///< mean over the level's spheres of their fit
  double fitMax = 0.0;   ///< largest fit of a sphere on the level
};

/// How the fit is estimated.
struct SphereFitSettings {
  /// Points per sphere surface (a spherical Fibonacci set), in [1, 100000]. Each point's
  /// distance to the closest point of the sphere's triangles is exact; the sphere's fit is the
  /// largest. The estimate is a lower bound of the true overshoot that converges as the count
  /// grows: every direction is within about 2*acos(1 - 2/N) radians of one of the N points
  /// (0.2 rad for the default 200); distance to a set is 1-Lipschitz, so the estimate is at
  /// most the chord 2 * radius * sin(angle / 2) below the true overshoot.
  std::uint32_t samplesPerSphere = 200;
};

/// Fit of every sphere, in units of the bounding-box diagonal, indexed like the tree's spheres.
/// Following Bradshaw's toolkit, a sphere's fit is the largest distance from a point on its
/// surface to the closest point of the triangles it is responsible for (tree.triangles(i)).
/// Cost: samplesPerSphere * (sum over spheres of their triangle counts) point-triangle
/// distances, in parallel. Throws clod::Error(kInvalidArgument) if the tree is malformed for
/// this mesh (a triangle index out of range, a sphere without triangles, inconsistent arrays)
/// or the settings are out of range.
std::vector<double> measureSphereFits(const SphereTree& tree, const MeshDistance& mesh,
                                      const SphereFitSettings& settings);

/// Per-level mean and max of measureSphereFits() with default settings.
std::vector<SphereTreeLevelFit> measureSphereTreeFit(const SphereTree& tree, const MeshDistance& mesh);

/// Same, with explicit fit settings.
std::vector<SphereTreeLevelFit> measureSphereTreeFit(const SphereTree& tree, const MeshDistance& mesh,
                                                     const SphereFitSettings& settings);

}  // namespace clod
