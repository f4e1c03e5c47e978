// clod closest MESH --points FILE [--json] [--winding-number]: exact closest point, feature,
// normal and signed distance of a mesh at each query point.
//
// The JSON output is a stable contract (external checks use it): a top-level array with one
// object per query point, in file order, each with
//   distance (unsigned), signed_distance (negative inside), point [x,y,z] (closest surface
//   point), feature {type: "vertex"|"edge"|"face", index}, normal [x,y,z] (outward unit normal
//   of that feature: face normal or angle-weighted pseudonormal), sign_method
//   ("pseudonormal"|"winding_number", the same in every object).
// Vertex indices are mesh vertices after loading (welding), edge indices index
// MeshTopology::edges() of the loaded mesh, face indices are triangles of the loaded mesh.
// Nothing is printed until every query is answered, so an error leaves stdout empty.
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "cli_util.h"
#include "clod/error.h"
#include "clod/mesh_io.h"
#include "clod/points_io.h"
#include "clod/proximity.h"
#include "command.h"

namespace clod::cli {
namespace {

struct ClosestOptions {
  std::string meshPath;
  std::string pointsPath;
  bool json = false;
  bool forceWindingNumber = false;
  MeshLoadOptions limits;  // --max-vertices, --max-triangles, --max-polygon-vertices
};

int runClosest(const ClosestOptions& options) {
  // Points first: a bad points file is reported without paying for the mesh.
  const std::vector<Vec3> points = readPointsFile(options.pointsPath);
  LoadedMesh loaded = loadMesh(options.meshPath, options.limits);
  MeshDistanceSettings settings;
  settings.forceWindingNumber = options.forceWindingNumber;
  const MeshDistance distance(std::move(loaded.mesh), settings);

  std::vector<MeshDistance::Signed> results(points.size());
  tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) { results[i] = distance.signedQuery(points[i]); });
  const char* signMethod = signMethodName(distance.signMethod());

  if (options.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const MeshDistance::Signed& r : results) {
      out.push_back({{"distance", r.closest.distance},
                     {"signed_distance", r.signedDistance},
                     {"point", toJson(r.closest.point)},
                     {"feature", {{"type", featureTypeName(r.closest.feature.type)}, {"index", r.closest.feature.index}}},
                     {"normal", toJson(r.closest.normal)},
                     {"sign_method", signMethod}});
    }
    printJson(out);
    return 0;
  }

  for (const std::string& w : loaded.warnings) std::cerr << "clod: warning: " << w << "\n";
  std::ostringstream text;
  text << "# sign method: " << signMethod << "\n"
       << "# query_x query_y query_z distance signed_distance point_x point_y point_z feature index normal_x "
          "normal_y normal_z\n"
       << std::setprecision(17);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const MeshDistance::Signed& r = results[i];
    const Vec3& q = points[i];
    const Vec3& p = r.closest.point;
    const Vec3& n = r.closest.normal;
    text << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << r.closest.distance << ' ' << r.signedDistance << ' '
         << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << featureTypeName(r.closest.feature.type) << ' '
         << r.closest.feature.index << ' ' << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
  }
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("closest", [](CLI::App& app) {
  auto options = std::make_shared<ClosestOptions>();
  CLI::App* sub = app.add_subcommand(
      "closest", "Exact closest point, closest feature, normal and signed distance of a mesh at query points");
  sub->add_option("mesh", options->meshPath, "Mesh file (OBJ, STL, PLY, OFF, glTF/GLB)")->required();
  sub->add_option("--points", options->pointsPath,
                  "Text file of query points: whitespace-separated 'x y z', one point per line, '#' comments")
      ->required();
  sub->add_flag("--json", options->json,
                "Print a JSON array, one object per point: distance, signed_distance, point, feature {type, "
                "index}, normal, sign_method");
  sub->add_flag("--winding-number", options->forceWindingNumber,
                "Take the sign from the generalized winding number even for closed meshes");
  addMeshLimitOptions(sub, &options->limits);
  return [options] { return runClosest(*options); };
});

}  // namespace
}  // namespace clod::cli
