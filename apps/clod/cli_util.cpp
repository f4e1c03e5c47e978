#include "cli_util.h"

#include <iostream>

namespace clod::cli {

void printJson(const nlohmann::json& document) { std::cout << document.dump(2) << "\n"; }

}  // namespace clod::cli
