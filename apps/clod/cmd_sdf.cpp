// clod sdf BAKE.clod --points FILE [--depth D] [--json]: the contact tree's signed distance field
// at query points (ContactTree::sample), optionally stopped at octree depth D.
//
// The JSON output is a stable contract (external checks use it): a top-level array with one
// object per query point, in file order (points_io.h format, mesh coordinates):
// {distance, gradient: [x,y,z], error_bound, depth}, plus the extra inside_root (false when the
// point lay outside the tree's root cube, see ContactTree::sample). distance is negative inside;
// gradient is that of the trilinear interpolant (not normalised); error_bound is the stopping
// cell's bound on |distance - exact|; depth is the depth of the cell the query stopped in
// (min(leaf depth, D)).
// A bake without a contact tree ('CTRE' section; written by `clod bake` unless --no-sdf) exits 1.
// --depth outside [0, the tree's maxDepth]: exit 2. Nothing is printed until every point is
// answered, so an error leaves stdout empty.
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "clod/bake.h"
#include "clod/contact_tree.h"
#include "clod/error.h"
#include "clod/points_io.h"
#include "command.h"

namespace clod::cli {
namespace {

struct SdfOptions {
  std::string bakePath;
  std::string pointsPath;
  long depthValue = 0;
  CLI::Option* depthOption = nullptr;  // set at registration; count() says whether --depth was given
  bool json = false;
};

[[noreturn]] void rejectDepth(long depth, const std::string& why) {
  throw Error(ErrorCode::kInvalidArgument, "--depth " + std::to_string(depth) + " " + why);
}

int runSdf(const SdfOptions& options) {
  const bool depthGiven = options.depthOption->count() > 0;
  const long depth = options.depthValue;
  // A negative depth is wrong for every tree: say so before touching any file.
  if (depthGiven && depth < 0) rejectDepth(depth, "is negative (0 = the root cell)");
  const std::vector<Vec3> points = readPointsFile(options.pointsPath);
  const BakeContents bake = loadBake(options.bakePath);
  if (!bake.contactTree) {
    throw Error(ErrorCode::kBakeMissingSection,
                "'" + options.bakePath + "' has no contact tree (section 'CTRE'): re-bake it with `clod bake` "
                "without --no-sdf (--sdf-error and --sdf-depth set its accuracy)");
  }
  const ContactTree& tree = *bake.contactTree;
  std::uint32_t maxDepth = kContactTreeLeafDepth;
  if (depthGiven) {
    if (depth > static_cast<long>(tree.maxDepth)) {
      rejectDepth(depth, "outside [0, " + std::to_string(tree.maxDepth) +
                                      "] (the bake's contact tree was built with --sdf-depth " +
                                      std::to_string(tree.maxDepth) + ")");
    }
    maxDepth = static_cast<std::uint32_t>(depth);
  }

  std::vector<ContactFieldSample> samples;
  samples.reserve(points.size());
  for (const Vec3& p : points) samples.push_back(tree.sample(p, maxDepth));

  if (options.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const ContactFieldSample& s : samples) {
      out.push_back({{"distance", s.distance},
                     {"gradient", toJson(s.gradient)},
                     {"error_bound", s.errorBound},
                     {"depth", s.depth},
                     {"inside_root", s.insideRoot}});
    }
    printJson(out);
    return 0;
  }
  std::ostringstream text;
  text << "contact tree: " << tree.nodeCount() << " cells, error " << tree.errorAbs << " (abs), depth limit "
       << (depthGiven ? std::to_string(maxDepth) : std::string("leaf")) << "\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const ContactFieldSample& s = samples[i];
    text << p.x() << " " << p.y() << " " << p.z() << ": distance " << s.distance << " +- " << s.errorBound
         << ", gradient " << s.gradient.x() << " " << s.gradient.y() << " " << s.gradient.z() << ", depth " << s.depth
         << (s.insideRoot ? "" : " (outside the root cube)") << "\n";
  }
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("sdf", [](CLI::App& app) {
  auto options = std::make_shared<SdfOptions>();
  CLI::App* sub = app.add_subcommand(
      "sdf", "Signed distance, gradient and error bound of the bake's contact tree at query points");
  sub->add_option("bake", options->bakePath, "Bake file (.clod) written by clod bake (with its contact tree)")->required();
  sub->add_option("--points", options->pointsPath, "Text file of query points, x y z per line")->required();
  options->depthOption = sub->add_option("--depth", options->depthValue,
                  "Stop at this octree depth (0 = root cell) for a coarser answer with a larger error bound; "
                  "default: the leaf");
  sub->add_flag("--json", options->json,
                "Print a JSON array, one {distance, gradient, error_bound, depth, inside_root} per query point");
  return [options] { return runSdf(*options); };
});

}  // namespace
}  // namespace clod::cli
