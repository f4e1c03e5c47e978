// clod query A.clod B.clod --pose-a "tx ty tz qw qx qy qz" --pose-b "..." --model M [--budget N]
// [--deadline-us T] [--max-contacts K] [--json]: contacts between two baked bodies placed in the
// world by their poses. JSON contract (external checks use it, keep it stable):
//   {"colliding": bool, "contacts": [{"point": [x,y,z], "normal": [x,y,z], "depth": d,
//     "level": l}], "tests": n, "finished": bool, "seconds": s}
// plus informative extras (model, stop, sphere_tests, triangle_tests, min_level, max_level,
// raw_contacts, error_bound per contact). The normal points from B to A; depth > 0 penetrates.
// A bake without the section the model needs is bad data (exit 1) and the message says which
// bake option adds it; unparsable poses or out-of-range options are bad usage (exit 2).
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/error.h"
#include "clod/quaternion.h"
#include "clod/query.h"
#include "command.h"

namespace clod::cli {
namespace {

struct QueryOptions {
  std::string pathA, pathB;
  std::string poseA = "0 0 0 1 0 0 0";
  std::string poseB = "0 0 0 1 0 0 0";
  std::string model = "cfm";
  std::string budget;      // empty: unlimited
  std::string deadlineUs;  // empty: none
  std::string margin;      // empty: 0
  std::int64_t maxContacts = 8;
  bool json = false;
};

Pose parsePose(const std::string& text, const char* option) {
  std::istringstream in(text);
  double v[7];
  for (double& x : v) {
    if (!(in >> x) || !std::isfinite(x)) {
      throw Error(ErrorCode::kInvalidArgument,
                  std::string(option) + " '" + text + "': expected 7 finite numbers \"tx ty tz qw qx qy qz\"");
    }
  }
  std::string rest;
  if (in >> rest) throw Error(ErrorCode::kInvalidArgument, std::string(option) + " '" + text + "': more than 7 numbers");
  const std::optional<Quat> q = unitQuaternion(v[3], v[4], v[5], v[6]);
  if (!q) throw Error(ErrorCode::kInvalidArgument, std::string(option) + " '" + text + "': zero quaternion");
  Pose pose;
  pose.rotation = *q;
  pose.translation = Vec3(v[0], v[1], v[2]);
  return pose;
}

int runQuery(const QueryOptions& options) {
  // Usage errors first (exit 2), before any file is read.
  QuerySettings settings;
  settings.model = parseContactModel(options.model);
  const Pose poseA = parsePose(options.poseA, "--pose-a");
  const Pose poseB = parsePose(options.poseB, "--pose-b");
  if (!options.budget.empty()) {
    settings.budget.maxTests = parseCountOption(options.budget, "--budget", 1, UINT64_MAX);
  }
  if (options.maxContacts < 1 || options.maxContacts > 1024) {
    throw Error(ErrorCode::kInvalidArgument, "--max-contacts " + std::to_string(options.maxContacts) + ": must be 1..1024");
  }
  std::optional<double> deadlineUs;
  if (!options.deadlineUs.empty()) deadlineUs = parseNumberOption(options.deadlineUs, "--deadline-us", 0.0, 1e12);
  settings.maxContacts = static_cast<std::uint32_t>(options.maxContacts);
  if (!options.margin.empty()) settings.marginAbs = parseNumberOption(options.margin, "--margin", 0.0, 1e300);

  CollisionBody a = CollisionBody::fromBake(loadBake(options.pathA));
  CollisionBody b = CollisionBody::fromBake(loadBake(options.pathB));
  if (a.name().empty()) a.setName(options.pathA);
  if (b.name().empty()) b.setName(options.pathB);

  QueryScratch scratch;
  QueryResult result;
  // The deadline starts when the query does, not when the files were read.
  if (deadlineUs) {
    settings.budget.deadline = QueryBudget::microsecondsFromNow(*deadlineUs).deadline;
  }
  queryContacts(a, poseA, b, poseB, settings, scratch, result);

  if (options.json) {
    nlohmann::json contacts = nlohmann::json::array();
    for (const Contact& c : result.contacts) {
      contacts.push_back({{"point", toJson(c.point)},
                          {"normal", toJson(c.normal)},
                          {"depth", c.depth},
                          {"level", c.level},
                          {"error_bound", c.errorBound}});
    }
    printJson({{"colliding", result.colliding},
               {"contacts", contacts},
               {"tests", result.tests},
               {"finished", result.finished},
               {"seconds", result.seconds},
               {"model", std::string(contactModelName(settings.model))},
               {"stop", std::string(queryStopName(result.stop))},
               {"sphere_tests", result.sphereTests},
               {"triangle_tests", result.triangleTests},
               {"min_level", result.minLevel},
               {"max_level", result.maxLevel},
               {"raw_contacts", result.rawContacts}});
    return 0;
  }
  std::ostringstream text;
  text.precision(9);
  text << (result.colliding ? "colliding" : "not colliding") << ", " << result.contacts.size() << " contacts, "
       << result.tests << " tests, " << (result.finished ? "finished" : "stopped: " + std::string(queryStopName(result.stop)))
       << ", levels " << result.minLevel << ".." << result.maxLevel << ", " << result.seconds * 1e6 << " us\n";
  for (const Contact& c : result.contacts) {
    text << "  point " << c.point.x() << " " << c.point.y() << " " << c.point.z() << "  normal " << c.normal.x() << " "
         << c.normal.y() << " " << c.normal.z() << "  depth " << c.depth << "  level " << c.level << "\n";
  }
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("query", [](CLI::App& app) {
  auto options = std::make_shared<QueryOptions>();
  CLI::App* sub = app.add_subcommand("query", "Contacts between two baked bodies (anytime narrow phase)");
  sub->add_option("a", options->pathA, "Bake file (.clod) of body A")->required();
  sub->add_option("b", options->pathB, "Bake file (.clod) of body B")->required();
  sub->add_option("--pose-a", options->poseA, "Pose of A: \"tx ty tz qw qx qy qz\" (mesh -> world)")->capture_default_str();
  sub->add_option("--pose-b", options->poseB, "Pose of B, same form")->capture_default_str();
  sub->add_option("--model", options->model, "Contact model: dos, average, cfm, contact-tree, exact")->capture_default_str();
  sub->add_option("--budget", options->budget, "Most sphere/triangle tests, >= 1 (default: unlimited)");
  sub->add_option("--deadline-us", options->deadlineUs, "Wall-clock deadline in microseconds, >= 0; the traversal stops early enough that turning its frontier into contacts ends by it too (include/clod/budget.h)");
  sub->add_option("--max-contacts", options->maxContacts, "Manifold size, 1..1024")->capture_default_str();
  sub->add_option("--margin", options->margin,
                  "Contact margin, >= 0 (bake units): bodies apart by at most this get a speculative contact at their closest points (depth < 0)");
  sub->add_flag("--json", options->json, "Print the result as JSON (colliding, contacts, tests, finished, seconds)");
  return [options] { return runQuery(*options); };
});

}  // namespace
}  // namespace clod::cli
