// bullet_compare: clod's world, Bullet 3.24 with GImpact, and Bullet with clod as its collider
// (clod_bullet), in one run, on
//   1. issue 17's box scenes (degradation.h: stack5, stack5-twisted, pyramid10, slide, slope-rest,
//      slope-slide): ms of wall time per simulated second at each budget (and, as a reference for the
//      Bullet setup, Bullet with its btBoxShape primitive), and whether the run meets
//      the scenario's plausibility criteria (clod::judgeScenario, the code clod's own runs are
//      judged by), plus the frame time (median, p99) of the Bullet runs;
//   2. the 200-body bin (scenes/bin_200.json): frame time (median, p99) and outcome (bodies that
//      left the bounds or the bin, mean height) of GImpact and of clod in Bullet (issue 19).
//
// Usage (all optional):
//   bullet_compare [--categories stack5,stack5-twisted,pyramid10,slide,slope-rest,slope-slide]
//                  [--models cfm,exact] [--budgets 16,64,256,1024,unlimited] [--rate HZ] [--seconds S]
//                  [--bin-steps N (0 = no bin)] [--bin-budgets 4096,unlimited] [--cache DIR]
//                  [--gimpact-margin M (metres, default 0.004)]
//
// Fairness (as bench/world_compare.cpp, docs/benchmarks/world.md):
//  - the same triangles everywhere: every body (static ground and slopes included) is the mesh clod
//    bakes, 12 triangles per box, as btGImpactMeshShape (margin 4 mm) or as clod_bullet's MeshShape;
//    both in the mesh's principal frame with clod's masses and inertia;
//  - friction by clod's mixing rule (geometric mean, Bullet's global combine callback), restitution
//    threshold as WorldSettings, 20 solver iterations, no sleeping, split impulses (Bullet default);
//  - substeps: clod's world picks its own, at least WorldSettings::minSubsteps (8 for the stacks and
//    the pyramid, 1 elsewhere); Bullet runs exactly minSubsteps per frame (stepSimulation(dt, k, dt/k)).
//  - budgets: clod's world spends its budget per frame; clod_bullet's budget is per Bullet substep,
//    so clod in Bullet at "budget N per frame" gets ceil(N / k) tests per substep.
// Times: steady_clock around World::step / stepSimulation only (bakes and world construction excluded);
// the Bullet rows also give the thread's CPU time per frame, whose 99th percentile is not inflated
// by the scheduler handing the core to another process for a time slice (a few ms) on a busy machine.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletDynamicsCommon.h>

#include "clod/bullet/collider.h"
#include "clod/degradation.h"
#include "bench_args.h"
#include "clod/error.h"
#include "clod/scene.h"
#include "clod/world.h"

namespace {

using clod::Vec3;

struct Options {
  std::vector<clod::ScenarioKind> categories = {clod::ScenarioKind::kStack5,    clod::ScenarioKind::kStack5Twisted,
                                                clod::ScenarioKind::kPyramid10, clod::ScenarioKind::kSlide,
                                                clod::ScenarioKind::kSlopeRest, clod::ScenarioKind::kSlopeSlide};
  std::vector<clod::ContactModel> models = {clod::ContactModel::kCfm, clod::ContactModel::kExact};
  std::vector<std::uint64_t> budgets = {16, 64, 256, 1024, 0};
  double rate = 60.0, seconds = 0.0;
  std::uint32_t binSteps = 240;
  std::vector<std::uint64_t> binBudgets = {4096, 0};
  std::string cache = CLOD_BINARY_DIR "/bullet-compare-cache";
  double gimpactMargin = 0.004;
};

using bench::parseCount;
using bench::splitList;
using bench::UsageError;
using bench::parsePositive;

Options parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") throw UsageError{""};
    if (i + 1 >= argc) throw UsageError{flag + ": missing value (or unknown flag)"};
    const std::string value = argv[++i];
    if (flag == "--categories") {
      o.categories.clear();
      for (const std::string& c : splitList(value)) {
        const clod::ScenarioKind k = clod::parseScenarioKind(c);
        if (clod::isDropScenario(k)) throw UsageError{"--categories: the mesh drops are not compared here (box scenes only)"};
        o.categories.push_back(k);
      }
    } else if (flag == "--models") {
      o.models.clear();
      for (const std::string& m : splitList(value)) o.models.push_back(clod::parseContactModel(m));
    } else if (flag == "--budgets") {
      o.budgets.clear();
      for (const std::string& b : splitList(value)) o.budgets.push_back(parseCount(flag, b));
    } else if (flag == "--bin-budgets") {
      o.binBudgets.clear();
      for (const std::string& b : splitList(value)) o.binBudgets.push_back(parseCount(flag, b));
    } else if (flag == "--rate") {
      o.rate = parsePositive(flag, value);
      if (o.rate <= 0.0) throw UsageError{"--rate: expected Hz > 0"};
    } else if (flag == "--seconds") {
      o.seconds = parsePositive(flag, value);
    } else if (flag == "--bin-steps") {
      o.binSteps = std::uint32_t(parseCount(flag, value));
    } else if (flag == "--gimpact-margin") {
      o.gimpactMargin = parsePositive(flag, value);
    } else if (flag == "--cache") {
      o.cache = value;
    } else {
      throw UsageError{"unknown flag '" + flag + "'"};
    }
  }
  return o;
}

double percentile(std::vector<double> v, double p) {  // nearest rank
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t rank = std::size_t(std::ceil(p * double(v.size())));
  return v[std::min(v.size(), std::max<std::size_t>(rank, 1)) - 1];
}

std::string fmt(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string budgetName(std::uint64_t b) { return b ? std::to_string(b) : "unlimited"; }

btVector3 toBt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Vec3 toClod(const btVector3& v) { return Vec3(double(v.x()), double(v.y()), double(v.z())); }

btScalar combineFrictionLikeClod(const btCollisionObject* a, const btCollisionObject* b) {
  return std::sqrt(a->getFriction() * b->getFriction());
}
btScalar combineRestitutionLikeClod(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getRestitution(), b->getRestitution());
}

// GImpact's collision margin (m): 4 mm as world_compare by default (Bullet's 0.04 default is 4 % of a
// 1 m box and 13 % of the bin's 0.3 m bodies); --gimpact-margin changes it.
btScalar gGImpactMargin = 0.004f;

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// How Bullet sees the bodies: the mesh as btGImpactMeshShape, the mesh as clod_bullet's MeshShape,
// or (reference only, not a mesh) boxes as Bullet's btBoxShape primitive.
enum class Shapes { kGImpact, kClod, kBox };

// A scene in Bullet, every body in its mesh's principal frame with clod's mass and inertia.
struct BulletScene {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  struct Shape {
    clod::Pose shapeFromMesh;
    std::vector<btScalar> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> array;
    std::unique_ptr<btCollisionShape> shape;
  };
  std::map<const clod::CollisionBody*, std::unique_ptr<Shape>> shapes;
  std::vector<const Shape*> bodyShape;  // scene order
  std::vector<std::unique_ptr<btDefaultMotionState>> motions;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<bool> removed;

  BulletScene(const clod::World& tmpl, const clod::SceneDescription& scene, Shapes kind) {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
    gCalculateCombinedFrictionCallback = combineFrictionLikeClod;
    gCalculateCombinedRestitutionCallback = combineRestitutionLikeClod;
    world.setGravity(toBt(scene.world.gravity));
    world.getSolverInfo().m_numIterations = 20;
    world.getSolverInfo().m_restitutionVelocityThreshold = btScalar(scene.world.restitutionThreshold);
    for (clod::BodyId i = 0; i < tmpl.bodyCount(); ++i) add(tmpl.desc(i), scene.bodies[i], kind);
    removed.assign(bodies.size(), false);
  }
  ~BulletScene() {
    for (auto& b : bodies)
      if (b->isInWorld()) world.removeRigidBody(b.get());
  }

  const Shape& shapeFor(const clod::RigidBodyDesc& d, const clod::SceneBody& sb, Shapes kind) {
    auto& slot = shapes[d.shape.get()];
    if (slot) return *slot;
    slot = std::make_unique<Shape>();
    Shape& s = *slot;
    const clod::TriangleMesh& mesh = d.shape->mesh();
    s.shapeFromMesh = clod::bullet::MeshShape::principalFrame(mesh);
    if (kind == Shapes::kBox && sb.shape == clod::SceneShapeKind::kBox) {
      s.shapeFromMesh = clod::Pose{};  // clod's box mesh is centred on its axes
      s.shape = std::make_unique<btBoxShape>(toBt(sb.halfExtents));
      return s;
    }
    if (kind == Shapes::kClod) {
      s.shape = std::make_unique<clod::bullet::MeshShape>(d.shape, s.shapeFromMesh);
      return s;
    }
    for (const Vec3& v : mesh.vertices) {
      const Vec3 p = s.shapeFromMesh.apply(v);
      for (int k = 0; k < 3; ++k) s.vertices.push_back(btScalar(p[k]));
    }
    for (const auto& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) s.indices.push_back(int(t[k]));
    s.array = std::make_unique<btTriangleIndexVertexArray>(int(mesh.triangleCount()), s.indices.data(), int(3 * sizeof(int)),
                                                           int(mesh.vertexCount()), s.vertices.data(), int(3 * sizeof(btScalar)));
    auto g = std::make_unique<btGImpactMeshShape>(s.array.get());
    g->setMargin(gGImpactMargin);
    g->updateBound();
    s.shape = std::move(g);
    return s;
  }

  void add(const clod::RigidBodyDesc& d, const clod::SceneBody& sb, Shapes kind) {
    const Shape& s = shapeFor(d, sb, kind);
    bodyShape.push_back(&s);
    const bool dynamic = d.type == clod::BodyType::kDynamic;
    const clod::Mat3 r = s.shapeFromMesh.rotation.toRotationMatrix();
    const Vec3 inertia = dynamic ? Vec3((r * d.inertia * r.transpose()).diagonal()) : Vec3::Zero();
    const clod::Pose worldFromShape = clod::Pose{d.orientation.normalized(), d.position} * s.shapeFromMesh.inverse();
    const clod::Quat& q = worldFromShape.rotation;
    btTransform t(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())), toBt(worldFromShape.translation));
    motions.push_back(std::make_unique<btDefaultMotionState>(t));
    btRigidBody::btRigidBodyConstructionInfo info(dynamic ? btScalar(d.mass) : btScalar(0), motions.back().get(),
                                                  s.shape.get(), toBt(inertia));
    info.m_friction = btScalar(d.friction);
    info.m_restitution = btScalar(d.restitution);
    bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody& body = *bodies.back();
    if (dynamic) {
      body.setLinearVelocity(toBt(d.velocity));
      body.setAngularVelocity(toBt(d.angularVelocity));
      body.setActivationState(DISABLE_DEACTIVATION);  // clod has no sleeping
    }
    world.addRigidBody(&body);
  }

  // The body's mesh frame in the world (for tilt) and its centre of mass.
  clod::Quat meshOrientation(std::size_t i) const {
    const btQuaternion q = bodies[i]->getWorldTransform().getRotation();
    return (clod::Quat(double(q.w()), double(q.x()), double(q.y()), double(q.z())) * bodyShape[i]->shapeFromMesh.rotation).normalized();
  }
  Vec3 centre(std::size_t i) const { return toClod(bodies[i]->getCenterOfMassPosition()); }
};

double tiltDeg(const clod::Quat& initial, const clod::Quat& current) {
  const double c = std::clamp((initial * Vec3::UnitZ()).dot(current * Vec3::UnitZ()), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

struct Row {
  std::string scenario, engine, model, budget;
  double msPerSimSecond = 0.0;
  std::vector<double> frameMs, frameCpuMs;  // Bullet rows
  clod::ScenarioOutcome outcome;
  std::uint64_t maxTestsPerFrame = 0;
};

// A scenario in Bullet (GImpact, or clod as the collider at `budget` tests per frame), judged
// by clod::judgeScenario.
Row runBulletScenario(clod::ScenarioKind kind, const clod::SceneDescription& scene, const clod::World& tmpl, Shapes shapes,
                      clod::ContactModel model, std::uint64_t budget) {
  const bool gimpact = shapes != Shapes::kClod;
  BulletScene b(tmpl, scene, shapes);
  const std::uint32_t k = std::max<std::uint32_t>(1, scene.world.minSubsteps);
  clod::bullet::Collider collider({.model = model, .budgetTests = budget ? (budget + k - 1) / k : 0});
  if (!gimpact) collider.install(b.world);
  Row row;
  row.scenario = std::string(clod::scenarioName(kind));
  row.engine = gimpact ? "Bullet 3.24" : "Bullet 3.24 + clod_bullet";
  row.model = shapes == Shapes::kGImpact ? "GImpact" : shapes == Shapes::kBox ? "btBoxShape (reference, not a mesh)"
                                                                            : std::string(clod::contactModelName(model));
  row.budget = gimpact ? "-" : budgetName(budget);
  const std::size_t tracked = b.bodies.size() - 1;
  const Vec3 c0 = b.centre(tracked);
  const clod::Quat q0 = b.meshOrientation(tracked);
  clod::ScenarioOutcome& out = row.outcome;
  out.kind = kind;
  std::string through;
  const btScalar dt = btScalar(scene.dt);
  double wall = 0.0;
  for (std::uint32_t s = 0; s < scene.steps; ++s) {
    const double cpu0 = threadCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    b.world.stepSimulation(dt, int(k), dt / btScalar(k));
    const double w = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row.frameCpuMs.push_back(1e3 * (threadCpuSeconds() - cpu0));
    wall += w;
    row.frameMs.push_back(1e3 * w);
    if (!gimpact) row.maxTestsPerFrame = std::max(row.maxTestsPerFrame, collider.lastDispatch().tests * k);
    ++out.steps;
    bool finite = true;
    for (std::size_t i = 0; i < b.bodies.size(); ++i) {
      if (b.bodies[i]->getInvMass() == 0) continue;
      const Vec3 c = b.centre(i);
      if (!c.allFinite()) finite = false;
      for (std::size_t j = 0; j < b.bodies.size() && through.empty(); ++j) {
        const clod::SceneBody& sb = scene.bodies[j];
        if (sb.type != clod::BodyType::kStatic) continue;
        const Vec3 local = sb.orientation.normalized().conjugate() * (c - sb.position);
        if ((local.cwiseAbs().array() < sb.halfExtents.array()).all())
          through = scene.bodies[i].name + " centre inside " + sb.name + " at t = " + fmt((s + 1) * scene.dt, 3) + " s";
      }
    }
    if (!finite) {
      out.diverged = true;
      out.failures.push_back("diverged: a centre of mass is not finite");
      break;
    }
    out.maxTiltDeg = std::max(out.maxTiltDeg, tiltDeg(q0, b.meshOrientation(tracked)));
  }
  out.simulatedSeconds = out.steps * scene.dt;
  row.msPerSimSecond = 1e3 * wall / std::max(out.simulatedSeconds, 1e-12);
  out.wallPerSimSecond = wall / std::max(out.simulatedSeconds, 1e-12);
  out.finalCenter = b.centre(tracked);
  out.speed = double(b.bodies[tracked]->getLinearVelocity().length());
  if (!through.empty()) {
    out.fellThrough = true;
    out.failures.push_back(through);
  }
  clod::judgeScenario(out, c0, tiltDeg(q0, b.meshOrientation(tracked)));
  collider.uninstall();
  return row;
}

void printScenarioHeader() {
  std::cout << "| scenario | engine | model | budget (tests/frame) | ms per simulated s | frame median ms | frame p99 ms"
               " | frame CPU p99 ms | plausible | tracked box moved m | tilt deg | first failure |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

void printScenarioRow(const Row& r) {
  const clod::ScenarioOutcome& o = r.outcome;
  std::cout << "| " << r.scenario << " | " << r.engine << " | " << r.model << " | " << r.budget << " | "
            << fmt(r.msPerSimSecond, 1) << " | " << (r.frameMs.empty() ? "-" : fmt(percentile(r.frameMs, 0.5), 3)) << " | "
            << (r.frameMs.empty() ? "-" : fmt(percentile(r.frameMs, 0.99), 3)) << " | "
            << (r.frameCpuMs.empty() ? "-" : fmt(percentile(r.frameCpuMs, 0.99), 3)) << " | " << (o.plausible ? "yes" : "**no**")
            << " | " << fmt(o.displacement, 4) << " | " << fmt(o.tiltDeg, 2) << " | "
            << (o.failures.empty() ? "" : o.failures.front()) << " |\n"
            << std::flush;
}

// ---- the bin ----

struct BinRow {
  std::string engine, model, budget;
  std::vector<double> frameMs, frameCpuMs;
  std::uint32_t leftBounds = 0, outsideBin = 0, dynamicBodies = 0;
  double meanZ = 0.0;
};

BinRow runBin(const clod::World& tmpl, const clod::SceneDescription& scene, std::uint32_t steps, bool gimpact,
              std::uint64_t budget) {
  BulletScene b(tmpl, scene, gimpact ? Shapes::kGImpact : Shapes::kClod);
  clod::bullet::Collider collider({.model = clod::ContactModel::kCfm, .budgetTests = budget, .maxContacts = scene.world.maxContacts});
  if (!gimpact) collider.install(b.world);
  BinRow row;
  row.engine = gimpact ? "Bullet 3.24" : "Bullet 3.24 + clod_bullet";
  row.model = gimpact ? "GImpact" : "cfm";
  row.budget = gimpact ? "-" : budgetName(budget);
  // The bin's inside: walls are the static boxes other than the floor (the largest footprint).
  double xMin = -1e300, xMax = 1e300, yMin = -1e300, yMax = 1e300, zMin = -1e300;
  const clod::SceneBody* floor = nullptr;
  for (const clod::SceneBody& sb : scene.bodies)
    if (sb.type == clod::BodyType::kStatic && (!floor || sb.halfExtents.x() * sb.halfExtents.y() > floor->halfExtents.x() * floor->halfExtents.y()))
      floor = &sb;
  if (floor) {
    zMin = floor->position.z() + floor->halfExtents.z();
    for (const clod::SceneBody& sb : scene.bodies) {
      if (&sb == floor || sb.type != clod::BodyType::kStatic) continue;
      const Vec3 d = sb.position - floor->position;
      if (std::abs(d.x()) > std::abs(d.y())) {
        if (d.x() < 0) xMin = std::max(xMin, sb.position.x() + sb.halfExtents.x());
        else xMax = std::min(xMax, sb.position.x() - sb.halfExtents.x());
      } else {
        if (d.y() < 0) yMin = std::max(yMin, sb.position.y() + sb.halfExtents.y());
        else yMax = std::min(yMax, sb.position.y() - sb.halfExtents.y());
      }
    }
  }
  const btScalar dt = btScalar(scene.dt);
  const clod::Aabb& bounds = scene.world.bounds;
  for (std::uint32_t s = 1; s <= steps; ++s) {
    const double c0 = threadCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    b.world.stepSimulation(dt, 1, dt);
    row.frameMs.push_back(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    row.frameCpuMs.push_back(1e3 * (threadCpuSeconds() - c0));
    for (std::size_t i = 0; i < b.bodies.size(); ++i) {  // as world_compare: out of bounds -> counted, removed
      if (b.removed[i] || b.bodies[i]->getInvMass() == 0) continue;
      const Vec3 c = b.centre(i);
      if ((c.array() < bounds.min.array()).any() || (c.array() > bounds.max.array()).any() || !c.allFinite()) {
        ++row.leftBounds;
        b.removed[i] = true;
        b.world.removeRigidBody(b.bodies[i].get());
      }
    }
    if (s % 20 == 0) std::cerr << "\r  bin " << row.model << " " << row.budget << ": " << s << '/' << steps << std::flush;
  }
  std::cerr << '\n';
  double z = 0.0;
  std::uint32_t in = 0;
  for (std::size_t i = 0; i < b.bodies.size(); ++i) {
    if (scene.bodies[i].type != clod::BodyType::kDynamic) continue;
    ++row.dynamicBodies;
    const Vec3 c = b.centre(i);
    if (!b.removed[i] && c.x() > xMin && c.x() < xMax && c.y() > yMin && c.y() < yMax && c.z() > zMin) {
      z += c.z();
      ++in;
    } else {
      ++row.outsideBin;
    }
  }
  row.meanZ = in ? z / in : 0.0;
  collider.uninstall();
  return row;
}

int run(const Options& o) {
  gGImpactMargin = btScalar(o.gimpactMargin);
  std::vector<Row> rows;
  printScenarioHeader();
  for (clod::ScenarioKind kind : o.categories) {
    std::cerr << "scenario " << clod::scenarioName(kind) << '\n';
    for (clod::ContactModel model : o.models)
      for (std::uint64_t budget : o.budgets) {
        clod::ScenarioSettings ss;
        ss.model = model;
        ss.budgetTests = budget;
        ss.rateHz = o.rate;
        ss.seconds = o.seconds;
        Row r;
        r.scenario = std::string(clod::scenarioName(kind));
        r.engine = "clod world";
        r.model = std::string(clod::contactModelName(model));
        r.budget = budgetName(budget);
        r.outcome = clod::runScenario(kind, ss, o.cache);
        r.msPerSimSecond = 1e3 * r.outcome.wallPerSimSecond;
        printScenarioRow(r);
        rows.push_back(std::move(r));
      }
    clod::ScenarioSettings ss;
    ss.model = clod::ContactModel::kCfm;
    ss.rateHz = o.rate;
    ss.seconds = o.seconds;
    const clod::SceneDescription scene = clod::makeScenario(kind, ss);
    const clod::World tmpl = clod::buildWorld(scene, o.cache);
    for (Shapes shapes : {Shapes::kGImpact, Shapes::kBox}) {
      rows.push_back(runBulletScenario(kind, scene, tmpl, shapes, clod::ContactModel::kCfm, 0));
      printScenarioRow(rows.back());
    }
    for (clod::ContactModel model : o.models)
      for (std::uint64_t budget : o.budgets) {
        rows.push_back(runBulletScenario(kind, scene, tmpl, Shapes::kClod, model, budget));
        printScenarioRow(rows.back());
      }
  }
  std::cout << "\nAll scenario rows:\n\n";
  printScenarioHeader();
  for (const Row& r : rows) printScenarioRow(r);

  if (o.binSteps > 0) {
    const clod::SceneDescription scene = clod::loadScene(CLOD_SOURCE_DIR "/scenes/bin_200.json");
    const clod::World tmpl = clod::buildWorld(scene, o.cache);
    std::vector<BinRow> bins;
    bins.push_back(runBin(tmpl, scene, o.binSteps, true, 0));
    for (std::uint64_t budget : o.binBudgets) bins.push_back(runBin(tmpl, scene, o.binSteps, false, budget));
    std::cout << "\n200-body bin (scenes/bin_200.json), " << o.binSteps << " frames at " << fmt(1.0 / scene.dt, 0)
              << " Hz, 1 Bullet substep per frame:\n\n"
                 "| engine | model | budget (tests/substep) | frame median ms | frame p99 ms | p99/median | CPU median ms"
                 " | CPU p99 ms | left bounds | outside bin at end | mean z at end m |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const BinRow& r : bins) {
      const double med = percentile(r.frameMs, 0.5), p99 = percentile(r.frameMs, 0.99);
      std::cout << "| " << r.engine << " | " << r.model << " | " << r.budget << " | " << fmt(med, 2) << " | " << fmt(p99, 2)
                << " | " << fmt(med > 0 ? p99 / med : 0.0, 2) << " | " << fmt(percentile(r.frameCpuMs, 0.5), 2) << " | "
                << fmt(percentile(r.frameCpuMs, 0.99), 2) << " | " << r.leftBounds << " | " << r.outsideBin << " of "
                << r.dynamicBodies << " | " << fmt(r.meanZ, 3) << " |\n";
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parseOptions(argc, argv));
  } catch (const UsageError& e) {
    if (!e.message.empty()) std::cerr << "bullet_compare: " << e.message << '\n';
    std::cerr << "usage: bullet_compare [--categories stack5,...] [--models cfm,exact] [--budgets 16,64,256,1024,unlimited]\n"
                 "                      [--rate HZ] [--seconds S] [--bin-steps N] [--bin-budgets 4096,unlimited] [--cache DIR]\n"
                 "                      [--gimpact-margin M]\n";
    return e.message.empty() ? 0 : 2;
  } catch (const clod::Error& e) {
    std::cerr << "bullet_compare: " << e.what() << '\n';
    return e.code() == clod::ErrorCode::kInvalidArgument ? 2 : 1;
  }
}
