// world_compare: frame time of a whole scene (default scenes/bin_200.json, the 200-body bin) with
// every clod contact model and per-frame budget, and the same scene in Bullet, in one run.
//
// Why not Google Benchmark: the figures wanted are per-frame distributions of ONE long, stateful
// simulation (median, 99th percentile, max tests per frame, bodies lost), not the mean of many
// repetitions of an identical operation; Google Benchmark would time whole simulations (or hide
// the frame sequence), so this is a plain program that times each frame itself.
//
// Usage (all flags optional):
//   world_compare [--scene FILE] [--cache DIR] [--steps N] [--models dos,cfm,contact-tree,exact]
//                 [--budgets 1024,4096,16384,0] [--budgets-us 1000,3000] (--budgets none: time budgets only) [--bullet gimpact,hull|none]
//                 [--bullet-substeps 1,clod] [--bullet-steps N] [--bullet-iterations N]
//                 [--row-seconds S] [--breakdown 1] [--frames-csv FILE] [--frontier-cost N]
//                 [--min-substep-iterations N]
// --frontier-cost N and --min-substep-iterations N override WorldSettings::frontierPairCost and
// ::minSubstepIterations (defaults: the library's) for experiments.
// --frames-csv FILE writes every clod frame's breakdown figures (the columns of --breakdown) as CSV.
// --breakdown 1 adds, after the table, per clod row the breakdown of the frames at the CPU median,
// at the CPU 99th percentile and of the slowest frame: substeps, pairs, tests, the work the budget
// does not count (frontier pairs sampled / turned into contacts, raw contacts, solver contacts)
// and where the time went (StepReport's broad phase, narrow phase, prepare, solver, integrate).
// --row-seconds (default 180, 0 = no cap) ends a row whose frames have taken S seconds of wall
// time; the row then reports the steps it did ("37 of 240 (capped)") and its outcome columns
// describe the pile at that step, not at the end.
// Budget 0 (or "unlimited") = no budget. Rows go to stdout as a markdown table; progress and
// per-row notes go to stderr. Exit status 2 for bad usage, 1 for bad data (clod::Error).
//
// Fairness of the Bullet peer (stated in docs/benchmarks/world.md):
//  - shapes: the same triangles clod uses (the scene's meshes after "scale") as btGImpactMeshShape
//    (btGImpactCollisionAlgorithm registered) or btConvexHullShape of the same vertices; boxes
//    as btBoxShape, spheres as btSphereShape (exact balls; clod uses a 320-triangle icosphere);
//  - mass, centre of mass and inertia: clod's (World::desc), the mesh moved into its principal
//    frame because btRigidBody takes a diagonal inertia about its centre of mass;
//  - gravity, dt, friction and restitution per body as the scene; the mixing rules set to clod's
//    (geometric-mean friction, larger restitution; rigid_body.h) through Bullet's global combine
//    callbacks; restitution threshold 0.5 m/s and 20 solver iterations as WorldSettings' defaults;
//  - no sleeping (clod has none), split impulses on (Bullet's default; clod also splits);
//  - substeps: a fixed count k per frame (--bullet-substeps), stepSimulation(dt, k, dt / k); clod
//    picks its own per frame (world.h). "clod" = the median over all clod rows' frames of the run
//    (rounded up), i.e. Bullet stepped at clod's typical substep rate.
// Times are per frame, wall (steady_clock) and process CPU time, around World::step or
// btDiscreteDynamicsWorld::stepSimulation only.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "bench_args.h"
#include "clod/error.h"
#include "clod/scene.h"
#include "clod/world.h"

#ifdef CLOD_BENCH_HAVE_BULLET
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletDynamicsCommon.h>
#endif

namespace {

using clod::BodyId;
using clod::Vec3;

struct Options {
  std::string scene = CLOD_SOURCE_DIR "/scenes/bin_200.json";
  std::string cache = CLOD_BINARY_DIR "/world-compare-cache";
  std::uint32_t steps = 0;  // 0 = the scene's
  std::vector<std::string> models = {"dos", "cfm", "contact-tree", "exact"};
  std::vector<std::uint64_t> budgets = {1024, 4096, 16384, 0};
  std::vector<double> budgetsMicros;  // --budgets-us: rows with a narrow-phase time budget instead
  std::vector<std::string> bullet = {"gimpact", "hull"};
  std::vector<std::uint32_t> bulletSubsteps = {1, 0};  // 0 = "clod"
  std::uint32_t bulletSteps = 0;  // 0 = same as clod
  int bulletIterations = 20;
  double rowSeconds = 180.0;  // a row stops after this much wall time (0 = never)
  bool breakdown = false;
  std::string framesCsv;
  std::optional<std::uint32_t> frontierCost, minSubstepIterations;
};

using bench::parseCount;
using bench::splitList;
using bench::UsageError;

Options parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") throw UsageError{""};
    if (i + 1 >= argc) throw UsageError{flag + ": missing value (or unknown flag)"};
    const std::string value = argv[++i];
    if (flag == "--scene") o.scene = value;
    else if (flag == "--cache") o.cache = value;
    else if (flag == "--steps") o.steps = std::uint32_t(parseCount(flag, value));
    else if (flag == "--bullet-steps") o.bulletSteps = std::uint32_t(parseCount(flag, value));
    else if (flag == "--breakdown") o.breakdown = parseCount(flag, value) != 0;
    else if (flag == "--frames-csv") o.framesCsv = value;
    else if (flag == "--frontier-cost") o.frontierCost = std::uint32_t(parseCount(flag, value));
    else if (flag == "--min-substep-iterations") o.minSubstepIterations = std::uint32_t(parseCount(flag, value));
    else if (flag == "--row-seconds") {
      char* end = nullptr;
      o.rowSeconds = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0' || !(o.rowSeconds >= 0.0)) throw UsageError{"--row-seconds: expected seconds >= 0"};
    } else if (flag == "--bullet-iterations") o.bulletIterations = int(std::max<std::uint64_t>(1, parseCount(flag, value)));
    else if (flag == "--models") {
      o.models = value == "none" ? std::vector<std::string>{} : splitList(value);
      for (const std::string& m : o.models) clod::parseContactModel(m);  // throws kInvalidArgument
    } else if (flag == "--budgets") {
      o.budgets.clear();
      if (value != "none")
        for (const std::string& b : splitList(value)) o.budgets.push_back(parseCount(flag, b));
    } else if (flag == "--budgets-us") {
      o.budgetsMicros.clear();
      for (const std::string& b : splitList(value)) {
        char* end = nullptr;
        const double us = std::strtod(b.c_str(), &end);
        if (b.empty() || *end != '\0' || !(us > 0.0 && us <= 1e9)) throw UsageError{"--budgets-us: expected microseconds in (0, 1e9], got '" + b + "'"};
        o.budgetsMicros.push_back(us);
      }
    } else if (flag == "--bullet") {
      o.bullet = value == "none" ? std::vector<std::string>{} : splitList(value);
      for (const std::string& b : o.bullet)
        if (b != "gimpact" && b != "hull") throw UsageError{"--bullet: unknown shape kind '" + b + "' (gimpact, hull, none)"};
    } else if (flag == "--bullet-substeps") {
      o.bulletSubsteps.clear();
      for (const std::string& s : splitList(value)) {
        if (s == "clod") {  // the median of the clod rows' per-frame substep counts (0 marks it)
          o.bulletSubsteps.push_back(0);
          continue;
        }
        const std::uint64_t k = parseCount(flag, s);
        if (k < 1 || k > 128) throw UsageError{"--bullet-substeps: expected 1..128, got '" + s + "'"};
        o.bulletSubsteps.push_back(std::uint32_t(k));
      }
    } else {
      throw UsageError{"unknown flag '" + flag + "'"};
    }
  }
  return o;
}

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Nearest-rank percentile (p in (0, 1]) of a copy of the samples.
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t rank = std::size_t(std::ceil(p * double(v.size())));
  return v[std::min(v.size(), std::max<std::size_t>(rank, 1)) - 1];
}

// One clod frame's StepReport figures (--breakdown).
struct Frame {
  std::uint32_t step = 0;
  double cpu = 0.0;
  std::uint32_t substeps = 0;
  std::uint64_t candidatePairs = 0, tests = 0, spent = 0, skipped = 0, frontierPairs = 0, rawContacts = 0, solverContacts = 0;
  std::uint32_t iterations = 0;
  double broad = 0, narrow = 0, prepare = 0, solver = 0, integrate = 0;
};

// What a row reports. Outcome figures are measured the same way for clod and Bullet.
struct Row {
  std::vector<Frame> frames;  // clod rows
  std::string engine, model, budget;
  std::uint32_t steps = 0;    // asked for
  std::uint32_t stepsRun = 0; // done: fewer when the row hit --row-seconds
  std::vector<double> wall, cpu;
  std::uint64_t maxTests = 0;
  std::uint64_t maxSpent = 0;  // StepReport::budgetSpent: tests + charged contact-tree sampling
  std::vector<double> substeps;
  std::uint32_t leftBounds = 0;   // centre of mass left the scene's bounds (then frozen/removed)
  std::uint32_t outsideBin = 0;   // dynamic bodies whose centre of mass ends outside the bin
  double keEnd = 0.0;             // kinetic energy at the end (J): has the pile settled?
  double meanZ = 0.0;             // mean centre-of-mass height at the end (m), bodies still in
};

// The inside of the bin, from the scene's static boxes (in bin_200.json: the walls' inner faces at
// |x|, |y| = 2.2 m and the floor's top at z = 0). Unbounded sides where a scene has no wall.
struct Bin {
  double xMin = -1e300, xMax = 1e300, yMin = -1e300, yMax = 1e300, zMin = -1e300;
};

Bin binOf(const clod::SceneDescription& scene) {
  // Floor = the static box with the largest x*y footprint; walls = the other static boxes. The
  // interior is bounded by the walls' faces that look toward the floor's centre.
  Bin bin;
  const clod::SceneBody* floor = nullptr;
  for (const clod::SceneBody& b : scene.bodies)
    if (b.type == clod::BodyType::kStatic && b.shape == clod::SceneShapeKind::kBox &&
        (!floor || b.halfExtents.x() * b.halfExtents.y() > floor->halfExtents.x() * floor->halfExtents.y()))
      floor = &b;
  if (!floor) return bin;
  const Vec3 c = floor->position;
  bin.zMin = c.z() + floor->halfExtents.z();
  for (const clod::SceneBody& b : scene.bodies) {
    if (&b == floor || b.type != clod::BodyType::kStatic || b.shape != clod::SceneShapeKind::kBox) continue;
    const Vec3 d = b.position - c;
    if (std::abs(d.x()) > std::abs(d.y())) {
      if (d.x() < 0) bin.xMin = std::max(bin.xMin, b.position.x() + b.halfExtents.x());
      else bin.xMax = std::min(bin.xMax, b.position.x() - b.halfExtents.x());
    } else {
      if (d.y() < 0) bin.yMin = std::max(bin.yMin, b.position.y() + b.halfExtents.y());
      else bin.yMax = std::min(bin.yMax, b.position.y() - b.halfExtents.y());
    }
  }
  return bin;
}

bool insideBin(const Bin& bin, const Vec3& p) {
  return p.x() > bin.xMin && p.x() < bin.xMax && p.y() > bin.yMin && p.y() < bin.yMax && p.z() > bin.zMin;
}

void finishOutcome(Row& row, const Bin& bin, const std::vector<Vec3>& centres) {
  double z = 0.0;
  std::uint32_t in = 0;
  for (const Vec3& p : centres) {
    if (insideBin(bin, p)) {
      z += p.z();
      ++in;
    } else {
      ++row.outsideBin;
    }
  }
  row.meanZ = in ? z / in : 0.0;
}

// True when the row's frames so far took longer than the cap (then the row ends early and says so).
bool overTime(const Row& row, double rowSeconds) {
  double total = 0.0;
  for (double w : row.wall) total += w;
  if (rowSeconds <= 0.0 || total <= rowSeconds) return false;
  std::cerr << "\n  row stopped after " << row.wall.size() << " of " << row.steps << " steps (--row-seconds "
            << rowSeconds << ")\n";
  return true;
}

void progress(const std::string& label, std::uint32_t step, std::uint32_t steps) {
  if (step % 20 == 0 || step == steps) std::cerr << "\r  " << label << ": " << step << '/' << steps << std::flush;
  if (step == steps) std::cerr << '\n';
}

// ---- clod ----

// One template world per model (buildWorld: bake cache, contact trees when the model needs them);
// each budget row then starts from a fresh World with the template's bodies (descs hold the
// initial state and share the baked shapes), so the contact trees are built once per run.
Row runClod(const clod::World& tmpl, const clod::SceneDescription& scene, clod::ContactModel model,
            std::uint64_t budget, double budgetMicros, std::uint32_t steps, double rowSeconds, const Bin& bin,
            const Options& o) {
  clod::WorldSettings ws = scene.world;
  if (o.frontierCost) ws.frontierPairCost = *o.frontierCost;
  if (o.minSubstepIterations) ws.minSubstepIterations = *o.minSubstepIterations;
  ws.model = model;
  ws.budgetTests = budget;
  ws.budgetMicros = budgetMicros;
  clod::World world(ws);
  for (BodyId i = 0; i < tmpl.bodyCount(); ++i) world.addBody(tmpl.desc(i));
  Row row;
  row.engine = "clod";
  row.model = std::string(clod::contactModelName(model));
  row.budget = budgetMicros > 0.0 ? std::to_string(std::llround(budgetMicros)) + " us"
                                  : budget ? std::to_string(budget) : "unlimited";
  row.steps = steps;
  const std::string label = "clod " + row.model + " " + row.budget;
  for (std::uint32_t s = 1; s <= steps; ++s) {
    const double c0 = processCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    const clod::StepReport& r = world.step(scene.dt);
    row.wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    row.cpu.push_back(processCpuSeconds() - c0);
    row.maxTests = std::max(row.maxTests, r.testsSpent);
    row.maxSpent = std::max(row.maxSpent, r.budgetSpent);
    row.frames.push_back(Frame{s, row.cpu.back(), r.substeps, r.candidatePairs, r.testsSpent, r.budgetSpent, r.pairsSkipped,
                               r.frontierPairs, r.rawContacts, r.solverContacts, r.solverIterations,
                               r.broadPhaseSeconds, r.narrowPhaseSeconds, r.prepareSeconds, r.solverSeconds,
                               r.integrateSeconds});
    row.substeps.push_back(r.substeps);
    row.leftBounds += std::uint32_t(r.leftBounds.size());
    row.stepsRun = s;
    progress(label, s, steps);
    if (overTime(row, rowSeconds)) break;
  }
  std::vector<Vec3> centres;
  for (BodyId i = 0; i < world.bodyCount(); ++i) {
    if (tmpl.desc(i).type != clod::BodyType::kDynamic) continue;
    const clod::RigidBodyState st = world.state(i);
    centres.push_back(st.position + st.orientation * tmpl.desc(i).centerOfMass);
  }
  row.keEnd = world.kineticEnergy();
  finishOutcome(row, bin, centres);
  return row;
}

// ---- Bullet ----
#ifdef CLOD_BENCH_HAVE_BULLET

// Box2D / clod mixing rules (rigid_body.h), so both engines see the same pair coefficients.
btScalar combineFrictionLikeClod(const btCollisionObject* a, const btCollisionObject* b) {
  return std::sqrt(a->getFriction() * b->getFriction());
}
btScalar combineRestitutionLikeClod(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getRestitution(), b->getRestitution());
}

// A mesh in its principal frame: vertex' = R^T (vertex - com), so that the inertia is diagonal.
struct BulletMesh {
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> array;
  std::unique_ptr<btCollisionShape> shape;
  clod::Mat3 axes = clod::Mat3::Identity();  // columns: principal axes in mesh coordinates
};

constexpr btScalar kBulletMeshMargin = 0.004f;  // m; Bullet's 0.04 default is 13 % of a 0.3 m body

struct BulletScene {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  std::map<const clod::CollisionBody*, std::unique_ptr<BulletMesh>> meshes;
  std::vector<std::unique_ptr<btCollisionShape>> primitives;
  std::vector<std::unique_ptr<btDefaultMotionState>> motions;
  std::vector<std::unique_ptr<btRigidBody>> bodies;  // scene order
  std::vector<Vec3> inertiaDiag;                     // principal moments (dynamic bodies)
  std::vector<bool> removed;

  BulletScene(const clod::World& tmpl, const clod::SceneDescription& scene, bool hull, int iterations) {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
    gCalculateCombinedFrictionCallback = combineFrictionLikeClod;
    gCalculateCombinedRestitutionCallback = combineRestitutionLikeClod;
    const Vec3& g = scene.world.gravity;
    world.setGravity(btVector3(btScalar(g.x()), btScalar(g.y()), btScalar(g.z())));
    world.getSolverInfo().m_numIterations = iterations;
    world.getSolverInfo().m_restitutionVelocityThreshold = btScalar(scene.world.restitutionThreshold);
    for (BodyId i = 0; i < tmpl.bodyCount(); ++i) addBody(tmpl.desc(i), scene.bodies[i], hull);
    removed.assign(bodies.size(), false);
  }
  ~BulletScene() {
    for (auto& b : bodies)
      if (b->isInWorld()) world.removeRigidBody(b.get());
  }

  BulletMesh& meshFor(const clod::RigidBodyDesc& d, bool hull) {
    auto& slot = meshes[d.shape.get()];
    if (slot) return *slot;
    slot = std::make_unique<BulletMesh>();
    BulletMesh& m = *slot;
    if (d.type == clod::BodyType::kDynamic) {
      // Principal axes of the inertia tensor (symmetric): right-handed so that it is a rotation.
      Eigen::SelfAdjointEigenSolver<clod::Mat3> eig(d.inertia);
      m.axes = eig.eigenvectors();
      if (m.axes.determinant() < 0) m.axes.col(2) = -m.axes.col(2);
    }
    const clod::TriangleMesh& mesh = d.shape->mesh();
    for (const Vec3& v : mesh.vertices) {
      const Vec3 p = m.axes.transpose() * (v - d.centerOfMass);
      for (int k = 0; k < 3; ++k) m.vertices.push_back(btScalar(p[k]));
    }
    if (hull) {
      auto shape = std::make_unique<btConvexHullShape>(m.vertices.data(), int(mesh.vertexCount()), int(3 * sizeof(btScalar)));
      shape->optimizeConvexHull();
      shape->setMargin(kBulletMeshMargin);
      m.shape = std::move(shape);
    } else {
      for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) m.indices.push_back(int(t[k]));
      m.array = std::make_unique<btTriangleIndexVertexArray>(int(mesh.triangleCount()), m.indices.data(), int(3 * sizeof(int)),
                                                             int(mesh.vertexCount()), m.vertices.data(),
                                                             int(3 * sizeof(btScalar)));
      auto shape = std::make_unique<btGImpactMeshShape>(m.array.get());
      shape->setMargin(kBulletMeshMargin);
      shape->updateBound();
      m.shape = std::move(shape);
    }
    return m;
  }

  void addBody(const clod::RigidBodyDesc& d, const clod::SceneBody& sb, bool hull) {
    btCollisionShape* shape = nullptr;
    clod::Mat3 axes = clod::Mat3::Identity();
    Vec3 com = d.centerOfMass;
    if (sb.shape == clod::SceneShapeKind::kBox) {
      primitives.push_back(std::make_unique<btBoxShape>(
          btVector3(btScalar(sb.halfExtents.x()), btScalar(sb.halfExtents.y()), btScalar(sb.halfExtents.z()))));
      shape = primitives.back().get();
      com = Vec3::Zero();  // clod's box mesh is centred: its centre of mass is the origin
    } else if (sb.shape == clod::SceneShapeKind::kSphere) {
      primitives.push_back(std::make_unique<btSphereShape>(btScalar(sb.radius)));
      shape = primitives.back().get();
      com = Vec3::Zero();
    } else {
      BulletMesh& m = meshFor(d, hull);
      shape = m.shape.get();
      axes = m.axes;
    }
    const bool dynamic = d.type == clod::BodyType::kDynamic;
    // Primitives: clod's inertia of a centred box / icosphere is diagonal in mesh axes (up to
    // rounding); meshes: diagonal in the principal frame.
    const Vec3 diag = dynamic ? Vec3((axes.transpose() * d.inertia * axes).diagonal()) : Vec3::Zero();
    inertiaDiag.push_back(diag);
    const Vec3 pos = d.position + d.orientation * com;
    const clod::Quat q = d.orientation * clod::Quat(axes);
    btTransform t;
    t.setOrigin(btVector3(btScalar(pos.x()), btScalar(pos.y()), btScalar(pos.z())));
    t.setRotation(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())));
    motions.push_back(std::make_unique<btDefaultMotionState>(t));
    btRigidBody::btRigidBodyConstructionInfo info(
        dynamic ? btScalar(d.mass) : btScalar(0), motions.back().get(), shape,
        btVector3(btScalar(diag.x()), btScalar(diag.y()), btScalar(diag.z())));
    info.m_friction = btScalar(d.friction);
    info.m_restitution = btScalar(d.restitution);
    bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody& body = *bodies.back();
    if (dynamic) {
      body.setLinearVelocity(btVector3(btScalar(d.velocity.x()), btScalar(d.velocity.y()), btScalar(d.velocity.z())));
      body.setAngularVelocity(
          btVector3(btScalar(d.angularVelocity.x()), btScalar(d.angularVelocity.y()), btScalar(d.angularVelocity.z())));
      body.setActivationState(DISABLE_DEACTIVATION);  // clod has no sleeping
    }
    world.addRigidBody(&body);
  }
};

Row runBullet(const clod::World& tmpl, const clod::SceneDescription& scene, bool hull, std::uint32_t substeps,
              std::uint32_t steps, int iterations, double rowSeconds, const Bin& bin) {
  BulletScene b(tmpl, scene, hull, iterations);
  Row row;
  row.engine = "Bullet 3.24";
  row.model = hull ? "convex hull" : "GImpact";
  row.budget = "-";
  row.steps = steps;
  const std::string label = "Bullet " + row.model + " " + std::to_string(substeps) + " substeps";
  const btScalar dt = btScalar(scene.dt);
  const clod::Aabb& bounds = scene.world.bounds;
  for (std::uint32_t s = 1; s <= steps; ++s) {
    const double c0 = processCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    b.world.stepSimulation(dt, int(substeps), dt / btScalar(substeps));
    row.wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    row.cpu.push_back(processCpuSeconds() - c0);
    row.substeps.push_back(substeps);
    // Same guard rail as clod: a centre of mass leaving the bounds is counted once and the body
    // taken out (clod freezes it), outside the timed region.
    for (std::size_t i = 0; i < b.bodies.size(); ++i) {
      btRigidBody& body = *b.bodies[i];
      if (b.removed[i] || body.getInvMass() == 0) continue;
      const btVector3 p = body.getCenterOfMassPosition();
      const Vec3 c(p.x(), p.y(), p.z());
      if ((c.array() < bounds.min.array()).any() || (c.array() > bounds.max.array()).any()) {
        ++row.leftBounds;
        b.removed[i] = true;
        b.world.removeRigidBody(&body);
      }
    }
    row.stepsRun = s;
    progress(label, s, steps);
    if (overTime(row, rowSeconds)) break;
  }
  std::vector<Vec3> centres;
  for (std::size_t i = 0; i < b.bodies.size(); ++i) {
    const btRigidBody& body = *b.bodies[i];
    if (body.getInvMass() == 0 && !b.removed[i]) continue;
    const btVector3 p = body.getCenterOfMassPosition();
    centres.push_back(Vec3(p.x(), p.y(), p.z()));
    if (b.removed[i]) continue;
    // Kinetic energy with the same masses and principal moments as clod's.
    const btVector3 v = body.getLinearVelocity();
    const btVector3 w = body.getWorldTransform().getBasis().transpose() * body.getAngularVelocity();
    const Vec3& I = b.inertiaDiag[i];
    row.keEnd += 0.5 / double(body.getInvMass()) * double(v.length2()) +
                 0.5 * (I.x() * w.x() * w.x() + I.y() * w.y() * w.y() + I.z() * w.z() * w.z());
  }
  finishOutcome(row, bin, centres);
  return row;
}
#endif

std::string fmt(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string withCommas(std::uint64_t v) {
  const std::string digits = std::to_string(v);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// The narrow phase's wall time per frame (StepReport::narrowPhaseSeconds): for time-budget rows,
// against the budget.
void printNarrowPhaseTimes(const Row& r) {
  std::vector<double> narrow;
  for (const Frame& f : r.frames) narrow.push_back(1e3 * f.narrow);
  std::cout << "narrow phase per frame, " << r.model << " " << r.budget << ": median " << fmt(percentile(narrow, 0.5), 3)
            << " ms, p99 " << fmt(percentile(narrow, 0.99), 3) << " ms, max " << fmt(percentile(narrow, 1.0), 3)
            << " ms\n" << std::flush;
}

void printTable(const std::vector<Row>& rows) {
  std::cout << "| engine | model / shape | budget (tests/frame) | steps | substeps/frame (median) | median ms | p99 ms"
                " | p99/median | max ms | CPU median ms | CPU p99 ms | CPU p99/median | max tests/frame | max spent/frame | left bounds | outside bin at end"
               " | KE at end J | mean z at end m |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    const double med = 1e3 * percentile(r.wall, 0.5), p99 = 1e3 * percentile(r.wall, 0.99);
    const double mx = 1e3 * percentile(r.wall, 1.0);
    const double cmed = percentile(r.cpu, 0.5), cp99 = percentile(r.cpu, 0.99);
    std::cout << "| " << r.engine << " | " << r.model << " | " << r.budget << " | "
              << (r.stepsRun == r.steps ? std::to_string(r.steps)
                                        : std::to_string(r.stepsRun) + " of " + std::to_string(r.steps) + " (capped)")
              << " | "
              << fmt(percentile(r.substeps, 0.5), 0) << " | " << fmt(med, 2) << " | " << fmt(p99, 2) << " | "
              << fmt(med > 0 ? p99 / med : 0.0, 2) << " | " << fmt(mx, 2) << " | "
              << fmt(1e3 * cmed, 2) << " | " << fmt(1e3 * cp99, 2) << " | " << fmt(cmed > 0 ? cp99 / cmed : 0.0, 2)
              << " | "
              << (r.engine == "clod" ? withCommas(r.maxTests) : std::string("-")) << " | "
              << (r.engine == "clod" ? withCommas(r.maxSpent) : std::string("-")) << " | " << r.leftBounds << " | "
              << r.outsideBin << " | " << fmt(r.keEnd, 3) << " | " << fmt(r.meanZ, 3) << " |\n";
  }
  std::cout << std::flush;
}

// Per clod row: the frames at the CPU median and 99th percentile (nearest rank) and the slowest.
void printBreakdown(const std::vector<Row>& rows) {
  std::cout << "\nPer-frame breakdown (StepReport; times in ms, wall, summed over substeps):\n\n"
               "| model | budget | frame | rank | CPU ms | substeps | candidate pairs | tests | budget spent | pairs skipped | frontier pairs"
               " | raw contacts | solver contacts | solver iterations | broad ms | narrow ms | prepare ms | solver ms"
               " | integrate ms |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    if (r.frames.empty()) continue;
    std::vector<const Frame*> sorted;
    for (const Frame& f : r.frames) sorted.push_back(&f);
    std::stable_sort(sorted.begin(), sorted.end(), [](const Frame* x, const Frame* y) { return x->cpu < y->cpu; });
    auto at = [&](double p) {
      const std::size_t rank = std::size_t(std::ceil(p * double(sorted.size())));
      return sorted[std::min(sorted.size(), std::max<std::size_t>(rank, 1)) - 1];
    };
    const std::pair<const char*, const Frame*> picks[] = {{"median", at(0.5)}, {"p99", at(0.99)}, {"max", at(1.0)}};
    for (const auto& [name, f] : picks)
      std::cout << "| " << r.model << " | " << r.budget << " | " << f->step << " | " << name << " | " << fmt(1e3 * f->cpu, 2)
                << " | " << f->substeps << " | " << withCommas(f->candidatePairs) << " | " << withCommas(f->tests) << " | "
                << withCommas(f->spent) << " | " << withCommas(f->skipped) << " | " << withCommas(f->frontierPairs) << " | " << withCommas(f->rawContacts)
                << " | " << withCommas(f->solverContacts) << " | " << f->iterations << " | " << fmt(1e3 * f->broad, 2)
                << " | " << fmt(1e3 * f->narrow, 2) << " | " << fmt(1e3 * f->prepare, 2) << " | "
                << fmt(1e3 * f->solver, 2) << " | " << fmt(1e3 * f->integrate, 2) << " |\n";
  }
  std::cout << std::flush;
}

int run(const Options& o) {
  clod::SceneDescription scene = clod::loadScene(o.scene);
  const std::uint32_t steps = o.steps ? o.steps : scene.steps;
  const std::uint32_t bulletSteps = o.bulletSteps ? o.bulletSteps : steps;
  const Bin bin = binOf(scene);
  std::cerr << "scene " << o.scene << ": " << scene.bodies.size() << " bodies, dt " << scene.dt << " s, " << steps
            << " steps; bake cache " << o.cache << '\n';
  std::vector<Row> rows;
  std::optional<clod::World> any;  // a template for Bullet (the shapes and descs, model irrelevant)
  for (const std::string& name : o.models) {
    clod::SceneDescription s = scene;
    s.world.model = clod::parseContactModel(name);
    clod::SceneBuildReport rep;
    const auto t0 = std::chrono::steady_clock::now();
    clod::World tmpl = clod::buildWorld(s, o.cache, &rep);
    std::cerr << "model " << name << ": world built in "
              << fmt(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1) << " s ("
              << rep.shapesBaked << " shapes baked, " << rep.shapesFromCache << " from cache)\n";
    for (std::uint64_t budget : o.budgets) {
      rows.push_back(runClod(tmpl, s, s.world.model, budget, 0.0, steps, o.rowSeconds, bin, o));
      printTable({rows.back()});
      printNarrowPhaseTimes(rows.back());
    }
    for (double us : o.budgetsMicros) {
      rows.push_back(runClod(tmpl, s, s.world.model, 0, us, steps, o.rowSeconds, bin, o));
      printTable({rows.back()});
      printNarrowPhaseTimes(rows.back());
    }
    if (!any) any.emplace(std::move(tmpl));
  }
  if (!o.bullet.empty()) {
#ifdef CLOD_BENCH_HAVE_BULLET
    if (!any) {
      clod::SceneDescription s = scene;
      s.world.model = clod::ContactModel::kCfm;  // no contact trees needed for the shapes
      any.emplace(clod::buildWorld(s, o.cache));
    }
    std::vector<double> clodSubsteps;
    for (const Row& r : rows) clodSubsteps.insert(clodSubsteps.end(), r.substeps.begin(), r.substeps.end());
    const auto clodRate = std::uint32_t(std::max(1.0, std::ceil(percentile(clodSubsteps, 0.5))));
    for (const std::string& kind : o.bullet)
      for (std::uint32_t k : o.bulletSubsteps) {
        if (k == 0) k = clodRate;
        rows.push_back(runBullet(*any, scene, kind == "hull", k, bulletSteps, o.bulletIterations, o.rowSeconds, bin));
        rows.back().model += " (" + std::to_string(k) + " substep" + (k > 1 ? "s" : "") + ")";
        printTable({rows.back()});
      }
#else
    std::cerr << "world_compare: built without Bullet; Bullet rows skipped\n";
#endif
  }
  std::cout << "\nAll rows:\n\n";
  printTable(rows);
  if (o.breakdown) printBreakdown(rows);
  if (!o.framesCsv.empty()) {
    std::FILE* f = std::fopen(o.framesCsv.c_str(), "w");
    if (!f) throw clod::Error(clod::ErrorCode::kFileWriteFailed, "cannot write " + o.framesCsv);
    std::fprintf(f, "model,budget,frame,cpu_ms,substeps,candidate_pairs,tests,budget_spent,pairs_skipped,frontier_pairs,"
                    "raw_contacts,solver_contacts,solver_iterations,broad_ms,narrow_ms,prepare_ms,solver_ms,integrate_ms\n");
    for (const Row& r : rows)
      for (const Frame& x : r.frames)
        std::fprintf(f, "%s,%s,%u,%.4f,%u,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%u,%.4f,%.4f,%.4f,%.4f,%.4f\n", r.model.c_str(),
                     r.budget.c_str(), x.step, 1e3 * x.cpu, x.substeps, (unsigned long long)x.candidatePairs,
                     (unsigned long long)x.tests, (unsigned long long)x.spent, (unsigned long long)x.skipped,
                     (unsigned long long)x.frontierPairs, (unsigned long long)x.rawContacts,
                     (unsigned long long)x.solverContacts, x.iterations, 1e3 * x.broad, 1e3 * x.narrow, 1e3 * x.prepare,
                     1e3 * x.solver, 1e3 * x.integrate);
    std::fclose(f);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parseOptions(argc, argv));
  } catch (const UsageError& e) {
    if (!e.message.empty()) std::cerr << "world_compare: " << e.message << '\n';
    std::cerr << "usage: world_compare [--scene FILE] [--cache DIR] [--steps N] [--models dos,cfm,contact-tree,exact|none]\n"
                 "                     [--budgets 1024,4096,16384,unlimited] [--budgets-us 1000,3000] [--bullet gimpact,hull|none]\n"
                 "                     [--bullet-substeps 1,clod] [--bullet-steps N] [--bullet-iterations N]\n"
                 "                     [--row-seconds S] [--breakdown 1] [--frames-csv FILE] [--frontier-cost N]\n"
                 "                     [--min-substep-iterations N]\n";
    return e.message.empty() ? 0 : 2;
  } catch (const clod::Error& e) {
    std::cerr << "world_compare: " << e.what() << '\n';
    return e.code() == clod::ErrorCode::kInvalidArgument ? 2 : 1;
  }
}
