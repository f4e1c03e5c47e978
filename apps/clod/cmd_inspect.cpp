// clod inspect MESH [--json]: load a mesh, validate it, print what was found.
//
// The JSON keys are a stable contract (external checks use them): vertices, triangles, closed,
// boundary_edges, nonmanifold_edges, degenerate_triangles, components, bbox_min, bbox_max,
// volume (null unless the mesh is closed and consistently oriented), warnings; plus extras.
// Counts are after triangulation and welding. Nothing is printed until everything is computed,
// so an error leaves stdout empty.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include "cli_util.h"
#include "clod/error.h"
#include "clod/mass_properties.h"
#include "clod/mesh_io.h"
#include "command.h"

namespace clod::cli {
namespace {

struct InspectOptions {
  std::string path;
  bool json = false;
  double weldToleranceRel = MeshLoadOptions{}.weldToleranceRel;
  bool keepOrientation = false;
  MeshLoadOptions limits;  // --max-vertices, --max-triangles, --max-polygon-vertices
};

nlohmann::json toJson(const Mat3& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

int runInspect(const InspectOptions& options) {
  if (!std::isfinite(options.weldToleranceRel))
    throw Error(ErrorCode::kInvalidArgument, "--weld-tolerance must be a finite number");
  MeshLoadOptions loadOptions = options.limits;
  loadOptions.weldToleranceRel = options.weldToleranceRel;
  loadOptions.orientOutward = !options.keepOrientation;
  LoadedMesh loaded = loadMesh(options.path, loadOptions);
  const MeshReport& r = loaded.report;

  // Mass properties exist only for closed, consistently oriented, non-flat meshes; anything else
  // reports null (validateMesh has already put the reason among the warnings).
  std::optional<MassProperties> mass;
  if (r.closed && r.consistentlyOriented) {
    try {
      mass = computeMassProperties(loaded.mesh);
    } catch (const Error& e) {
      if (e.code() != ErrorCode::kUnsupportedMesh) throw;
      loaded.warnings.push_back(std::string("no mass properties: ") + e.what());
    }
  }
  double area = 0.0;
  for (std::uint32_t t = 0; t < loaded.mesh.triangleCount(); ++t) area += loaded.mesh.triangleArea(t);

  if (options.json) {
    nlohmann::json out;
    out["file"] = options.path;
    out["vertices"] = r.vertexCount;
    out["triangles"] = r.triangleCount;
    out["closed"] = r.closed;
    out["boundary_edges"] = r.boundaryEdges;
    out["nonmanifold_edges"] = r.nonManifoldEdges;
    out["nonmanifold_vertices"] = r.nonManifoldVertices;
    out["degenerate_triangles"] = r.degenerateTriangles;
    out["duplicate_triangles"] = r.duplicateTriangles;
    out["unreferenced_vertices"] = r.unreferencedVertices;
    out["components"] = r.components;
    out["consistently_oriented"] = r.consistentlyOriented;
    out["flipped"] = loaded.flipped;
    out["bbox_min"] = cli::toJson(r.bounds.min);
    out["bbox_max"] = cli::toJson(r.bounds.max);
    out["bbox_diagonal"] = r.bounds.diagonal();
    out["surface_area"] = area;
    out["imported_vertices"] = loaded.importedVertexCount;
    out["welded_vertices"] = loaded.weldedVertexCount;
    out["weld_tolerance"] = loaded.weldToleranceAbs;
    out["volume"] = mass ? nlohmann::json(mass->volume) : nlohmann::json(nullptr);
    out["center_of_mass"] = mass ? cli::toJson(mass->centerOfMass) : nlohmann::json(nullptr);
    out["inertia"] = mass ? toJson(mass->inertia) : nlohmann::json(nullptr);  // density 1, about the centre of mass
    out["warnings"] = loaded.warnings;
    printJson(out);
    return 0;
  }

  std::ostringstream text;
  auto vec = [](const Vec3& v) {
    std::ostringstream s;
    s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return s.str();
  };
  text << options.path << "\n"
       << "  vertices " << r.vertexCount << " (" << loaded.importedVertexCount << " imported, "
       << loaded.weldedVertexCount << " welded), triangles " << r.triangleCount << "\n"
       << "  bbox " << vec(r.bounds.min) << " - " << vec(r.bounds.max) << ", diagonal " << r.bounds.diagonal() << "\n"
       << "  " << (r.closed ? "closed" : "open") << ": " << r.boundaryEdges << " boundary edges, "
       << r.nonManifoldEdges << " non-manifold edges, " << r.nonManifoldVertices << " non-manifold vertices\n"
       << "  " << r.components << " component(s), " << r.degenerateTriangles << " degenerate, " << r.duplicateTriangles
       << " duplicate triangles, orientation " << (r.consistentlyOriented ? "consistent" : "inconsistent")
       << (loaded.flipped ? " (flipped outward)" : "") << "\n"
       << "  surface area " << area << "\n";
  if (mass)
    text << "  volume " << mass->volume << ", centre of mass " << vec(mass->centerOfMass) << "\n";
  else
    text << "  volume: none (not a closed, consistently oriented solid)\n";
  for (const std::string& w : loaded.warnings) text << "  warning: " << w << "\n";
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("inspect", [](CLI::App& app) {
  auto options = std::make_shared<InspectOptions>();
  CLI::App* sub = app.add_subcommand("inspect", "Load a mesh, validate it and report counts, defects and volume");
  sub->add_option("mesh", options->path, "Mesh file (OBJ, STL, PLY, OFF, glTF/GLB)")->required();
  sub->add_flag("--json", options->json, "Print one JSON object (stable keys) instead of text");
  sub->add_option("--weld-tolerance", options->weldToleranceRel,
                  "Weld vertices closer than this times the bounding-box diagonal (0: exact duplicates only, "
                  "negative: no welding)")
      ->capture_default_str();
  sub->add_flag("--keep-orientation", options->keepOrientation, "Do not flip an inside-out closed mesh");
  addMeshLimitOptions(sub, &options->limits);
  return [options] { return runInspect(*options); };
});

}  // namespace
}  // namespace clod::cli
