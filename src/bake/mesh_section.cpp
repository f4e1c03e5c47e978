#include "mesh_section.h"

#include <cmath>
#include <cstring>

#include "clod/bake.h"

namespace clod::detail {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "vertices are copied as packed f64 triples");
static_assert(sizeof(Triangle) == 3 * sizeof(std::uint32_t), "triangles are copied as packed u32 triples");

void checkMesh(const TriangleMesh& mesh, const Complaint& complain) {
  if (mesh.vertices.size() >= 0xffffffffull) complain("vertex count " + std::to_string(mesh.vertices.size()) + " does not fit 32 bits");
  if (mesh.triangles.size() >= 0xffffffffull) complain("triangle count " + std::to_string(mesh.triangles.size()) + " does not fit 32 bits");
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3& p = mesh.vertices[v];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
      complain("vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  const std::uint32_t vertexCount = mesh.vertexCount();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.triangles[t][k] >= vertexCount) {
        complain("triangle " + std::to_string(t) + ": vertex index " + std::to_string(mesh.triangles[t][k]) +
                 " >= vertex count " + std::to_string(vertexCount));
      }
    }
  }
}

std::vector<std::byte> encodeMeshSection(const TriangleMesh& mesh, std::uint64_t hash, const std::string& sourceName) {
  ByteWriter writer;
  writer.write<std::uint64_t>(hash);
  writer.writeString(sourceName);
  writer.align(8);
  writer.write<std::uint64_t>(3 * mesh.vertices.size());
  writer.writeBytes({reinterpret_cast<const std::byte*>(mesh.vertices.data()), mesh.vertices.size() * sizeof(Vec3)});
  writer.write<std::uint64_t>(3 * mesh.triangles.size());
  writer.writeBytes({reinterpret_cast<const std::byte*>(mesh.triangles.data()), mesh.triangles.size() * sizeof(Triangle)});
  writer.align(8);
  return writer.take();
}

namespace {

// Reads a u64 element count (a multiple of 3) and copies that many elements straight into
// `out` (resized to count / 3 items), one memcpy: no per-element work on the load path.
template <class Item, class Element>
void readTriples(ByteReader& reader, std::vector<Item>& out, const char* what) {
  const auto count = reader.read<std::uint64_t>();
  if (count % 3 != 0) reader.fail(std::string(what) + " element count " + std::to_string(count) + " is not a multiple of 3");
  if (count / 3 >= 0xffffffffull) reader.fail(std::string(what) + " count " + std::to_string(count / 3) + " does not fit 32 bits");
  if (count > reader.remaining() / sizeof(Element)) {
    throw Error(ErrorCode::kBakeTruncated, reader.context() + ": " + what + " need " + std::to_string(count) + " elements of " +
                                               std::to_string(sizeof(Element)) + " bytes but only " +
                                               std::to_string(reader.remaining()) + " bytes remain");
  }
  out.resize(count / 3);
  const auto bytes = reader.readBytes(count * sizeof(Element));
  if (!bytes.empty()) std::memcpy(static_cast<void*>(out.data()), bytes.data(), bytes.size());
}

}  // namespace

DecodedMeshSection decodeMeshSection(std::span<const std::byte> payload) {
  ByteReader reader(payload.data(), payload.size(), "bake section 'MESH'");
  DecodedMeshSection decoded;
  decoded.hash = reader.read<std::uint64_t>();
  decoded.sourceName = reader.readString();
  skipZeroPadding(reader);
  readTriples<Vec3, double>(reader, decoded.mesh.vertices, "vertices");
  readTriples<Triangle, std::uint32_t>(reader, decoded.mesh.triangles, "triangles");
  skipZeroPadding(reader);
  if (!reader.atEnd()) reader.fail(std::to_string(reader.remaining()) + " unexpected bytes after the triangles");

  checkMesh(decoded.mesh, Complaint{ErrorCode::kBakeCorrupt, reader.context()});
  const std::uint64_t computed = meshContentHash(decoded.mesh);
  if (computed != decoded.hash) {
    reader.fail("stored mesh hash " + std::to_string(decoded.hash) + " != hash of the stored mesh " + std::to_string(computed));
  }
  return decoded;
}

}  // namespace clod::detail
