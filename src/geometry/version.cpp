#include "clod/version.h"

namespace clod {

// Compiled into the library, so it reports the version of the library, not of the caller's headers.
const char* version() noexcept { return CLOD_VERSION_STRING; }

}  // namespace clod
