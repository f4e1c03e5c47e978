#pragma once
// JSON scenes: a description of a world (settings + bodies) read from a file, and the world
// built from it, with each mesh baked once and cached on disk. The format is in
// docs/dynamics.md ("Scene format"); scenes/ holds the shipped ones.
//
// Top-level keys (all optional except bodies): "gravity" [x,y,z] (default [0,0,-9.81]),
// "dt" (s, default 1/60), "steps" or "duration" (s; default 120 steps), "contact_model"
// (contact.h names, default "cfm"), "budget" (tests per frame, 0 = unlimited), "budget_us"
// (narrow-phase microseconds per frame, WorldSettings::budgetMicros, 0 = unlimited), "max_contacts",
// "max_substeps" (WorldSettings::maxSubsteps, 1..kMaxSceneSubsteps, default 128; caps every
// substep rule, the arrival rule's first-contact floor included: docs/dynamics.md),
// "min_substeps" (WorldSettings::minSubsteps, 1..max_substeps, default 1; a stack gets a substep
// per body up to 8 whatever it says),
// "min_substep_iterations" (WorldSettings::minSubstepIterations, 0..20, default 4),
// "frontier_pair_cost" (WorldSettings::frontierPairCost, 0..1024, default 2),
// "rolling_resistance" (WorldSettings::rollingResistanceRel, 0..1, default 0.003),
// "max_pairs", "max_cached_node_pairs" (WorldSettings's memory limits, defaults 2^20 and 2^23),
// "mesh_limits" {"max_vertices", "max_triangles", "max_polygon_vertices"} (MeshLoadOptions's
// resource limits for every mesh file of the scene, defaults as there),
// "bounds" {"min": [..], "max": [..]}, "bodies" [ ... ]. Body keys: "name", exactly one of
// "mesh" (path relative to the scene file), "box" [hx,hy,hz] (half extents) or "sphere" r (a
// ball: RigidBodyDesc::ballRadius, its mesh makeBallHull's, the solid ball's mass properties);
// "position", "orientation" [w,x,y,z] (any finite, nonzero magnitude: normalised), "velocity",
// "angular_velocity", "torque" [x,y,z] (N m,
// world frame, constant: applyConstantTorques hands it to World::applyTorque before every step),
// "density" or "mass"
// (default density 1000; an open mesh gets the mass properties of its bounding box), "scale"
// (uniform, mesh files only), "static", "kinematic", "restitution", "friction", "bake"
// {"method": "octree"|"medial", "depth", "branching", "contact_tree_depth"}.
//
// Errors: every unknown or duplicate key, wrong type or out-of-range value throws
// clod::Error(kSceneError) whose message starts with the file and the key's path, e.g.
// "scene.json: bodies[3].velocity[1]: expected a number".

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "clod/mesh_io.h"
#include "clod/world.h"

namespace clod {

/// The largest "max_substeps" a scene may ask for (each substep is a broad phase, queries and a
/// solve: beyond this a step's cost is a runaway, not a setting).
inline constexpr std::uint32_t kMaxSceneSubsteps = 4096;

/// How a body's shape is baked (sphere-tree and contact-tree options).
struct SceneBakeOptions {
  std::string method = "octree";  ///< "octree" or "medial"
  std::uint32_t depth = 3;        ///< sphere-tree levels below the root, [0, 8]
  std::uint32_t branching = 8;    ///< [2, 64]
  std::uint32_t contactTreeDepth = 6;  ///< ContactTreeSettings::maxDepth, [1, 12]
};

enum class SceneShapeKind : std::uint8_t { kMesh = 0, kBox = 1, kSphere = 2 };

struct SceneBody {
  std::string name;
  SceneShapeKind shape = SceneShapeKind::kBox;
  std::filesystem::path meshPath;      ///< absolute or relative to the working directory
  double scale = 1.0;                  ///< uniform scale of the mesh file's coordinates (> 0)
  Vec3 halfExtents = Vec3::Constant(0.5);
  double radius = 0.5;
  std::optional<double> mass;          ///< else density
  double density = 1000.0;
  BodyType type = BodyType::kDynamic;
  double restitution = 0.0;
  double friction = 0.5;
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();
  Vec3 angularVelocity = Vec3::Zero();
  Vec3 torque = Vec3::Zero();          ///< constant external torque, world frame (N m for SI scenes)
  SceneBakeOptions bake;
};

struct SceneDescription {
  WorldSettings world;
  /// Options, resource limits included, of every mesh file the scene loads ("mesh_limits").
  MeshLoadOptions meshLoad;
  double dt = 1.0 / 60.0;
  std::uint32_t steps = 120;
  std::vector<SceneBody> bodies;
};

/// Parses scene JSON. `baseDir` resolves relative mesh paths; `fileName` prefixes messages.
/// Throws clod::Error(kSceneError) as described at the top. O(size of the text).
SceneDescription parseScene(std::string_view json, const std::filesystem::path& baseDir,
                            const std::string& fileName = "scene");
/// Reads and parses a scene file (kFileNotFound / kFileUnreadable as readWholeFile).
SceneDescription loadScene(const std::filesystem::path& path);

/// What buildWorld did about baking.
struct SceneBuildReport {
  std::uint32_t shapesBaked = 0;       ///< baked now (cache miss)
  std::uint32_t shapesFromCache = 0;   ///< loaded from cacheDir
  double bakeSeconds = 0.0;
};

/// Builds the world: loads meshes (mesh_io.h), makes primitives (primitives.h), bakes each
/// distinct (mesh, options) once -- reusing `cacheDir`/<mesh hash>-<options>.clod when present,
/// writing it otherwise (atomically) -- adds the contact tree when the model needs it, computes
/// mass properties (mass_properties.h; a given mass scales the density), and adds the bodies in
/// scene order. An empty cacheDir disables the cache. Throws clod::Error from the mesh loader,
/// the baker, or World::addBody (messages name the body).
World buildWorld(const SceneDescription& scene, const std::filesystem::path& cacheDir,
                 SceneBuildReport* report = nullptr);

/// Applies every scene body's constant "torque" (SceneBody::torque, when not zero) to the world
/// built from it by buildWorld (body i = scene body i) through World::applyTorque: call it before
/// each World::step, which clears applied torques at its end. O(bodies).
void applyConstantTorques(const SceneDescription& scene, World& world);

}  // namespace clod
