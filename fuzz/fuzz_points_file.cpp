// libFuzzer target for the points-file parser: any input must either parse into finite points
// or throw clod::Error; never crash, hang or produce a non-finite coordinate.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "clod/error.h"
#include "clod/points_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto points = clod::parsePoints(std::string_view(reinterpret_cast<const char*>(data), size));
    for (const auto& p : points) {
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) std::abort();
    }
  } catch (const clod::Error&) {
  }
  return 0;
}
