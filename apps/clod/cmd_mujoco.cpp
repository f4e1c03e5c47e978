// clod mujoco MODEL.xml -o OUTDIR [--contact-model M] [--budget N] [--budget-us T]
//     [--duration S] [--gltf]: loads an MJCF model and runs it twice, with MuJoCo's own collider
// and with clod as its mesh collider (clod_mujoco, include/clod/mujoco/collider.h), writing each
// run as `clod simulate` writes a scene: OUTDIR/mujoco/ and OUTDIR/clod/ each hold
// trajectory.csv, contacts.csv, summary.json (and with --gltf scene.glb + layers.json for the
// viewer, docs/viewer-format.md), both runs written as one unit (replaceDirectoryAtomically: other
// entries of OUTDIR are carried over). Built only when MuJoCo is found.
//
// A "body" of these files is a geom of the model (what the viewer draws), named by the geom's
// name, else "<body name>/<geom index>": its pose is the geom's, its velocity the geom's
// (mj_objectVelocity, world frame). contacts.csv: body_a = geom1, body_b = geom2 of MuJoCo's
// contact, normal from body_b toward body_a (clod's convention, contact.h: MuJoCo's frame normal
// negated), depth = -dist, level 0. Duration: --duration, else the model's
// <custom><numeric name="clod_duration" data="S"/></custom>, else 2 s. Summary extras:
// "collider" (mujoco or clod), "final": positions of the moving geoms. The sphere-trees clod
// bakes have ColliderSettings' default depth, or the model's
// <numeric name="clod_sphere_tree_depth" data="D"/> (1..8; the nut-on-bolt demo uses 4).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "clod/atomic_directory.h"
#include "clod/atomic_file.h"
#include "clod/debug_layers.h"
#include "clod/error.h"
#include "clod/gltf_export.h"
#include "clod/mujoco/collider.h"
#include "clod/primitives.h"
#include "clod/simulation_recorder.h"
#include "command.h"

namespace clod::cli {
namespace {

struct MujocoOptions {
  std::string model;
  std::string outDir;
  std::string contactModel = "exact";
  std::string budget = "0";
  std::string budgetMicros = "0";
  std::string duration;
  bool gltf = false;
};

Pose geomPose(const mjData* d, int g) {
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> r(d->geom_xmat + 9 * g);
  return {Quat(Mat3(r)).normalized(), Vec3(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2])};
}

// The triangle mesh the viewer draws for a geom (MuJoCo's own shapes triangulated).
std::optional<TriangleMesh> geomMesh(const mjModel* m, int g) {
  const mjtNum* s = m->geom_size + 3 * g;
  switch (m->geom_type[g]) {
    case mjGEOM_MESH: {
      const int id = m->geom_dataid[g];
      TriangleMesh mesh;
      for (int v = 0; v < m->mesh_vertnum[id]; ++v) {
        const float* p = m->mesh_vert + 3 * (m->mesh_vertadr[id] + v);
        mesh.vertices.emplace_back(p[0], p[1], p[2]);
      }
      for (int f = 0; f < m->mesh_facenum[id]; ++f) {
        const int* t = m->mesh_face + 3 * (m->mesh_faceadr[id] + f);
        mesh.triangles.push_back({std::uint32_t(t[0]), std::uint32_t(t[1]), std::uint32_t(t[2])});
      }
      return mesh;
    }
    case mjGEOM_BOX: return makeBox(Vec3(s[0], s[1], s[2]));
    case mjGEOM_SPHERE: return makeIcosphere(s[0], 2);
    case mjGEOM_CYLINDER: return makeCylinder(s[0], s[1], 32);
    case mjGEOM_CAPSULE: return makeCylinder(s[0], s[1] + s[0], 32);  // drawn as its bounding cylinder
    case mjGEOM_PLANE: {
      // A thin slab under the plane, as large as the plane's drawn size (or 1 m when infinite).
      const double hx = s[0] > 0 ? s[0] : 1.0, hy = s[1] > 0 ? s[1] : 1.0, hz = 0.001;
      TriangleMesh slab = makeBox(Vec3(hx, hy, hz));
      for (Vec3& v : slab.vertices) v.z() -= hz;
      return slab;
    }
    default: return std::nullopt;  // ellipsoid, height field: not drawn
  }
}

struct RunReport {
  nlohmann::json final = nlohmann::json::object();
  std::vector<std::pair<std::string, std::string>> files;  ///< name, content: written with the other run's
};

void appendRow(std::ostringstream& out, std::uint32_t step, double time, const std::string& name, const Pose& p,
               const mjtNum velocity[6]) {
  // mj_objectVelocity gives (angular, linear).
  out << step << ',' << time << ',' << name << ',' << p.translation.x() << ',' << p.translation.y() << ','
      << p.translation.z() << ',' << p.rotation.w() << ',' << p.rotation.x() << ',' << p.rotation.y() << ','
      << p.rotation.z() << ',' << velocity[3] << ',' << velocity[4] << ',' << velocity[5] << ',' << velocity[0] << ','
      << velocity[1] << ',' << velocity[2] << '\n';
}

RunReport runOnce(const mjModel* m, mujoco::Collider* collider, const MujocoOptions& o, std::uint32_t steps) {
  mujoco::DataPtr data(mj_makeData(m));
  if (!data) throw Error(ErrorCode::kInvalidArgument, o.model + ": MuJoCo could not allocate the model's data");
  mjData* d = data.get();
  if (collider) collider->install();
  struct Uninstall {
    mujoco::Collider* c;
    ~Uninstall() {
      if (c) c->uninstall();
    }
  } uninstall{collider};
  mj_forward(m, d);

  // The geoms drawn and recorded, with their names (CSV-quoted copies for the CSV files).
  std::vector<int> geoms;
  std::vector<std::string> names, csvNames;
  std::vector<TriangleMesh> meshes;
  std::vector<bool> isStatic;
  for (int g = 0; g < m->ngeom; ++g) {
    std::optional<TriangleMesh> mesh = geomMesh(m, g);
    if (!mesh || mesh->triangles.empty()) continue;
    const char* geomName = mj_id2name(m, mjOBJ_GEOM, g);
    const char* bodyName = mj_id2name(m, mjOBJ_BODY, m->geom_bodyid[g]);
    std::string name = geomName ? geomName : std::string(bodyName ? bodyName : "world") + "/" + std::to_string(g);
    geoms.push_back(g);
    csvNames.push_back(csvField(name));
    names.push_back(std::move(name));
    meshes.push_back(std::move(*mesh));
    isStatic.push_back(m->body_weldid[m->geom_bodyid[g]] == 0);  // welded to the world: never moves
  }
  std::vector<int> geomIndex(std::size_t(m->ngeom), -1);
  for (std::size_t i = 0; i < geoms.size(); ++i) geomIndex[geoms[i]] = int(i);

  const double dt = m->opt.timestep;
  const std::uint32_t stride = std::max<std::uint32_t>(1, std::uint32_t(std::ceil(1.0 / (kMaxFramesPerSecond * dt) - 1e-9)));
  std::ostringstream traj, contacts;
  traj.precision(17);
  contacts.precision(17);
  traj << "step,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n";
  contacts << "step,body_a,body_b,px,py,pz,nx,ny,nz,depth,level\n";
  FrameSeries frames;
  std::vector<std::vector<Pose>> keyframes(geoms.size());
  std::vector<double> keyTimes;
  nlohmann::json energy = nlohmann::json::array(), spent = nlohmann::json::array(), stepSeconds = nlohmann::json::array();
  std::uint64_t testsTotal = 0, skipped = 0, interrupted = 0;

  auto record = [&](std::uint32_t step) {
    const double time = step * dt;
    for (std::size_t i = 0; i < geoms.size(); ++i) {
      mjtNum velocity[6];
      mj_objectVelocity(m, d, mjOBJ_GEOM, geoms[i], velocity, 0);
      appendRow(traj, step, time, csvNames[i], geomPose(d, geoms[i]), velocity);
    }
    std::uint32_t contactCount = 0;
    const bool frame = o.gltf && (step % stride == 0 || step == steps);  // + the last step
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& k = d->contact[c];
      const int a = geomIndex[k.geom1], b = geomIndex[k.geom2];
      const std::string nameA = a >= 0 ? csvNames[a] : std::to_string(k.geom1);
      const std::string nameB = b >= 0 ? csvNames[b] : std::to_string(k.geom2);
      if (step > 0) {
        contacts << step << ',' << nameA << ',' << nameB << ',' << k.pos[0] << ',' << k.pos[1] << ',' << k.pos[2]
                 << ',' << -k.frame[0] << ',' << -k.frame[1] << ',' << -k.frame[2] << ',' << -k.dist << ",0\n";
        ++contactCount;
      }
      if (frame && step > 0) {
        const float values[7] = {float(k.pos[0]), float(k.pos[1]), float(k.pos[2]), float(-k.frame[0]),
                                 float(-k.frame[1]), float(-k.frame[2]), float(-k.dist)};
        frames.contactData.insert(frames.contactData.end(), values, values + 7);
      }
    }
    if (frame) {
      frames.time.push_back(time);
      frames.step.push_back(step);
      frames.kineticEnergy.push_back(d->energy[1]);
      frames.potentialEnergy.push_back(d->energy[0]);
      frames.contacts.push_back(contactCount);
      const mujoco::StepStats s = collider ? collider->lastStep(d) : mujoco::StepStats{};
      frames.testsSpent.push_back(s.testsSpent);
      frames.testsBudget.push_back(s.testsBudget);
      frames.contactOffsets.push_back(std::uint32_t(frames.contactData.size() / 7));
      keyTimes.push_back(time);
      for (std::size_t i = 0; i < geoms.size(); ++i) keyframes[i].push_back(geomPose(d, geoms[i]));
    }
  };
  record(0);
  const auto start = std::chrono::steady_clock::now();
  for (std::uint32_t step = 1; step <= steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    mj_step(m, d);
    stepSeconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    for (int i = 0; i < mjNWARNING; ++i)
      if (d->warning[i].number > 0 && i == mjWARN_BADQACC)
        throw Error(ErrorCode::kSimulationDiverged, o.model + ": MuJoCo reported a bad acceleration at step " +
                                                        std::to_string(step));
    record(step);
    energy.push_back(d->energy[0] + d->energy[1]);
    const mujoco::StepStats s = collider ? collider->lastStep(d) : mujoco::StepStats{};
    spent.push_back(s.budgetSpent);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (collider) {
    const mujoco::StepStats t = collider->totals(d);
    testsTotal = t.testsSpent;
    skipped = t.pairsSkipped;
    interrupted = t.pairsInterrupted;
  }

  RunReport report;
  nlohmann::json bodies = nlohmann::json::array();
  for (std::size_t i = 0; i < geoms.size(); ++i) {
    const Pose p = geomPose(d, geoms[i]);
    mjtNum velocity[6];
    mj_objectVelocity(m, d, mjOBJ_GEOM, geoms[i], velocity, 0);
    bodies.push_back({{"name", names[i]},
                      {"position", toJson(p.translation)},
                      {"orientation", {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()}},
                      {"velocity", {velocity[3], velocity[4], velocity[5]}},
                      {"angular_velocity", {velocity[0], velocity[1], velocity[2]}},
                      {"static", bool(isStatic[i])}});
    if (!isStatic[i]) report.final[names[i]] = toJson(p.translation);
  }
  const mujoco::ColliderSettings* cs = collider ? &collider->settings() : nullptr;
  nlohmann::json summary = {{"bodies", bodies},
                            {"collider", collider ? "clod" : "mujoco"},
                            {"mujoco_version", mj_versionString()},
                            {"steps", steps},
                            {"dt", dt},
                            {"contact_model", cs ? std::string(contactModelName(cs->model)) : "mujoco-convex"},
                            {"budget", cs ? cs->budgetTests : 0},
                            {"budget_us", cs ? cs->budgetMicros : 0.0},
                            {"energy", energy},
                            {"budget_spent", spent},
                            {"step_seconds", stepSeconds},
                            {"tests_total", testsTotal},
                            {"pair_queries_skipped", skipped},
                            {"pair_queries_interrupted", interrupted},
                            {"left_bounds", nlohmann::json::array()},
                            {"final", report.final},
                            {"seconds", seconds}};
  std::string glb, layersJson;
  if (o.gltf) {
    GltfScene scene;
    scene.keyTimes = keyTimes;
    for (std::size_t i = 0; i < geoms.size(); ++i) {
      GltfBody body;
      body.name = names[i];
      body.mesh = &meshes[i];
      body.isStatic = isStatic[i];
      body.initialPose = keyframes[i].front();
      if (!isStatic[i]) body.keyframes = keyframes[i];
      scene.bodies.push_back(std::move(body));
    }
    glb = encodeGlb(scene);
    DebugLayers layers;
    layers.frames = std::move(frames);
    layersJson = encodeDebugLayers(layers);
  }
  report.files = {{"trajectory.csv", traj.str()}, {"contacts.csv", contacts.str()}, {"summary.json", summary.dump(2) + "\n"}};
  if (o.gltf) {
    report.files.emplace_back("scene.glb", std::move(glb));
    report.files.emplace_back("layers.json", std::move(layersJson));
  }
  return report;
}

int runMujoco(const MujocoOptions& o) {
  // Usage errors first (exit 2), before the model is read.
  mujoco::ColliderSettings settings;
  settings.model = parseContactModel(o.contactModel);
  settings.budgetTests = parseCountOption(o.budget, "--budget", 0, UINT64_MAX);
  settings.budgetMicros = parseNumberOption(o.budgetMicros, "--budget-us", 0.0, 1e9);
  std::optional<double> duration;
  if (!o.duration.empty()) duration = parseNumberOption(o.duration, "--duration", 1e-9, 1e6);
  mujoco::ModelPtr model = mujoco::loadModel(o.model);
  mjModel* m = model.get();
  m->opt.enableflags |= mjENBL_ENERGY;  // kinetic and potential energy for the summary and viewer
  if (!duration) {
    duration = 2.0;
    const int id = mj_name2id(m, mjOBJ_NUMERIC, "clod_duration");
    if (id >= 0 && m->numeric_size[id] >= 1) duration = m->numeric_data[m->numeric_adr[id]];
    if (!(*duration > 0.0) || !std::isfinite(*duration) || *duration > 1e6)
      throw Error(ErrorCode::kParseError, o.model + ": numeric clod_duration " + std::to_string(*duration) +
                                              " is not a positive number of seconds");
  }
  if (const int id = mj_name2id(m, mjOBJ_NUMERIC, "clod_sphere_tree_depth"); id >= 0 && m->numeric_size[id] >= 1) {
    const double depth = m->numeric_data[m->numeric_adr[id]];
    if (!(depth >= 1.0 && depth <= 8.0) || depth != std::floor(depth))
      throw Error(ErrorCode::kParseError,
                  o.model + ": numeric clod_sphere_tree_depth " + std::to_string(depth) + " is not an integer in [1, 8]");
    settings.sphereTree.depth = std::uint32_t(depth);
  }
  const std::uint32_t steps = std::max<std::uint32_t>(1, std::uint32_t(std::llround(*duration / m->opt.timestep)));
  mujoco::Collider collider(settings);
  const auto bakeStart = std::chrono::steady_clock::now();
  collider.addModel(m);
  const double bakeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - bakeStart).count();
  const std::filesystem::path out(o.outDir);
  checkOutputDirectory(out);
  const RunReport own = runOnce(m, nullptr, o, steps);
  const RunReport withClod = runOnce(m, &collider, o, steps);
  // Both runs as one unit: OUTDIR/mujoco and OUTDIR/clod never come from different invocations.
  static const std::string kOwned[] = {"mujoco", "clod"};
  replaceDirectoryAtomically(out, kOwned, [&](const std::filesystem::path& staging) {
    for (const auto& [name, run] : {std::pair{"mujoco", &own}, std::pair{"clod", &withClod}}) {
      std::error_code ec;
      if (!std::filesystem::create_directory(staging / name, ec))
        throw Error(ErrorCode::kFileWriteFailed, (staging / name).string() + ": cannot create directory: " + ec.message());
      for (const auto& [file, content] : run->files) writeFileAtomically(staging / name / file, content);
    }
  });
  std::cout << "simulated " << steps << " steps (" << *duration << " s) twice -> " << o.outDir << "/mujoco, "
            << o.outDir << "/clod (" << collider.bakedShapes() << " shapes baked in " << bakeSeconds << " s)\n";
  for (auto it = own.final.begin(); it != own.final.end(); ++it) {
    const auto& a = it.value();
    const auto& b = withClod.final.at(it.key());
    std::cout << "  " << it.key() << ": mujoco (" << a[0] << ", " << a[1] << ", " << a[2] << ")  clod (" << b[0] << ", "
              << b[1] << ", " << b[2] << ")\n";
  }
  if (!collider.lastError().empty()) std::cerr << "clod: warning: a pair fell back to MuJoCo: " << collider.lastError() << "\n";
  return 0;
}

const CommandRegistration kRegistration("mujoco", [](CLI::App& app) {
  auto options = std::make_shared<MujocoOptions>();
  CLI::App* sub = app.add_subcommand(
      "mujoco", "Run an MJCF model with MuJoCo's collider and with clod's; write both runs like `clod simulate`");
  sub->add_option("model", options->model, "MJCF model (.xml)")->required();
  sub->add_option("-o,--output", options->outDir, "Output directory (gets mujoco/ and clod/)")->required();
  sub->add_option("--contact-model", options->contactModel, "dos, average, cfm, contact-tree, exact (default exact)");
  sub->add_option("--budget", options->budget, "Tests per mj_step for all mesh pairs (0 = unlimited)");
  sub->add_option("--budget-us", options->budgetMicros, "Narrow-phase microseconds per mj_step (0 = unlimited)");
  sub->add_option("--duration", options->duration, "Seconds to simulate (default: the model's clod_duration, else 2)");
  sub->add_flag("--gltf", options->gltf, "Also write scene.glb and layers.json (frames + contacts) for the viewer");
  return [options] { return runMujoco(*options); };
});

}  // namespace
}  // namespace clod::cli
