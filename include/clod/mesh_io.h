#pragma once
// Loading triangle meshes from files: OBJ, STL (ASCII and binary), PLY, OFF, glTF/GLB,
// read through Assimp, triangulated, welded and checked.

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
/// (kNoTriangles), or only zero-area triangles (kAllTrianglesDegenerate).
/// Open, non-manifold and flat meshes load, with warnings.
///
/// OFF files (by extension/hint, or any content starting with "OFF") are read by clod's own
/// strict reader, because Assimp 5.2.5's OFF reader repairs
/// bad indices silently and crashes on some malformed files; polygons are fan-triangulated.
/// Every other format goes through Assimp.
///
/// Pipeline: Assimp import with triangulation only (no vertex joining, no degenerate removal,
/// no normal fixing: counts stay honest) -> merge all meshes of all nodes with their node
/// transforms -> check coordinates and indices -> weld (weldVertices with
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
