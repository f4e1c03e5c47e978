#pragma once
// The 'MESH' section of a bake file: the mesh, its content hash and its source name.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "clod/mesh.h"
#include "section_codec.h"

namespace clod::detail {

/// Throws via `complain` unless every coordinate is finite, every index < vertex count and
/// both counts fit in 32 bits.
void checkMesh(const TriangleMesh& mesh, const Complaint& complain);

/// Encodes a mesh that passed checkMesh. `hash` must be meshContentHash(mesh).
std::vector<std::byte> encodeMeshSection(const TriangleMesh& mesh, std::uint64_t hash, const std::string& sourceName);

struct DecodedMeshSection {
  TriangleMesh mesh;
  std::uint64_t hash = 0;
  std::string sourceName;
};

/// Decodes and checks a 'MESH' payload of version 1. Throws kBakeTruncated / kBakeCorrupt.
DecodedMeshSection decodeMeshSection(std::span<const std::byte> payload);

}  // namespace clod::detail
