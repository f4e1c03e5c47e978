#pragma once
// Checking a triangle mesh: what is fatal (no stage of clod can use it) and what is merely
// worth a warning (open, non-manifold, degenerate, duplicate, inconsistently oriented...).
// Later stages decide what they support; this header only reports.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "clod/error.h"
#include "clod/mesh.h"

namespace clod {

/// Twice the area below which a triangle counts as degenerate ("zero area"), relative to the
/// squared bounding-box diagonal: |(b - a) x (c - a)| <= kDegenerateCrossRel * diagonal^2.
/// Exactly collinear corners in double precision leave a cross product of a few ulps of
/// |b - a| * |c - a| <= diagonal^2, i.e. ~1e-16 * diagonal^2, so 1e-14 catches those with a
/// margin and flags no real triangle of any sane mesh (1e-14 * d^2 is a triangle with legs of
/// 1e-7 d). Triangles with two equal corner indices are always degenerate.
inline constexpr double kDegenerateCrossRel = 1e-14;

/// The bounding-box diagonals (mesh units) clod computes with. Lengths are squared (areas,
/// distances) and raised to the fifth power (a solid's inertia) in double and baked in float, so
/// far outside this range answers overflow or underflow: a box of half extent 1e200 got a
/// sphere-tree radius of infinity, a sphere of radius 1e-300 "zero-area" triangles. Between
/// them every product clod forms stays finite and normal (1e12^5 = 1e60; 1e-12^5 = 1e-60).
inline constexpr double kMinMeshDiagonal = 1e-12;
inline constexpr double kMaxMeshDiagonal = 1e12;

/// One finding of validateMesh.
struct MeshIssue {
  /// Set for fatal findings (the ErrorCode requireValidMesh throws); empty for warnings.
  std::optional<ErrorCode> fatal;
  /// One human-readable line that names the culprit, e.g.
  /// "triangle 812: vertex index 9001 >= vertex count 4000" or "37 boundary edges: the mesh is open".
  std::string message;
};

/// Everything validateMesh found. Counts refer to the mesh exactly as given (after whatever
/// triangulation and welding the caller did).
struct MeshReport {
  std::uint32_t vertexCount = 0;
  std::uint32_t triangleCount = 0;
  /// Bounding box of the finite vertices (empty when there are none).
  Aabb bounds;

  // --- fatal conditions (any of these makes the mesh unusable) ---
  std::uint32_t nonFiniteVertices = 0;      ///< vertices with a NaN or infinite coordinate
  std::uint32_t outOfRangeTriangles = 0;    ///< triangles with an index >= vertexCount
  // (no triangles, and all triangles degenerate, follow from the counts below)

  // --- topology (computed only when every index is in range; zero otherwise) ---
  std::uint32_t edgeCount = 0;              ///< distinct undirected edges
  std::uint32_t boundaryEdges = 0;          ///< edges used by exactly one triangle
  std::uint32_t nonManifoldEdges = 0;       ///< edges used by three or more triangles
  /// Vertices whose incident triangles form more than one fan (edge-connected group around the
  /// vertex), e.g. two cones touching at their tips. Isolated (unreferenced) vertices are not counted.
  std::uint32_t nonManifoldVertices = 0;
  std::uint32_t unreferencedVertices = 0;   ///< vertices no triangle uses
  std::uint32_t degenerateTriangles = 0;    ///< zero area, see kDegenerateCrossRel
  /// Triangles whose corner set equals an earlier triangle's (either orientation); each extra
  /// copy counts once.
  std::uint32_t duplicateTriangles = 0;
  /// Connected components: triangles are connected when they share a vertex (union-find over
  /// vertices). Unreferenced vertices form no component.
  std::uint32_t components = 0;
  /// Manifold edges (exactly two triangles) that both triangles traverse in the same direction.
  std::uint32_t inconsistentEdges = 0;

  /// No boundary and no non-manifold edge: every edge is shared by exactly two triangles.
  bool closed = false;
  /// Every manifold edge is traversed in opposite directions by its two triangles.
  bool consistentlyOriented = false;
  /// Signed volume sum(a . (b x c)) / 6, only for a closed, consistently oriented mesh (no
  /// fatal issue); positive when triangles face outward, negative when the mesh is inside-out.
  std::optional<double> signedVolume;

  /// Every finding, fatal ones first, one line each. Per-element fatal findings (a NaN vertex, an
  /// out-of-range triangle) are listed individually up to kMaxListedIssues per kind, then summarised.
  std::vector<MeshIssue> issues;

  /// True when no issue is fatal.
  bool usable() const {
    for (const MeshIssue& issue : issues)
      if (issue.fatal) return false;
    return true;
  }
  /// True when the mesh is closed, consistently oriented and its signed volume is negative.
  bool insideOut() const { return signedVolume && *signedVolume < 0.0; }
};

/// Maximum number of individually listed findings of one per-element kind in MeshReport::issues.
inline constexpr std::uint32_t kMaxListedIssues = 20;

/// Checks a mesh and reports every finding, fatal or not. Never throws for bad data (only
/// std::bad_alloc). Fatal findings: non-finite coordinates (kNonFiniteVertex), out-of-range
/// indices (kIndexOutOfRange), no triangles (kNoTriangles), a bounding-box diagonal outside
/// [kMinMeshDiagonal, kMaxMeshDiagonal] (kUnsupportedMesh), every triangle degenerate
/// (kAllTrianglesDegenerate). Warnings: open, non-manifold edges/vertices, degenerate or
/// duplicate triangles, unreferenced vertices, several components, inconsistent orientation,
/// inside-out, flat (zero extent along an axis, or a closed mesh enclosing zero volume). Complexity: O(V + T log T) time, O(V + T) memory.
MeshReport validateMesh(const TriangleMesh& mesh);

/// Throws clod::Error for the first fatal finding of `report` (in the order non-finite vertex,
/// out-of-range index, no triangles, size out of range, all degenerate), with the message of that
/// finding plus a count of further fatal findings. Does nothing when report.usable().
void throwIfUnusable(const MeshReport& report);

/// validateMesh + throwIfUnusable, for meshes built in code: returns the report when the mesh is
/// usable, throws clod::Error naming the culprit otherwise.
MeshReport requireValidMesh(const TriangleMesh& mesh);

/// Reverses the winding of every triangle (swaps corners 1 and 2), turning an inside-out mesh
/// outward. O(T).
void flipOrientation(TriangleMesh& mesh);

}  // namespace clod
