// libFuzzer target for the bake-file reader (decodeBake). Every input must either decode or
// throw clod::Error; anything else (a crash, a sanitizer report, another exception) is a bug.
//
// Checksums would stop almost every mutation at the container, so the first input byte picks
// what the rest of the input is:
//   0: a whole bake file;
//   1: the payload of the 'STRE' section, wrapped with a valid 'MESH' section and valid checksums;
//   2: the payload of the 'MESH' section, wrapped with a valid 'STRE' section and valid checksums.
// Modes 1 and 2 reach the section decoders' semantic checks directly.
// Whatever decodes must survive encode -> decode -> encode unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "clod/bake.h"
#include "clod/error.h"

namespace {

// A tetrahedron with a two-level sphere-tree: the source of the valid companion sections.
const clod::BakeContents& referenceContents() {
  static const clod::BakeContents contents = [] {
    clod::BakeContents c;
    c.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    c.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    c.sourceName = "tetra";
    clod::SphereTree& t = c.sphereTree;
    t.centerX = {0.5, 0.25, 0.75};
    t.centerY = {0.5, 0.25, 0.5};
    t.centerZ = {0.5, 0.25, 0.5};
    t.radius = {1.0, 0.9, 1.1};  // each sphere holds every corner of the triangles it lists
    t.parent = {clod::kNoSphere, 0, 0};
    t.firstChild = {1, 0, 0};
    t.childCount = {2, 0, 0};
    t.triangleOffsets = {0, 4, 6, 8};
    t.triangleList = {0, 1, 2, 3, 0, 1, 2, 3};
    t.levelOffsets = {0, 1, 3};
    return c;
  }();
  return contents;
}

std::vector<std::byte> sectionPayload(clod::BakeSectionTag tag, std::uint32_t version) {
  const std::vector<std::byte> file = clod::encodeBake(referenceContents());
  const auto payload = clod::BakeFileReader(file).section(tag, version).payload;
  return {payload.begin(), payload.end()};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::byte> rest(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  static const std::vector<std::byte> meshPayload = sectionPayload(clod::kBakeMeshTag, clod::kBakeMeshVersion);
  static const std::vector<std::byte> treePayload = sectionPayload(clod::kBakeSphereTreeTag, clod::kBakeSphereTreeVersion);

  std::vector<std::byte> file;
  switch (data[0] % 3) {
    case 0: file.assign(rest.begin(), rest.end()); break;
    case 1: {
      clod::BakeFileWriter writer;
      writer.addSection(clod::kBakeMeshTag, clod::kBakeMeshVersion, meshPayload);
      writer.addSection(clod::kBakeSphereTreeTag, clod::kBakeSphereTreeVersion, {rest.begin(), rest.end()});
      file = writer.encode();
      break;
    }
    default: {
      clod::BakeFileWriter writer;
      writer.addSection(clod::kBakeMeshTag, clod::kBakeMeshVersion, {rest.begin(), rest.end()});
      writer.addSection(clod::kBakeSphereTreeTag, clod::kBakeSphereTreeVersion, treePayload);
      file = writer.encode();
      break;
    }
  }

  clod::BakeContents decoded;
  try {
    decoded = clod::decodeBake(file);
  } catch (const clod::Error&) {
    return 0;  // rejected with a clear error: fine
  }
  // Accepted contents must be writable and stable under another round trip.
  const std::vector<std::byte> once = clod::encodeBake(decoded);
  const std::vector<std::byte> twice = clod::encodeBake(clod::decodeBake(once));
  if (once != twice) std::abort();
  return 0;
}
