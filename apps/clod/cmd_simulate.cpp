// clod simulate SCENE.json -o OUTDIR [--contact-model M] [--budget N] [--budget-us T] [--progress]: runs a JSON
// scene (scene.h) and writes, as one unit (replaceDirectoryAtomically), OUTDIR/trajectory.csv
// (step,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz; step 0 is the initial state),
// OUTDIR/contacts.csv (step,body_a,body_b,px,py,pz,nx,ny,nz,depth,level; the contacts the solver
// used in the step's last substep; the normal points from body_b toward body_a, contact.h) and
// OUTDIR/summary.json ({"bodies": [{"name", "position", "orientation" [w,x,y,z], "velocity",
// "angular_velocity"}], "energy": [per step, kinetic + potential], "budget_spent": [tests per
// step], "step_seconds": [wall time per step], "tests_total", "left_bounds": [...], ...}). Baked shapes are cached in
// OUTDIR/bake-cache, so a second run starts at once; it and anything else the user keeps in OUTDIR are
// carried over into the new OUTDIR (atomic_directory.h).
// With --gltf it also writes OUTDIR/scene.glb and OUTDIR/layers.json (docs/viewer-format.md;
// simulation_recorder.h: every step, or at most 60 frames per simulated second), and
// --gltf-layers picks the per-body layers (spheres, cfm, ctree; "none" for frames only).
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "clod/atomic_directory.h"
#include "clod/atomic_file.h"
#include "clod/error.h"
#include "clod/scene.h"
#include "clod/simulation_recorder.h"
#include "command.h"

namespace clod::cli {
namespace {

struct SimulateOptions {
  std::string scene;
  std::string outDir;
  std::string model;
  std::string budget;        // empty: the scene's
  std::string budgetMicros;  // empty: the scene's
  bool progress = false;
  bool gltf = false;
  std::string gltfLayers = "spheres,cfm,ctree";
};

// "spheres,cfm,ctree" (any subset, comma separated) or "none"; anything else is bad usage
// (kInvalidArgument: exit 2), found before any simulation work.
BodyLayerOptions parseGltfLayers(const std::string& text) {
  BodyLayerOptions o;
  o.sphereTree = o.cfmSamples = o.contactTree = false;
  if (text == "none") return o;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "spheres") o.sphereTree = true;
    else if (item == "cfm") o.cfmSamples = true;
    else if (item == "ctree") o.contactTree = true;
    else
      throw Error(ErrorCode::kInvalidArgument,
                  "--gltf-layers: unknown layer '" + item + "' (expected spheres, cfm, ctree, or none)");
  }
  return o;
}

// `name` is already a CSV field (csvField).
void appendState(std::ostringstream& out, std::uint32_t step, double time, const std::string& name,
                 const RigidBodyState& s) {
  out << step << ',' << time << ',' << name << ',' << s.position.x() << ',' << s.position.y() << ','
      << s.position.z() << ',' << s.orientation.w() << ',' << s.orientation.x() << ',' << s.orientation.y() << ','
      << s.orientation.z() << ',' << s.velocity.x() << ',' << s.velocity.y() << ',' << s.velocity.z() << ','
      << s.angularVelocity.x() << ',' << s.angularVelocity.y() << ',' << s.angularVelocity.z() << '\n';
}

int runSimulate(const SimulateOptions& o) {
  // Usage errors first (exit 2), before the scene is read.
  const BodyLayerOptions layerOptions = parseGltfLayers(o.gltfLayers);
  std::optional<std::uint64_t> budget;
  std::optional<double> budgetMicros;
  if (!o.budget.empty()) budget = parseCountOption(o.budget, "--budget", 0, UINT64_MAX);
  if (!o.budgetMicros.empty()) budgetMicros = parseNumberOption(o.budgetMicros, "--budget-us", 0.0, 1e9);
  std::optional<ContactModel> model;
  if (!o.model.empty()) model = parseContactModel(o.model);
  SceneDescription scene = loadScene(o.scene);
  if (model) scene.world.model = *model;
  if (budget) scene.world.budgetTests = *budget;
  if (budgetMicros) scene.world.budgetMicros = *budgetMicros;
  const std::filesystem::path out(o.outDir);
  checkOutputDirectory(out);  // a file or device as OUTDIR: refused before the work
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw Error(ErrorCode::kFileWriteFailed, o.outDir + ": cannot create directory: " + ec.message());
  SceneBuildReport build;
  World world = buildWorld(scene, out / "bake-cache", &build);
  std::vector<std::string> names, csvNames;  // csvNames: quoted for the CSV files (RFC 4180)
  for (const SceneBody& b : scene.bodies) {
    names.push_back(b.name);
    csvNames.push_back(csvField(b.name));
  }

  std::ostringstream traj, contacts;
  traj.precision(17);
  contacts.precision(17);
  traj << "step,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n";
  contacts << "step,body_a,body_b,px,py,pz,nx,ny,nz,depth,level\n";
  for (BodyId i = 0; i < world.bodyCount(); ++i) appendState(traj, 0, 0.0, csvNames[i], world.state(i));
  std::optional<SimulationRecorder> recorder;
  if (o.gltf) recorder.emplace(world, names, scene.dt, scene.steps);
  nlohmann::json stepSeconds = nlohmann::json::array();
  nlohmann::json energy = nlohmann::json::array(), spent = nlohmann::json::array(), left = nlohmann::json::array();
  std::uint64_t testsTotal = 0, skipped = 0, interrupted = 0, fallbackPairs = 0;
  const auto start = std::chrono::steady_clock::now();
  bool barShown = false;
  for (std::uint32_t step = 1; step <= scene.steps; ++step) {
    applyConstantTorques(scene, world);
    const auto stepStart = std::chrono::steady_clock::now();
    const StepReport& r = world.step(scene.dt);
    stepSeconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - stepStart).count());
    const double time = step * scene.dt;
    if (recorder) recorder->recordStep(step, r);
    for (BodyId i = 0; i < world.bodyCount(); ++i) appendState(traj, step, time, csvNames[i], world.state(i));
    for (std::size_t c = 0; c < r.contacts.size(); ++c) {
      const Contact& k = r.contacts[c];
      contacts << step << ',' << csvNames[r.contactBodies[c][0]] << ',' << csvNames[r.contactBodies[c][1]] << ','
               << k.point.x() << ',' << k.point.y() << ',' << k.point.z() << ',' << k.normal.x() << ','
               << k.normal.y() << ',' << k.normal.z() << ',' << k.depth << ',' << k.level << '\n';
    }
    energy.push_back(world.kineticEnergy() + world.potentialEnergy());
    spent.push_back(r.testsSpent);
    testsTotal += r.testsSpent;
    skipped += r.pairsSkipped;
    interrupted += r.pairsInterrupted;
    fallbackPairs += r.fallbackPairs;
    for (BodyId b : r.leftBounds) {
      left.push_back({{"body", names[b]}, {"step", step}});
      std::cerr << "clod: warning: body '" << names[b] << "' left the world bounds at step " << step
                << " (frozen there)\n";
    }
    // Progress bar once the run has taken a couple of seconds (or always with --progress).
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if ((o.progress || elapsed > 2.0) && (step % 10 == 0 || step == scene.steps)) {
      const int width = 40, filled = int(width * double(step) / scene.steps);
      std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ') << "] " << step << '/'
                << scene.steps << std::flush;
      barShown = true;
    }
  }
  if (barShown) std::cerr << '\n';
  nlohmann::json bodies = nlohmann::json::array();
  for (BodyId i = 0; i < world.bodyCount(); ++i) {
    const RigidBodyState s = world.state(i);
    bodies.push_back({{"name", names[i]},
                      {"position", toJson(s.position)},
                      {"orientation", {s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z()}},
                      {"velocity", toJson(s.velocity)},
                      {"angular_velocity", toJson(s.angularVelocity)}});
  }
  nlohmann::json summary = {{"bodies", bodies},
                            {"steps", scene.steps},
                            {"dt", scene.dt},
                            {"contact_model", std::string(contactModelName(scene.world.model))},
                            {"budget", scene.world.budgetTests},
                            {"budget_us", scene.world.budgetMicros},
                            {"energy", energy},
                            {"budget_spent", spent},
                            {"step_seconds", stepSeconds},
                            {"tests_total", testsTotal},
                            {"pair_queries_skipped", skipped},
                            {"pair_queries_interrupted", interrupted},
                            {"exact_fallback_pairs", fallbackPairs},
                            {"left_bounds", left},
                            {"shapes_baked", build.shapesBaked},
                            {"shapes_from_cache", build.shapesFromCache},
                            {"bake_seconds", build.bakeSeconds},
                            {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
  // Encode the viewer files before writing anything, so an export error leaves no new files.
  std::string glb, layersJson;
  if (recorder) {
    glb = encodeGlb(recorder->gltfScene());
    layersJson = encodeDebugLayers(recorder->debugLayers(layerOptions));
  }
  // All five as one unit: a kill never leaves this run's files beside an older run's.
  static const std::string kOwned[] = {"trajectory.csv", "contacts.csv", "summary.json", "scene.glb", "layers.json"};
  replaceDirectoryAtomically(out, kOwned, [&](const std::filesystem::path& staging) {
    writeFileAtomically(staging / "trajectory.csv", traj.str());
    writeFileAtomically(staging / "contacts.csv", contacts.str());
    writeFileAtomically(staging / "summary.json", summary.dump(2) + "\n");
    if (recorder) {
      writeFileAtomically(staging / "scene.glb", glb);
      writeFileAtomically(staging / "layers.json", layersJson);
    }
  });
  std::cout << "simulated " << scene.steps << " steps of " << world.bodyCount() << " bodies -> " << o.outDir << "\n";
  if (recorder) {
    std::cout << "glTF: scene.glb + layers.json, " << recorder->frameCount() << " frames ("
              << (recorder->frameStride() == 1 ? std::string("every step")
                                               : "every " + std::to_string(recorder->frameStride()) +
                                                     " steps, at most 60 per simulated second")
              << ")\n";
  }
  return 0;
}

const CommandRegistration kRegistration("simulate", [](CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* sub = app.add_subcommand("simulate", "Run a JSON scene; write trajectory.csv, contacts.csv, summary.json");
  sub->add_option("scene", options->scene, "Scene file (.json)")->required();
  sub->add_option("-o,--output", options->outDir, "Output directory")->required();
  sub->add_option("--contact-model", options->model, "Override: dos, average, cfm, contact-tree, exact");
  sub->add_option("--budget", options->budget, "Override: tests per frame (0 = unlimited)");
  sub->add_option("--budget-us", options->budgetMicros,
                  "Override: narrow-phase microseconds per frame (0 = unlimited; with --budget both apply)");
  sub->add_flag("--progress", options->progress, "Always show the progress bar on stderr");
  CLI::Option* gltf =
      sub->add_flag("--gltf", options->gltf, "Also write scene.glb (meshes + animation) and layers.json (debug layers)");
  sub->add_option("--gltf-layers", options->gltfLayers,
                  "Per-body layers in layers.json: comma list of spheres, cfm, ctree, or none (default: all three)")
      ->needs(gltf);
  return [options] { return runSimulate(*options); };
});

}  // namespace
}  // namespace clod::cli
