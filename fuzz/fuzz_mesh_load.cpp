// libFuzzer target for the mesh loaders: loadMeshFromMemory over every supported format.
// The first byte picks the format hint, the rest is the file content. The only acceptable
// outcomes are a loaded mesh or clod::Error; anything else (crash, hang, sanitizer report,
// another exception) is a bug.
#include <cstddef>
#include <cstdint>
#include <span>

#include "clod/error.h"
#include "clod/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const char* const kHints[] = {"obj", "stl", "ply", "off", "gltf", "glb", "dae"};
  if (size < 1) return 0;
  const char* hint = kHints[data[0] % (sizeof kHints / sizeof kHints[0])];
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  try {
    const clod::LoadedMesh loaded = clod::loadMeshFromMemory(bytes, hint);
    // The contract of a successful load: indices in range, coordinates finite, not all degenerate.
    for (const clod::Triangle& t : loaded.mesh.triangles)
      for (std::uint32_t i : t)
        if (i >= loaded.mesh.vertexCount()) __builtin_trap();
    for (const clod::Vec3& v : loaded.mesh.vertices)
      if (!v.allFinite()) __builtin_trap();
    if (loaded.mesh.triangles.empty() || !loaded.report.usable()) __builtin_trap();
  } catch (const clod::Error&) {
  }
  return 0;
}
