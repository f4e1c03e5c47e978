#pragma once
// How much work a test may do. The CI runs the suite twice: Release with the full counts an issue
// asks for, then under AddressSanitizer + UBSan (CLOD_TEST_SCALE=sanitizer), where code runs 3-10x
// slower and the point is memory and UB safety of every code path, not statistics. Tests may then
// cut sample counts, tree depths and repeated variants, never whole code paths.
#include <cstdlib>
#include <cstring>

namespace clod::test {

/// True in the ASan+UBSan run (CLOD_TEST_SCALE=sanitizer).
inline bool sanitizerRun() {
  const char* scale = std::getenv("CLOD_TEST_SCALE");
  return scale != nullptr && std::strcmp(scale, "sanitizer") == 0;
}

}  // namespace clod::test
