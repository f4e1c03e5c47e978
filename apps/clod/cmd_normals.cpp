// clod normals BAKE.clod --level L --model dos|average|cfm --points FILE [--json]: the contact
// normal a model gives for a contact at each query point, resolved at sphere-tree level L.
//
// For each point p (mesh coordinates, points_io.h format) the sphere of level L used is, among the
// spheres of that level that contain p (|p - c| <= r), the one whose centre is nearest to p (lowest
// index on ties). A point inside no sphere of the level gets sphere null and normal null: no sphere
// of that level would report a contact there.
//
// The JSON output is a stable contract (external checks use it): a top-level array with one
// object per query point, in file order: {point: [x,y,z], sphere: index or null,
// normal: [x,y,z] or null}. sphere is the global sphere index (breadth-first, as in the bake).
// The normal is contactNormal(model, ...) (contact_normal.h): dos = centre-to-point direction,
// average = the sphere's averaged triangle normal, cfm = the closest feature map's stored normal
// for the direction from the centre to p. The cfm and average models need a bake with closest
// feature maps ('CFMP' section; exit 1 otherwise). --level outside the tree's levels: exit 2.
// Nothing is printed until every point is answered, so an error leaves stdout empty.
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "clod/bake.h"
#include "clod/contact_normal.h"
#include "clod/error.h"
#include "clod/points_io.h"
#include "command.h"

namespace clod::cli {
namespace {

struct NormalsOptions {
  std::string bakePath;
  std::string pointsPath;
  std::string model = "cfm";
  long level = 0;
  bool json = false;
};

struct NormalAnswer {
  Vec3 point;
  std::optional<std::uint32_t> sphere;
  Vec3 normal = Vec3::Zero();
};

int runNormals(const NormalsOptions& options) {
  const ContactNormalModel model = parseContactNormalModel(options.model);
  const std::vector<Vec3> points = readPointsFile(options.pointsPath);
  const BakeContents bake = loadBake(options.bakePath);
  const SphereTree& tree = bake.sphereTree;
  if (options.level < 0 || options.level >= static_cast<long>(tree.levelCount())) {
    throw Error(ErrorCode::kInvalidArgument, "--level " + std::to_string(options.level) + " outside [0, " +
                                                 std::to_string(tree.levelCount() - 1) + "] (the bake's sphere-tree has " +
                                                 std::to_string(tree.levelCount()) + " levels)");
  }
  // D&O needs no map; an empty stand-in keeps one code path (contactNormal reads the map only
  // for average and cfm).
  if (!bake.closestFeatureMap && model != ContactNormalModel::kDingliana) {
    throw Error(ErrorCode::kBakeMissingSection, "'" + options.bakePath + "' has no closest feature maps (section 'CFMP'); "
                                                "model '" + options.model + "' needs them: re-bake with a current clod");
  }
  std::optional<ClosestFeatureMap> dosMaps;
  if (!bake.closestFeatureMap) {
    ClosestFeatureMapData data;
    data.settings.minStacks = 1;
    data.settings.rootStacks = 1;
    data.levelStacks.assign(tree.levelCount(), 1);
    for (std::uint32_t i = 0; i < tree.sphereCount(); ++i) {
      data.sphereOffset.push_back(i);
      data.sphereSingle.push_back(1);
      data.codes16.push_back(0);
      for (int k = 0; k < 3; ++k) data.averageNormals.push_back(0.0f);
    }
    dosMaps = ClosestFeatureMap::fromData(std::move(data), tree);
  }
  const ClosestFeatureMap& maps = bake.closestFeatureMap ? *bake.closestFeatureMap : *dosMaps;

  const auto level = static_cast<std::uint32_t>(options.level);
  std::vector<NormalAnswer> answers;
  answers.reserve(points.size());
  for (const Vec3& p : points) {
    NormalAnswer answer{p, std::nullopt, Vec3::Zero()};
    double best = 0.0;
    for (std::uint32_t i = tree.levelBegin(level); i < tree.levelEnd(level); ++i) {
      const double d = (p - tree.center(i)).norm();
      if (d <= tree.radius[i] && (!answer.sphere || d < best)) {
        answer.sphere = i;
        best = d;
      }
    }
    if (answer.sphere) answer.normal = contactNormal(model, tree, maps, *answer.sphere, p);
    answers.push_back(answer);
  }

  if (options.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const NormalAnswer& a : answers) {
      out.push_back({{"point", toJson(a.point)},
                     {"sphere", a.sphere ? nlohmann::json(*a.sphere) : nlohmann::json(nullptr)},
                     {"normal", a.sphere ? toJson(a.normal) : nlohmann::json(nullptr)}});
    }
    printJson(out);
    return 0;
  }
  std::ostringstream text;
  text << "model " << contactNormalModelName(model) << ", level " << level << "\n";
  for (const NormalAnswer& a : answers) {
    text << a.point.x() << " " << a.point.y() << " " << a.point.z() << ": ";
    if (a.sphere) {
      text << "sphere " << *a.sphere << ", normal " << a.normal.x() << " " << a.normal.y() << " " << a.normal.z() << "\n";
    } else {
      text << "inside no sphere of level " << level << "\n";
    }
  }
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("normals", [](CLI::App& app) {
  auto options = std::make_shared<NormalsOptions>();
  CLI::App* sub = app.add_subcommand(
      "normals", "Contact normal of a model (dos, average, cfm) at query points, resolved at one sphere-tree level");
  sub->add_option("bake", options->bakePath, "Bake file (.clod) written by clod bake")->required();
  sub->add_option("--level", options->level, "Sphere-tree level (0 = root)")->required();
  sub->add_option("--model", options->model, "Contact normal model")
      ->check(CLI::IsMember({"dos", "average", "cfm"}))
      ->capture_default_str();
  sub->add_option("--points", options->pointsPath, "Text file of query points, x y z per line")->required();
  sub->add_flag("--json", options->json,
                "Print a JSON array, one {point, sphere, normal} per query point (null sphere/normal when the "
                "point is inside no sphere of the level)");
  return [options] { return runNormals(*options); };
});

}  // namespace
}  // namespace clod::cli
