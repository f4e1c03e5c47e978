// clod spheres FILE.clod --level L [--json]: print the spheres of one sphere-tree level of a
// bake file, in the mesh's own coordinates. Level 0 is the root. A level outside the tree is
// bad usage (exit 2) and the message gives the valid range; a bad file is bad data (exit 1).
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "cli_util.h"
#include "clod/bake.h"
#include "clod/error.h"
#include "command.h"

namespace clod::cli {
namespace {

struct SpheresOptions {
  std::string path;
  std::int64_t level = 0;
  bool json = false;
};

int runSpheres(const SpheresOptions& options) {
  const BakeContents contents = loadBake(options.path);
  const SphereTree& tree = contents.sphereTree;
  const std::int64_t levelCount = tree.levelCount();
  if (options.level < 0 || options.level >= levelCount) {
    throw Error(ErrorCode::kInvalidArgument, "--level " + std::to_string(options.level) + " is out of range: '" +
                                                 options.path + "' has levels 0.." + std::to_string(levelCount - 1) +
                                                 " (0 is the root)");
  }
  const auto level = static_cast<std::uint32_t>(options.level);

  if (options.json) {
    nlohmann::json spheres = nlohmann::json::array();
    for (std::uint32_t i = tree.levelBegin(level); i < tree.levelEnd(level); ++i) {
      spheres.push_back({{"center", toJson(tree.center(i))}, {"radius", tree.radius[i]}});
    }
    printJson(spheres);
    return 0;
  }
  std::ostringstream text;
  text.precision(17);
  text << "# level " << level << " of " << levelCount << ": " << (tree.levelEnd(level) - tree.levelBegin(level))
       << " spheres (x y z radius)\n";
  for (std::uint32_t i = tree.levelBegin(level); i < tree.levelEnd(level); ++i) {
    text << tree.centerX[i] << " " << tree.centerY[i] << " " << tree.centerZ[i] << " " << tree.radius[i] << "\n";
  }
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("spheres", [](CLI::App& app) {
  auto options = std::make_shared<SpheresOptions>();
  CLI::App* sub = app.add_subcommand("spheres", "Print the spheres of one sphere-tree level of a .clod bake file");
  sub->add_option("bake", options->path, "Bake file (.clod) written by 'clod bake'")->required();
  sub->add_option("--level", options->level, "Sphere-tree level, 0 = root")->required();
  sub->add_flag("--json", options->json, "Print a JSON array of {center: [x, y, z], radius}");
  return [options] { return runSpheres(*options); };
});

}  // namespace
}  // namespace clod::cli
