#pragma once
// Loading triangle meshes from files: OBJ, STL (ASCII and binary), PLY, OFF, glTF/GLB,
// read through Assimp, triangulated, welded and checked.

#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "clod/mesh.h"

namespace clod {

struct MeshLoadOptions {
  /// Vertices closer than weldToleranceRel * (bounding-box diagonal) are merged into one.
  /// 0 merges only exact duplicates; negative disables welding.
  double weldToleranceRel = 1e-7;
  /// Flip every triangle of a closed, consistently oriented mesh whose signed volume is
  /// negative (inside-out), so normals point outward.
  bool orientOutward = true;
};

/// A loaded mesh plus what the loader had to say about it.
struct LoadedMesh {
  TriangleMesh mesh;
  /// Non-fatal findings: open, non-manifold, degenerate or duplicate triangles, flipped
  /// orientation, welded vertices... One human-readable line each.
  std::vector<std::string> warnings;
};

/// Loads a mesh file. Throws clod::Error naming the culprit for: a missing or unreadable
/// file (kFileNotFound, kFileUnreadable), an empty file (kEmptyFile), an unknown format
/// (kUnknownFormat), malformed content (kParseError), NaN/Inf coordinates
/// (kNonFiniteVertex), out-of-range indices (kIndexOutOfRange), no triangles
/// (kNoTriangles), or only zero-area triangles (kAllTrianglesDegenerate).
/// Open, non-manifold and flat meshes load, with warnings.
LoadedMesh loadMesh(const std::filesystem::path& path, const MeshLoadOptions& options = {});

/// Same as loadMesh, from bytes in memory; `formatHint` is a file extension such as "obj".
LoadedMesh loadMeshFromMemory(std::span<const std::byte> bytes, std::string_view formatHint,
                              const MeshLoadOptions& options = {});

}  // namespace clod
