// Scene JSON -> SceneDescription -> World. Validation walks the JSON by hand so every error can
// name the key's path (nlohmann's own exceptions cannot).
#include "clod/scene.h"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include "clod/atomic_file.h"
#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/error.h"
#include "clod/mass_properties.h"
#include "clod/mesh_io.h"
#include "clod/mesh_validation.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/quaternion.h"
#include "clod/sphere_tree_builder.h"

namespace clod {
namespace {

using Json = nlohmann::json;

struct Reader {
  std::string file;
  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw Error(ErrorCode::kSceneError, file + ": " + path + ": " + what);
  }
  double number(const Json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "expected a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "expected a finite number");
    return v;
  }
  double nonNegative(const Json& j, const std::string& path) const {
    const double v = number(j, path);
    if (v < 0.0) fail(path, "expected a number >= 0");
    return v;
  }
  double positive(const Json& j, const std::string& path) const {
    const double v = number(j, path);
    if (v <= 0.0) fail(path, "expected a number > 0");
    return v;
  }
  std::uint64_t count(const Json& j, const std::string& path, std::uint64_t lo, std::uint64_t hi) const {
    if (!j.is_number_integer() && !j.is_number_unsigned()) fail(path, "expected an integer");
    if (j.is_number_integer() && j.get<std::int64_t>() < 0) fail(path, "expected an integer >= " + std::to_string(lo));
    const std::uint64_t v = j.get<std::uint64_t>();
    if (v < lo || v > hi) fail(path, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  bool boolean(const Json& j, const std::string& path) const {
    if (!j.is_boolean()) fail(path, "expected true or false");
    return j.get<bool>();
  }
  std::string string(const Json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "expected a string");
    return j.get<std::string>();
  }
  template <int N>
  Eigen::Matrix<double, N, 1> vec(const Json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, "expected an array of " + std::to_string(N) + " numbers");
    if (j.size() != N) fail(path, "expected " + std::to_string(N) + " numbers, got " + std::to_string(j.size()));
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = number(j[std::size_t(i)], path + "[" + std::to_string(i) + "]");
    return v;
  }
  void object(const Json& j, const std::string& path, std::initializer_list<const char*> allowed) const {
    if (!j.is_object()) fail(path.empty() ? "(top level)" : path, "expected an object");
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (!ok) fail(path.empty() ? it.key() : path + "." + it.key(), "unknown key");
    }
  }
};

SceneBakeOptions parseBake(const Reader& r, const Json& j, const std::string& path) {
  r.object(j, path, {"method", "depth", "branching", "contact_tree_depth"});
  SceneBakeOptions o;
  if (j.contains("method")) {
    o.method = r.string(j["method"], path + ".method");
    if (o.method != "octree" && o.method != "medial") r.fail(path + ".method", "expected \"octree\" or \"medial\"");
  }
  if (j.contains("depth")) o.depth = std::uint32_t(r.count(j["depth"], path + ".depth", 0, 8));
  if (j.contains("branching")) o.branching = std::uint32_t(r.count(j["branching"], path + ".branching", 2, 64));
  if (j.contains("contact_tree_depth"))
    o.contactTreeDepth = std::uint32_t(r.count(j["contact_tree_depth"], path + ".contact_tree_depth", 1, 12));
  return o;
}

// The same range as the CLI's --max-vertices, --max-triangles, --max-polygon-vertices.
void parseMeshLimits(const Reader& r, const Json& j, const std::string& path, MeshLoadOptions& o) {
  r.object(j, path, {"max_vertices", "max_triangles", "max_polygon_vertices"});
  constexpr std::uint64_t kMost = std::uint64_t(1) << 40;
  if (j.contains("max_vertices")) o.maxVertices = r.count(j["max_vertices"], path + ".max_vertices", 1, kMost);
  if (j.contains("max_triangles")) o.maxTriangles = r.count(j["max_triangles"], path + ".max_triangles", 1, kMost);
  if (j.contains("max_polygon_vertices"))
    o.maxPolygonVertices = r.count(j["max_polygon_vertices"], path + ".max_polygon_vertices", 1, kMost);
}

SceneBody parseBody(const Reader& r, const Json& j, const std::string& path, const std::filesystem::path& baseDir,
                    std::size_t index) {
  r.object(j, path, {"name", "mesh", "box", "sphere", "position", "orientation", "velocity", "angular_velocity",
                     "torque", "density", "mass", "static", "kinematic", "restitution", "friction", "bake", "scale"});
  SceneBody b;
  b.name = j.contains("name") ? r.string(j["name"], path + ".name") : "body" + std::to_string(index);
  const int shapes = int(j.contains("mesh")) + int(j.contains("box")) + int(j.contains("sphere"));
  if (shapes != 1) r.fail(path, "expected exactly one of \"mesh\", \"box\", \"sphere\"");
  if (j.contains("mesh")) {
    b.shape = SceneShapeKind::kMesh;
    const std::filesystem::path p = r.string(j["mesh"], path + ".mesh");
    b.meshPath = p.is_absolute() ? p : baseDir / p;
  } else if (j.contains("box")) {
    b.shape = SceneShapeKind::kBox;
    b.halfExtents = r.vec<3>(j["box"], path + ".box");
    for (int k = 0; k < 3; ++k)
      if (b.halfExtents[k] <= 0.0) r.fail(path + ".box[" + std::to_string(k) + "]", "expected a number > 0");
  } else {
    b.shape = SceneShapeKind::kSphere;
    b.radius = r.positive(j["sphere"], path + ".sphere");
  }
  if (j.contains("scale")) b.scale = r.positive(j["scale"], path + ".scale");
  if (j.contains("position")) b.position = r.vec<3>(j["position"], path + ".position");
  if (j.contains("orientation")) {
    const Eigen::Vector4d q = r.vec<4>(j["orientation"], path + ".orientation");
    const std::optional<Quat> unit = unitQuaternion(q[0], q[1], q[2], q[3]);
    if (!unit) r.fail(path + ".orientation", "quaternion [w,x,y,z] must not be zero");
    b.orientation = *unit;
  }
  if (j.contains("velocity")) b.velocity = r.vec<3>(j["velocity"], path + ".velocity");
  if (j.contains("angular_velocity")) b.angularVelocity = r.vec<3>(j["angular_velocity"], path + ".angular_velocity");
  if (j.contains("torque")) b.torque = r.vec<3>(j["torque"], path + ".torque");
  if (j.contains("density") && j.contains("mass")) r.fail(path, "give \"density\" or \"mass\", not both");
  if (j.contains("density")) b.density = r.positive(j["density"], path + ".density");
  if (j.contains("mass")) b.mass = r.positive(j["mass"], path + ".mass");
  const bool isStatic = j.contains("static") && r.boolean(j["static"], path + ".static");
  const bool isKinematic = j.contains("kinematic") && r.boolean(j["kinematic"], path + ".kinematic");
  if (isStatic && isKinematic) r.fail(path, "a body cannot be both static and kinematic");
  b.type = isStatic ? BodyType::kStatic : (isKinematic ? BodyType::kKinematic : BodyType::kDynamic);
  if (j.contains("restitution")) {
    b.restitution = r.number(j["restitution"], path + ".restitution");
    if (b.restitution < 0.0 || b.restitution > 1.0) r.fail(path + ".restitution", "expected a number in [0, 1]");
  }
  if (j.contains("friction")) b.friction = r.nonNegative(j["friction"], path + ".friction");
  if (j.contains("bake")) b.bake = parseBake(r, j["bake"], path + ".bake");
  return b;
}

// nlohmann::json keeps the last of two equal keys without a word, so {"dt": 0.01, "dt": 0.1}
// would silently run at 0.1. This parser callback follows the parse with a stack of open
// containers and refuses a key its object already has, naming the key's path.
struct DuplicateKeyCheck {
  struct Open {
    bool array = false;
    std::size_t index = 0;           // arrays: elements completed so far
    std::string key;                 // objects: the key being read
    std::set<std::string> keys;      // objects: keys seen
  };
  explicit DuplicateKeyCheck(const Reader& r) : reader(&r) {}
  const Reader* reader;
  std::vector<Open> open;

  std::string path() const {
    std::string p;
    for (const Open& o : open) {
      if (o.array) p += "[" + std::to_string(o.index) + "]";
      else p += (p.empty() ? "" : ".") + o.key;
    }
    return p;
  }
  void valueDone() {
    if (!open.empty() && open.back().array) ++open.back().index;
  }
  bool operator()(Json::parse_event_t event, const Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start: open.emplace_back(); break;
      case Json::parse_event_t::array_start: open.emplace_back().array = true; break;
      case Json::parse_event_t::key: {
        Open& o = open.back();
        o.key = parsed.get<std::string>();
        if (!o.keys.insert(o.key).second) reader->fail(path(), "duplicate key");
        break;
      }
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        open.pop_back();
        valueDone();
        break;
      case Json::parse_event_t::value: valueDone(); break;
    }
    return true;
  }
};

}  // namespace

SceneDescription parseScene(std::string_view text, const std::filesystem::path& baseDir, const std::string& fileName) {
  Reader r{fileName};
  Json j;
  try {
    DuplicateKeyCheck check(r);
    j = Json::parse(text, [&check](int, Json::parse_event_t event, Json& parsed) { return check(event, parsed); });
  } catch (const Json::exception& e) {
    // parse_error, and out_of_range for a number beyond a double ("1E666", found by
    // fuzz_scene_load): both are bad text, not a bug.
    throw Error(ErrorCode::kSceneError, fileName + ": not valid JSON: " + e.what());
  }
  r.object(j, "", {"gravity", "dt", "steps", "duration", "contact_model", "budget", "budget_us", "max_contacts", "max_substeps", "min_substeps",
                  "min_substep_iterations", "frontier_pair_cost", "rolling_resistance", "max_pairs", "max_cached_node_pairs", "mesh_limits",
                  "bounds", "bodies"});
  SceneDescription s;
  if (j.contains("gravity")) s.world.gravity = r.vec<3>(j["gravity"], "gravity");
  if (j.contains("dt")) s.dt = r.positive(j["dt"], "dt");
  if (j.contains("steps") && j.contains("duration")) r.fail("steps", "give \"steps\" or \"duration\", not both");
  if (j.contains("steps")) s.steps = std::uint32_t(r.count(j["steps"], "steps", 1, 100000000));
  if (j.contains("duration")) {
    const double d = r.positive(j["duration"], "duration");
    const double n = std::ceil(d / s.dt - 1e-9);
    if (n > 1e8) r.fail("duration", "more than 1e8 steps");
    s.steps = std::uint32_t(std::max(1.0, n));
  }
  if (j.contains("contact_model")) {
    const std::string m = r.string(j["contact_model"], "contact_model");
    try {
      s.world.model = parseContactModel(m);
    } catch (const Error& e) {
      r.fail("contact_model", e.what());
    }
  }
  if (j.contains("budget")) s.world.budgetTests = r.count(j["budget"], "budget", 0, std::uint64_t(1) << 40);
  if (j.contains("budget_us")) {
    s.world.budgetMicros = r.nonNegative(j["budget_us"], "budget_us");
    if (s.world.budgetMicros > 1e9) r.fail("budget_us", "must be at most 1e9 (microseconds per frame)");
  }
  if (j.contains("max_contacts")) s.world.maxContacts = std::uint32_t(r.count(j["max_contacts"], "max_contacts", 1, 1024));
  // Substeps are the world's cost per step: more than kMaxSceneSubsteps is a runaway scene.
  if (j.contains("max_substeps"))
    s.world.maxSubsteps = std::uint32_t(r.count(j["max_substeps"], "max_substeps", 1, kMaxSceneSubsteps));
  if (j.contains("min_substeps"))
    s.world.minSubsteps = std::uint32_t(r.count(j["min_substeps"], "min_substeps", 1, s.world.maxSubsteps));
  if (j.contains("min_substep_iterations"))
    s.world.minSubstepIterations =
        std::uint32_t(r.count(j["min_substep_iterations"], "min_substep_iterations", 0, s.world.velocityIterations));
  if (j.contains("rolling_resistance")) {
    s.world.rollingResistanceRel = r.nonNegative(j["rolling_resistance"], "rolling_resistance");
    if (s.world.rollingResistanceRel > 1.0) r.fail("rolling_resistance", "must be at most 1 (a fraction of the smaller body's diagonal)");
  }
  if (j.contains("frontier_pair_cost"))
    s.world.frontierPairCost = std::uint32_t(r.count(j["frontier_pair_cost"], "frontier_pair_cost", 0, 1024));
  if (j.contains("max_pairs")) s.world.maxPairs = r.count(j["max_pairs"], "max_pairs", 1, std::uint64_t(1) << 40);
  if (j.contains("max_cached_node_pairs"))
    s.world.maxCachedNodePairs = r.count(j["max_cached_node_pairs"], "max_cached_node_pairs", 0, std::uint64_t(1) << 40);
  if (j.contains("mesh_limits")) parseMeshLimits(r, j["mesh_limits"], "mesh_limits", s.meshLoad);
  if (j.contains("bounds")) {
    r.object(j["bounds"], "bounds", {"min", "max"});
    if (!j["bounds"].contains("min") || !j["bounds"].contains("max")) r.fail("bounds", "needs \"min\" and \"max\"");
    s.world.bounds.min = r.vec<3>(j["bounds"]["min"], "bounds.min");
    s.world.bounds.max = r.vec<3>(j["bounds"]["max"], "bounds.max");
  }
  if (!j.contains("bodies")) r.fail("bodies", "missing (an array of bodies)");
  if (!j["bodies"].is_array()) r.fail("bodies", "expected an array");
  for (std::size_t i = 0; i < j["bodies"].size(); ++i)
    s.bodies.push_back(parseBody(r, j["bodies"][i], "bodies[" + std::to_string(i) + "]", baseDir, i));
  return s;
}

SceneDescription loadScene(const std::filesystem::path& path) {
  const std::string text = readWholeFile(path);
  return parseScene(text, path.parent_path(), path.string());
}

World buildWorld(const SceneDescription& scene, const std::filesystem::path& cacheDir, SceneBuildReport* report) {
  SceneBuildReport rep;
  World world(scene.world);
  const bool needContactTree = scene.world.model == ContactModel::kContactTree;
  std::map<std::string, std::pair<std::shared_ptr<const CollisionBody>, MassProperties>> shapes;
  std::map<std::string, TriangleMesh> meshFiles;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const SceneBody& sb = scene.bodies[i];
    TriangleMesh mesh;
    std::string source;
    if (sb.shape == SceneShapeKind::kMesh) {
      const std::string key = sb.meshPath.string();
      auto it = meshFiles.find(key);
      if (it == meshFiles.end()) it = meshFiles.emplace(key, loadMesh(sb.meshPath, scene.meshLoad).mesh).first;
      mesh = it->second;
      if (sb.scale != 1.0)
        for (Vec3& v : mesh.vertices) v *= sb.scale;
      source = sb.meshPath.filename().string();
    } else if (sb.shape == SceneShapeKind::kBox) {
      mesh = makeBox(sb.halfExtents);
      source = "box";
    } else {
      // A polyhedron around the ball (2 subdivisions, 320 triangles); the world puts the contacts
      // on the ball itself (RigidBodyDesc::ballRadius).
      mesh = makeBallHull(sb.radius, 2);
      source = "sphere";
    }
    const std::uint64_t hash = meshContentHash(mesh);
    char name[96];
    std::snprintf(name, sizeof name, "%016llx-%s-d%u-b%u.clod", static_cast<unsigned long long>(hash),
                  sb.bake.method.c_str(), sb.bake.depth, sb.bake.branching);
    const std::string key = std::string(name) + (needContactTree ? "-ct" + std::to_string(sb.bake.contactTreeDepth) : "");
    auto found = shapes.find(key);
    if (found == shapes.end()) {
      // Checked before the bake so that a fatal finding names its body (a primitive or a scaled
      // mesh whose size is out of range: the bake's own check knows only the mesh).
      try {
        requireValidMesh(mesh);
      } catch (const Error& e) {
        throw Error(e.code(), "body " + std::to_string(i) + " '" + sb.name + "': " + e.what());
      }
      const auto t0 = std::chrono::steady_clock::now();
      std::optional<BakeContents> contents;
      const std::filesystem::path cached = cacheDir.empty() ? std::filesystem::path() : cacheDir / name;
      if (!cached.empty() && std::filesystem::exists(cached)) {
        try {
          contents = loadBake(cached);
          if (contents->meshHash != hash) contents.reset();  // stale: rebake
        } catch (const Error&) {
          contents.reset();  // corrupt cache entries are rebuilt, not fatal
        }
      }
      if (contents) {
        ++rep.shapesFromCache;
      } else {
        BakeSettings bs;
        bs.sphereTree.method = parseSphereTreeMethod(sb.bake.method);
        bs.sphereTree.depth = sb.bake.depth;
        bs.sphereTree.branching = sb.bake.branching;
        bs.measureFit = false;
        bs.buildContactTree = false;  // built below, with the scene's depth, only when a model needs it
        bs.sourceName = source;
        contents = bakeMesh(mesh, bs).contents;
        if (!cached.empty()) {
          std::filesystem::create_directories(cacheDir);
          saveBake(cached, *contents);
        }
        ++rep.shapesBaked;
      }
      auto body = std::make_shared<CollisionBody>(CollisionBody::fromBake(*contents));
      body->setName(source);
      if (needContactTree) {
        ContactTreeSettings ct;
        ct.maxDepth = sb.bake.contactTreeDepth;
        body->setContactTree(buildContactTree(MeshDistance(mesh), ct));
      }
      MassProperties mp = sb.shape == SceneShapeKind::kSphere ? ballMassProperties(sb.radius)
                                                               : computeMassPropertiesOrBoundingBox(mesh);
      rep.bakeSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      found = shapes.emplace(key, std::make_pair(std::shared_ptr<const CollisionBody>(body), mp)).first;
    }
    RigidBodyDesc d;
    d.name = sb.name;
    d.shape = found->second.first;
    d.type = sb.type;
    if (sb.type == BodyType::kDynamic) {
      const MassProperties& mp = found->second.second;
      const double density = sb.mass ? *sb.mass / mp.volume : sb.density;
      d.mass = density * mp.volume;
      d.inertia = density * mp.inertia;  // computed at density 1: inertia scales linearly
      d.centerOfMass = mp.centerOfMass;
    }
    if (sb.shape == SceneShapeKind::kSphere) d.ballRadius = sb.radius;
    d.restitution = sb.restitution;
    d.friction = sb.friction;
    d.position = sb.position;
    d.orientation = sb.orientation;
    d.velocity = sb.velocity;
    d.angularVelocity = sb.angularVelocity;
    world.addBody(d);
  }
  if (report) *report = rep;
  return world;
}

void applyConstantTorques(const SceneDescription& scene, World& world) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].torque != Vec3::Zero()) world.applyTorque(static_cast<BodyId>(i), scene.bodies[i].torque);
  }
}

}  // namespace clod
