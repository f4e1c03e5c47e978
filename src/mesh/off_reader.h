#pragma once
// A strict reader for OFF files (Geomview Object File Format), used instead of Assimp's: the
// OFF reader of Assimp 5.2.5 clamps out-of-range indices silently, reads negative indices as 0,
// and reads out of bounds on faces with no vertices or stray tokens (found by fuzz_mesh_load).
//
// Accepted: an optional [ST][C][N]OFF keyword line (counts may follow it on the same line),
// then "vertexCount faceCount [edgeCount]", vertexCount lines of x y z (extra per-vertex values
// such as colours or normals are ignored), faceCount lines of "n i0 ... i(n-1)" (extra colour
// values after the indices are ignored). '#' starts a comment. Polygons are triangulated by
// appendFaceTriangles (polygon_triangulation.h); faces of 1 or 2 vertices (points, lines) are
// counted and skipped. The limits of MeshLoadOptions are checked on the header's vertex count
// before anything is allocated, and on every face before it is read.

#include <cstdint>
#include <string>
#include <string_view>

#include "clod/mesh.h"
#include "clod/mesh_io.h"

namespace clod::detail {

struct OffContent {
  TriangleMesh mesh;
  std::uint64_t ignoredPrimitives = 0;  ///< faces with 1 or 2 vertices
  std::uint64_t fannedPolygons = 0;     ///< polygons not simple in their plane (PolygonCut::kFanFallback)
};

/// True when an OFF file is what Assimp would take these bytes for when the extension does not
/// say: the first three bytes are "off" in any case.
bool looksLikeOff(std::string_view text);

/// Parses an OFF text. Throws clod::Error naming `source` and the line: kParseError for a
/// malformed keyword, count, coordinate or face line, or a file that ends early; kIndexOutOfRange
/// for a negative or too large index; kUnsupportedMesh past a limit of `limits` (maxVertices,
/// maxTriangles, maxPolygonVertices; the other options are not used). Non-finite coordinates are
/// parsed as such (the caller's validation reports them). O(size log size).
OffContent readOff(std::string_view text, const std::string& source, const MeshLoadOptions& limits = {});

}  // namespace clod::detail
