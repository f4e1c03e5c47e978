#pragma once
// Exact proximity queries on a triangle mesh: closest point (with the feature it lies on),
// unsigned and signed distance, and the generalized winding number. These are the oracle
// every approximate structure in clod (sphere-trees, closest feature maps, contact trees) is
// tested against, so they are exact in double precision, not approximations.
//
// Sign convention: signed distance is negative inside the mesh.

#include <cstdint>
#include <memory>
#include <span>

#include "clod/math.h"
#include "clod/mesh.h"
#include "clod/mesh_topology.h"

namespace clod {

/// Which kind of feature of a triangle or mesh a closest point lies on.
enum class FeatureType : std::uint8_t { kVertex = 0, kEdge = 1, kFace = 2 };

/// "vertex", "edge" or "face".
const char* featureTypeName(FeatureType type) noexcept;

/// Closest point on one triangle, classified by Voronoi region (Ericson, Real-Time Collision
/// Detection, 5.1.5): the face interior, one of the three edges, or one of the three corners.
struct TrianglePoint {
  Vec3 point;
  double distanceSquared;
  FeatureType feature;
  /// Corner k (kVertex) or edge k running from corner k to corner (k+1)%3 (kEdge); 0 for kFace.
  std::uint8_t localIndex;
};

/// Closest point on triangle (a, b, c) to p. Robust for degenerate (zero-area), needle and
/// collinear triangles: these are handled as segments or points and never produce NaN.
/// Needle and flat triangles (width below ~1e-4 of the longest side) are answered from their
/// three sides plus the plane projection when it falls strictly inside, because the region
/// test loses its digits there. The feature reported is where the point lies: a point at
/// parameter 0 or 1 of a side is reported as that corner. Ties between features (p exactly
/// equidistant) go to whichever the region walk meets first. O(1), no allocation.
/// Inputs must be finite; distanceSquared must be representable (|p - a| < ~1e150).
TrianglePoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) noexcept;

/// A feature of a mesh: a vertex index, an edge index into MeshTopology::edges(), or a
/// triangle index.
struct MeshFeature {
  FeatureType type = FeatureType::kFace;
  std::uint32_t index = 0;
};

/// Result of a closest-point query against a whole mesh. Units are the mesh's.
struct ClosestPoint {
  Vec3 point = Vec3::Zero();     ///< closest point on the surface
  double distance = 0.0;         ///< unsigned Euclidean distance |query - point|
  std::uint32_t triangle = 0;    ///< a triangle containing the closest point
  MeshFeature feature;           ///< the feature the closest point lies on
  Vec3 normal = Vec3::Zero();    ///< outward unit normal of that feature (face normal, or
                                 ///< angle-weighted pseudonormal of an edge or vertex)
};

/// How the sign of a signed distance is decided.
enum class SignMethod : std::uint8_t {
  kPseudonormal = 0,   ///< angle-weighted pseudonormals (Baerentzen & Aanaes 2005): exact for
                       ///< closed, consistently oriented, manifold meshes
  kWindingNumber = 1,  ///< generalized winding number >= 1/2 means inside (Jacobson et al. 2013,
                       ///< hierarchical evaluation after Barill et al. 2018): robust for open
                       ///< and non-manifold meshes
};

/// "pseudonormal" or "winding_number".
const char* signMethodName(SignMethod method) noexcept;

/// Build settings of MeshDistance.
struct MeshDistanceSettings {
  /// Triangles per BVH leaf (upper bound), 1..64 (kInvalidArgument otherwise). Does not change
  /// any answer, only speed.
  std::uint32_t leafSize = 4;
  /// Force a sign method; by default pseudonormals for closed meshes, winding numbers otherwise.
  bool forceWindingNumber = false;
  /// Pseudonormals for an open mesh too, where its shared edges are consistently oriented and
  /// its vertices manifold: behind the surface is inside, as for a sheet (a floor quad, a
  /// terrain) whose winding number never reaches 1/2 off it; a point whose closest point is on
  /// the border and which lies beyond it (off the line along that feature's pseudonormal) is
  /// outside -- the solid is what lies behind the faces. Ignored where those do not hold, or
  /// with forceWindingNumber.
  bool sheetPseudonormals = false;
  /// Accuracy of the hierarchical winding number (Barill et al. 2018): a cluster of triangles
  /// is replaced by its second-order far-field expansion when the query point is farther than
  /// windingBeta times the cluster's radius from its centre. The truncation error of a cluster
  /// falls as windingBeta^-3; at the default 2 the total error stays well below the 1/2 that
  /// would flip an inside/outside decision (tests: < 0.1 on the shared mesh corpus), larger
  /// values cost more time. Must be finite and >= 1 (kInvalidArgument otherwise).
  double windingBeta = 2.0;
};

/// Exact distance queries on one mesh. Build once (O(T log T)), then query from any number
/// of threads concurrently: every query method is const and allocation-free.
///
/// Inside: a 4-wide bounding-volume hierarchy (binned-SAH build with TBB, flat node array,
/// 32-bit indices, float boxes rounded outward) over the triangles stored in tree order.
/// Closest-point queries descend nearest-child-first and prune by squared distance with a
/// margin that covers the float rounding, so the answer is exactly the brute-force minimum
/// over all triangles in double precision (same triangle routine), whatever the tree shape.
/// Typical cost O(log T) per query; worst case O(T).
///
/// Sign: see signMethod(). Winding numbers are evaluated hierarchically on the same tree
/// (second-order far field per node, accuracy MeshDistanceSettings::windingBeta).
///
/// Query points must be finite (CLOD_ASSERT) and not absurdly far from the mesh (squared
/// distances must fit a double: |p| < ~1e150 for a mesh near the origin).
class MeshDistance {
public:
  /// Copies the mesh. The mesh must be valid (indices in range, finite coordinates, at least
  /// one triangle with non-zero area): see validateMesh(). Throws clod::Error otherwise:
  /// kNoTriangles, kNonFiniteVertex (names the vertex), kIndexOutOfRange (names the triangle
  /// and index), kAllTrianglesDegenerate; kInvalidArgument for settings out of range.
  /// Open, non-manifold and degenerate-containing meshes are accepted. O(T log T) time,
  /// a few hundred bytes per triangle (the copy, the tree, normals and winding-number moments).
  explicit MeshDistance(TriangleMesh mesh, const MeshDistanceSettings& settings = {});
  ~MeshDistance();
  MeshDistance(MeshDistance&&) noexcept;
  MeshDistance& operator=(MeshDistance&&) noexcept;

  /// Closest point on the surface to p, with the feature it lies on and that feature's normal.
  /// `normal` is zero only where the feature has no defined direction (a degenerate face, or an
  /// edge/vertex whose incident faces are all degenerate or cancel exactly). Exact: equal to
  /// the minimum over all triangles of closestPointOnTriangle. Ties between triangles at the
  /// same distance may report any of them.
  ClosestPoint closestPoint(const Vec3& p) const;

  /// Signed distance at p (negative inside), with the sign from signMethod(). A point on the
  /// surface has signed distance 0. With kPseudonormal, where the closest feature has a zero
  /// normal the sign falls back to the winding number rather than guessing.
  double signedDistance(const Vec3& p) const;

  /// Closest point and signed distance in one query.
  struct Signed {
    ClosestPoint closest;
    double signedDistance;
  };
  Signed signedQuery(const Vec3& p) const;

  /// Generalized winding number at p: ~1 inside a closed outward-oriented mesh, ~0 outside,
  /// fractional near holes of an open mesh, 2 where two closed parts overlap. Hierarchical
  /// (Barill et al. 2018): exact solid angles (Van Oosterom & Strackee 1983) for near
  /// triangles, a second-order expansion for far clusters; the error falls as windingBeta^-3
  /// (about 0.05 worst, 0.005 mean at the default 2 on the shared meshes). Undefined (but
  /// finite) exactly on the surface. O(log T) typical.
  double windingNumber(const Vec3& p) const;

  /// Closest point among a subset of triangles (brute force over the subset). Used by
  /// builders that need the nearest feature of the part of the mesh a sphere is responsible for.
  /// `triangles` must be non-empty.
  ClosestPoint closestPointAmong(const Vec3& p, std::span<const std::uint32_t> triangles) const;

  /// Outward unit normal of a feature: face normal (zero for a degenerate triangle), edge
  /// pseudonormal (normalised sum of the normals of the triangles sharing the edge), or vertex
  /// pseudonormal (normalised sum of incident face normals weighted by the corner angle,
  /// Baerentzen & Aanaes 2005). The index must be in range (CLOD_ASSERT). O(1).
  Vec3 featureNormal(MeshFeature feature) const;

  /// kPseudonormal iff the mesh is closed (every edge has exactly two triangles; or, with
  /// settings.sheetPseudonormals, at most two), consistently
  /// oriented (the two triangles of every edge traverse it in opposite directions), every
  /// vertex is manifold (its triangles form one fan: two cones touching at a vertex break the
  /// pseudonormal argument there) and settings.forceWindingNumber is false; otherwise
  /// kWindingNumber. An inside-out closed mesh gives inverted signs either way (the loader
  /// fixes orientation: MeshLoadOptions::orientOutward).
  SignMethod signMethod() const;
  /// The mesh as given to the constructor.
  const TriangleMesh& mesh() const;
  /// Edge table of mesh(); edge features index its edges().
  const MeshTopology& topology() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clod
