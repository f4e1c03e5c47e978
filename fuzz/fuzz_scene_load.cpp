// libFuzzer target for the scene reader (parseScene). Every input must either parse or throw
// clod::Error(kSceneError); anything else (a crash, a sanitizer report, another exception) is a
// bug. Parsing never touches the file system (mesh paths are only resolved, not opened).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "clod/error.h"
#include "clod/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const clod::SceneDescription scene = clod::parseScene(text, "/nonexistent", "fuzz.json");
    if (scene.steps == 0 || !(scene.dt > 0.0)) std::abort();  // parseScene promises both
  } catch (const clod::Error& e) {
    if (e.code() != clod::ErrorCode::kSceneError) std::abort();
  }
  return 0;
}
