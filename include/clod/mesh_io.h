#pragma once
// Loading triangle meshes from files: OBJ, STL (ASCII and binary), PLY, OFF, glTF/GLB (and
// the other formats Assimp reads, such as Collada), triangulated, welded and checked.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "clod/mesh.h"
#include "clod/mesh_validation.h"

namespace clod {

struct MeshLoadOptions {
  /// Vertices closer than weldToleranceRel * (bounding-box diagonal) are merged into one.
  /// 0 merges only exact duplicates; negative disables welding.
  double weldToleranceRel = 1e-7;
  /// Flip every triangle of a closed, consistently oriented mesh whose signed volume is
  /// negative (inside-out), so normals point outward.
  bool orientOutward = true;
  /// glTF JSON (a .gltf file, or the JSON chunk of a .glb) that nests arrays/objects deeper
  /// than this is refused with kParseError before the importer sees it: the importer's JSON
  /// parser recurses once per level and would overflow the stack (a 400 kB file nesting
  /// 200,000 deep crashed it). Real glTF files nest about 5 levels; a few thousand is still safe.
  std::uint32_t maxJsonDepth = 512;

  // Resource limits. A file beyond one is refused with kUnsupportedMesh, and a message naming the
  // limit (e.g. "... more than MeshLoadOptions::maxVertices = 150000000"): raise the option to
  // load it. They are checked as early as each format allows, before anything is allocated for
  // the data: OFF and PLY header counts, OBJ `v` and `f` lines (counted in one pass over the
  // text, before Assimp parses it), then, for every format, the importer's output before clod copies it (node instances
  // counted once each). clod's own copy costs about 24 bytes per vertex and 12 per triangle;
  // Assimp's parse takes several times that while it runs.

  /// Most vertices before welding (LoadedMesh::importedVertexCount): declared by the file, and
  /// delivered by the importer, which gives STL 3 per triangle and OBJ one per face corner. The
  /// default, 3 x maxTriangles, lets such files of maxTriangles triangles through.
  std::uint64_t maxVertices = 150'000'000;
  /// Most triangles, counting n - 2 for every polygon of n corners. A PLY header's face count is
  /// held against it as if every face were one triangle.
  std::uint64_t maxTriangles = 50'000'000;
  /// Most corners of one polygon (face). Polygons are triangulated in O(n log n)
  /// (a 100,000-corner face takes well under a second), so this only bounds the work and the
  /// memory one line of a file can ask for.
  std::uint64_t maxPolygonVertices = 1'000'000;
};

/// A loaded mesh plus what the loader had to say about it.
struct LoadedMesh {
  /// All triangles of all meshes of all nodes of the file, node transforms applied, polygons
  /// triangulated, vertices welded, orientation fixed if asked. Degenerate and duplicate
  /// triangles are kept (counted in `report`); points and lines in the file are ignored.
  TriangleMesh mesh;
  /// Non-fatal findings: open, non-manifold, degenerate or duplicate triangles, flipped
  /// orientation, ignored points/lines... One human-readable line each.
  std::vector<std::string> warnings;
  /// validateMesh of `mesh` as returned (after welding and flipping); always usable().
  MeshReport report;
  /// Vertex count as the importer delivered it, before welding (STL: 3 per triangle).
  std::uint32_t importedVertexCount = 0;
  /// Vertices removed by welding (importedVertexCount - mesh.vertexCount()).
  std::uint32_t weldedVertexCount = 0;
  /// Absolute weld tolerance used: weldToleranceRel * bounding-box diagonal (0 when disabled).
  double weldToleranceAbs = 0.0;
  /// True when the mesh was inside-out and every triangle was flipped (a warning says so too).
  bool flipped = false;
};

/// Loads a mesh file. Throws clod::Error naming the culprit for: a missing or unreadable
/// file (kFileNotFound, kFileUnreadable), an empty file (kEmptyFile), an unknown format
/// (kUnknownFormat), malformed content (kParseError), NaN/Inf coordinates
/// (kNonFiniteVertex), out-of-range indices (kIndexOutOfRange), no triangles
/// (kNoTriangles), only zero-area triangles (kAllTrianglesDegenerate), or more vertices,
/// triangles or polygon corners than the options allow (kUnsupportedMesh, naming the option).
/// Open, non-manifold and flat meshes load, with warnings.
///
/// OFF files (by extension/hint, or any content starting with "OFF") are read by clod's own
/// strict reader, because Assimp 5.2.5's OFF reader repairs
/// bad indices silently and crashes on some malformed files.
/// Every other format goes through Assimp (Collada .dae included, see below).
///
/// Coordinates come out as written in the file (docs/conventions.md): Assimp's Collada reader
/// would rotate Z-up and X-up files to Y-up and scale by the file's <unit>; clod undoes both.
/// glTF node transforms (part of the geometry's definition) are applied.
///
/// Polygons (faces of more than 3 corners, any format) are triangulated by clod in
/// O(n log n): strictly convex ones as a fan from their first corner, others in their best-fit
/// plane into triangles inside the polygon; a polygon that is not simple in that plane
/// (self-intersecting, zero area) becomes a fan, with a warning. Either way a face of n corners
/// gives n - 2 triangles wound like the face.
///
/// Pipeline: Assimp import without post-processing (no triangulation, no vertex joining, no
/// degenerate removal, no normal fixing: counts stay honest) -> check limits -> merge all meshes
/// of all nodes with their node transforms, triangulating polygons -> check coordinates and
/// indices -> weld (weldVertices with
/// weldToleranceRel * diagonal) -> validateMesh -> throw if unusable -> flip if inside-out.
/// Nothing is printed: Assimp's log is captured, and its messages about repaired data (e.g. an
/// out-of-range index the OFF reader would clamp, a glTF face it would drop) become errors,
/// the rest become warnings prefixed "importer: ".
/// Precision: Assimp (as packaged) stores positions in single precision, so coordinates are
/// rounded to float before they become doubles here. Vertices that no face uses are not kept
/// by Assimp's OBJ reader (stanford-bunny.obj: 35,947 `v` lines, 34,834 used).
LoadedMesh loadMesh(const std::filesystem::path& path, const MeshLoadOptions& options = {});

/// Same as loadMesh, from bytes in memory; `formatHint` is a file extension such as "obj",
/// "stl", "ply", "off", "gltf", "glb" (letters and digits, at most 15; otherwise
/// kInvalidArgument). A .gltf that refers to external .bin/.png files cannot resolve them from
/// memory (kParseError); embedded (data URI) buffers and .glb work.
/// Thread safety: both functions may run concurrently (each call uses its own importer).
LoadedMesh loadMeshFromMemory(std::span<const std::byte> bytes, std::string_view formatHint,
                              const MeshLoadOptions& options = {});

}  // namespace clod
