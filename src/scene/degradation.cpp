// The graceful-degradation scenarios (degradation.h): scenes built in code, run and judged.
#include "clod/degradation.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "clod/error.h"
#include "clod/mesh_io.h"

namespace clod {
namespace {

constexpr double kGravity = 9.81;
constexpr double kPi = 3.14159265358979323846;
constexpr double kBoxHalf = 0.5;
constexpr double kGroundHalfThickness = 0.25;
constexpr double kStackFriction = 0.6;
constexpr double kSlideSpeed = 2.0, kSlideFriction = 0.3;
constexpr double kSlopeRestDeg = 20.0, kSlopeRestFriction = 0.6;
constexpr double kSlopeSlideDeg = 35.0, kSlopeSlideFriction = 0.3;
constexpr double kPyramidGap = 0.02;
constexpr double kTwistStepDeg = 10.0;
constexpr double kDropDiagonal = 0.75, kDropHeight = 0.25, kDropFriction = 0.6;
// Stacks: as scenes/stack_10.json (world.h, WorldSettings::minSubsteps, has the measurement).
constexpr std::uint32_t kStackMinSubsteps = 8;
// The thresholds.
constexpr double kStackMoveLimit = 0.02, kPyramidMoveLimit = 0.05;
constexpr double kStackTiltLimitDeg = 1.0, kPyramidTiltLimitDeg = 2.0;
constexpr double kRestSpeedLimit = 0.05;
constexpr double kSlideTiltLimitDeg = 2.0, kDistanceTolerance = 0.10;
constexpr double kSlopeRestMoveLimit = 0.02;
constexpr double kSinkLimitRel = 0.01;

struct Names {
  ScenarioKind kind;
  const char* name;
};
constexpr Names kNames[] = {{ScenarioKind::kStack5, "stack5"},         {ScenarioKind::kStack5Twisted, "stack5-twisted"},
                            {ScenarioKind::kPyramid10, "pyramid10"},   {ScenarioKind::kSlide, "slide"},
                            {ScenarioKind::kSlopeRest, "slope-rest"},  {ScenarioKind::kSlopeSlide, "slope-slide"},
                            {ScenarioKind::kDropBunny, "drop-bunny"},  {ScenarioKind::kDropSpot, "drop-spot"},
                            {ScenarioKind::kDropFandisk, "drop-fandisk"}};

bool isStack(ScenarioKind kind) {
  return kind == ScenarioKind::kStack5 || kind == ScenarioKind::kStack5Twisted || kind == ScenarioKind::kPyramid10;
}

double slopeDeg(ScenarioKind kind) { return kind == ScenarioKind::kSlopeRest ? kSlopeRestDeg : kSlopeSlideDeg; }

// Rotation of the slope: about +y by the slope angle, so +x runs downhill.
Quat slopeRotation(ScenarioKind kind) { return Quat(Eigen::AngleAxisd(slopeDeg(kind) * kPi / 180.0, Vec3::UnitY())); }

SceneBody groundBox(const Vec3& halfExtents, double friction) {
  SceneBody g;
  g.name = "ground";
  g.shape = SceneShapeKind::kBox;
  g.halfExtents = halfExtents;
  g.type = BodyType::kStatic;
  g.friction = friction;
  g.position = Vec3(0.0, 0.0, -halfExtents.z());
  return g;
}

SceneBody box(const std::string& name, const Vec3& position, const Quat& orientation, double friction) {
  SceneBody b;
  b.name = name;
  b.shape = SceneShapeKind::kBox;
  b.halfExtents = Vec3::Constant(kBoxHalf);
  b.friction = friction;
  b.position = position;
  b.orientation = orientation;
  return b;
}

const char* dropMeshFile(ScenarioKind kind) {
  switch (kind) {
    case ScenarioKind::kDropBunny: return "bunny-1500.obj";
    case ScenarioKind::kDropSpot: return "spot.obj";
    default: return "fandisk.obj";
  }
}

// Bunny and spot are modelled y-up; turn them z-up. Fandisk lies flat as it is.
Quat dropOrientation(ScenarioKind kind) {
  return kind == ScenarioKind::kDropFandisk ? Quat::Identity() : Quat(Eigen::AngleAxisd(kPi / 2.0, Vec3::UnitX()));
}

SceneBody dropBody(ScenarioKind kind, const std::filesystem::path& meshDir) {
  const std::filesystem::path path = meshDir / dropMeshFile(kind);
  const TriangleMesh mesh = loadMesh(path).mesh;
  Aabb local;
  for (const Vec3& v : mesh.vertices) local.extend(v);
  const double scale = kDropDiagonal / (local.max - local.min).norm();
  const Quat q = dropOrientation(kind);
  Aabb world;
  for (const Vec3& v : mesh.vertices) world.extend(q * (scale * v));
  SceneBody b;
  b.name = std::string(scenarioName(kind)).substr(5);  // "bunny", "spot", "fandisk"
  b.shape = SceneShapeKind::kMesh;
  b.meshPath = path;
  b.scale = scale;
  b.friction = kDropFriction;
  b.orientation = q;
  // Centre the box over the origin, its lowest point kDropHeight above the ground.
  const Vec3 centre = 0.5 * (world.min + world.max);
  b.position = Vec3(-centre.x(), -centre.y(), kDropHeight - world.min.z());
  return b;
}

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

double tiltDeg(const Quat& initial, const Quat& current) {
  const double c = std::clamp((initial * Vec3::UnitZ()).dot(current * Vec3::UnitZ()), -1.0, 1.0);
  return std::acos(c) * 180.0 / kPi;
}

struct StaticBox {
  std::string name;
  Vec3 position;
  Quat orientation;
  Vec3 halfExtents;
  bool contains(const Vec3& p) const {
    const Vec3 local = orientation.conjugate() * (p - position);
    return (local.cwiseAbs().array() < halfExtents.array()).all();
  }
};

}  // namespace

std::string_view scenarioName(ScenarioKind kind) noexcept {
  for (const Names& n : kNames)
    if (n.kind == kind) return n.name;
  return "unknown";
}

ScenarioKind parseScenarioKind(std::string_view name) {
  std::string valid;
  for (const Names& n : kNames) {
    if (name == n.name) return n.kind;
    valid += (valid.empty() ? "" : ", ") + std::string(n.name);
  }
  throw Error(ErrorCode::kInvalidArgument, "unknown scenario '" + std::string(name) + "' (valid: " + valid + ")");
}

bool isDropScenario(ScenarioKind kind) noexcept {
  return kind == ScenarioKind::kDropBunny || kind == ScenarioKind::kDropSpot || kind == ScenarioKind::kDropFandisk;
}

double defaultScenarioSeconds(ScenarioKind kind) noexcept {
  if (isStack(kind)) return 10.0;
  switch (kind) {
    case ScenarioKind::kSlopeRest: return 4.0;
    case ScenarioKind::kSlopeSlide: return 2.0;
    default: return 3.0;  // slide (stops after 0.68 s), drops
  }
}

bool degradesMonotonically(double errorAtN, double errorAt2N) noexcept {
  if (std::isnan(errorAtN) || std::isnan(errorAt2N)) return false;
  return errorAt2N <= errorAtN + std::max(0.1 * errorAtN, 0.002);
}

SceneDescription makeScenario(ScenarioKind kind, const ScenarioSettings& settings) {
  if (!(settings.rateHz > 0.0) || !std::isfinite(settings.rateHz))
    throw Error(ErrorCode::kInvalidArgument, "scenario rate must be a positive number of Hz");
  if (!(settings.seconds >= 0.0) || !std::isfinite(settings.seconds))
    throw Error(ErrorCode::kInvalidArgument, "scenario seconds must be finite and >= 0");
  if (!(settings.budgetMicros >= 0.0) || !std::isfinite(settings.budgetMicros))
    throw Error(ErrorCode::kInvalidArgument, "scenario budgetMicros must be finite and >= 0");
  if (!std::isfinite(settings.dropHeightOffset))
    throw Error(ErrorCode::kInvalidArgument, "scenario dropHeightOffset must be finite");
  SceneDescription scene;
  scene.world.model = settings.model;
  scene.world.budgetTests = settings.budgetTests;
  scene.world.budgetMicros = settings.budgetMicros;
  scene.dt = 1.0 / settings.rateHz;
  const double seconds = settings.seconds > 0.0 ? settings.seconds : defaultScenarioSeconds(kind);
  scene.steps = static_cast<std::uint32_t>(std::max(1.0, std::round(seconds * settings.rateHz)));
  const Quat identity = Quat::Identity();
  switch (kind) {
    case ScenarioKind::kStack5:
    case ScenarioKind::kStack5Twisted: {
      scene.world.minSubsteps = kStackMinSubsteps;
      scene.bodies.push_back(groundBox(Vec3(2.0, 2.0, kGroundHalfThickness), kStackFriction));
      for (int k = 0; k < 5; ++k) {
        const double twist = kind == ScenarioKind::kStack5Twisted ? kTwistStepDeg * k * kPi / 180.0 : 0.0;
        scene.bodies.push_back(box("box" + std::to_string(k), Vec3(0.0, 0.0, kBoxHalf * (2 * k + 1)),
                                   Quat(Eigen::AngleAxisd(twist, Vec3::UnitZ())), kStackFriction));
      }
      break;
    }
    case ScenarioKind::kPyramid10: {
      scene.world.minSubsteps = kStackMinSubsteps;
      scene.bodies.push_back(groundBox(Vec3(3.0, 2.0, kGroundHalfThickness), kStackFriction));
      const double pitch = 2.0 * kBoxHalf + kPyramidGap;
      for (int row = 0; row < 4; ++row) {
        const int count = 4 - row;
        for (int i = 0; i < count; ++i) {
          const double x = (i - 0.5 * (count - 1)) * pitch;
          scene.bodies.push_back(box("box" + std::to_string(row) + std::to_string(i),
                                     Vec3(x, 0.0, kBoxHalf * (2 * row + 1)), identity, kStackFriction));
        }
      }
      break;
    }
    case ScenarioKind::kSlide: {
      scene.bodies.push_back(groundBox(Vec3(3.0, 2.0, kGroundHalfThickness), kSlideFriction));
      SceneBody b = box("box", Vec3(-1.5, 0.0, kBoxHalf), identity, kSlideFriction);
      b.velocity = Vec3(kSlideSpeed, 0.0, 0.0);
      scene.bodies.push_back(b);
      break;
    }
    case ScenarioKind::kSlopeRest:
    case ScenarioKind::kSlopeSlide: {
      const bool rest = kind == ScenarioKind::kSlopeRest;
      const double friction = rest ? kSlopeRestFriction : kSlopeSlideFriction;
      const double halfLength = rest ? 2.0 : 5.0;
      const Quat q = slopeRotation(kind);
      SceneBody ground = groundBox(Vec3(halfLength, 1.5, kGroundHalfThickness), friction);
      ground.position = Vec3::Zero();
      ground.orientation = q;
      scene.bodies.push_back(ground);
      // Resting on the top face, face on face; slope-slide starts 1 m from the upper end.
      const Vec3 normal = q * Vec3::UnitZ(), downhill = q * Vec3::UnitX();
      const double along = rest ? 0.0 : -(halfLength - 1.0);
      scene.bodies.push_back(box("box", (kGroundHalfThickness + kBoxHalf) * normal + along * downhill, q, friction));
      break;
    }
    case ScenarioKind::kDropBunny:
    case ScenarioKind::kDropSpot:
    case ScenarioKind::kDropFandisk: {
      scene.bodies.push_back(groundBox(Vec3(2.0, 2.0, kGroundHalfThickness), kDropFriction));
      scene.bodies.push_back(dropBody(kind, settings.meshDir));
      scene.bodies.back().position.z() += settings.dropHeightOffset;
      break;
    }
  }
  return scene;
}

ScenarioOutcome runScenario(ScenarioKind kind, const ScenarioSettings& settings, const std::filesystem::path& cacheDir,
                            const ScenarioOutcome* reference) {
  const SceneDescription scene = makeScenario(kind, settings);
  World world = buildWorld(scene, cacheDir);
  const BodyId tracked = static_cast<BodyId>(world.bodyCount() - 1);
  std::vector<StaticBox> statics;
  std::vector<BodyId> dynamics;
  for (BodyId id = 0; id < world.bodyCount(); ++id) {
    const SceneBody& sb = scene.bodies[id];
    if (sb.type == BodyType::kStatic) {
      statics.push_back({sb.name, sb.position, sb.orientation.normalized(), sb.halfExtents});
    } else {
      dynamics.push_back(id);
    }
  }
  auto centreOfMass = [&](BodyId id) {
    const RigidBodyState s = world.state(id);
    return Vec3(s.position + s.orientation * world.desc(id).centerOfMass);
  };
  const Vec3 c0 = centreOfMass(tracked);
  const Quat q0 = world.state(tracked).orientation;
  const bool drop = isDropScenario(kind);
  const std::vector<Vec3>& vertices = world.desc(tracked).shape->mesh().vertices;
  const double diagonal = world.desc(tracked).shape->diagonal();
  const double groundTop = 0.0;

  ScenarioOutcome out;
  out.kind = kind;
  out.maxSinkRel = drop ? -std::numeric_limits<double>::infinity() : 0.0;
  std::string throughMessage;
  double budgetSpentSum = 0.0, narrowSeconds = 0.0;
  const double dt = scene.dt;
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = threadCpuSeconds();
  for (std::uint32_t step = 0; step < scene.steps; ++step) {
    try {
      const StepReport& report = world.step(dt);
      out.testsSpent += report.testsSpent;
      budgetSpentSum += static_cast<double>(report.budgetSpent);
      out.maxBudgetSpent = std::max(out.maxBudgetSpent, report.budgetSpent);
      out.pairsSkipped += report.pairsSkipped;
      out.pairsInterrupted += report.pairsInterrupted;
      narrowSeconds += report.narrowPhaseSeconds;
      if (!report.leftBounds.empty() && throughMessage.empty()) {
        out.fellThrough = true;
        throughMessage = world.desc(report.leftBounds.front()).name + " left the bounds" + format(" at t = %.3g s", (step + 1) * dt);
      }
    } catch (const Error& e) {
      if (e.code() != ErrorCode::kSimulationDiverged) throw;
      out.diverged = true;
      out.failures.push_back(std::string("diverged: ") + e.what());
      break;
    }
    ++out.steps;
    for (BodyId id : dynamics) {
      const Vec3 c = centreOfMass(id);
      for (const StaticBox& s : statics) {
        if (throughMessage.empty() && s.contains(c)) {
          out.fellThrough = true;
          throughMessage = world.desc(id).name + " centre inside " + s.name + format(" at t = %.3g s", (step + 1) * dt);
        }
      }
    }
    const RigidBodyState st = world.state(tracked);
    out.maxTiltDeg = std::max(out.maxTiltDeg, tiltDeg(q0, st.orientation));
    if (drop) {
      const Mat3 r = st.orientation.toRotationMatrix();
      double lowest = std::numeric_limits<double>::infinity();
      for (const Vec3& v : vertices) lowest = std::min(lowest, r.row(2).dot(v));
      out.maxSinkRel = std::max(out.maxSinkRel, (groundTop - (lowest + st.position.z())) / diagonal);
    }
  }
  const double simulated = out.steps * dt;
  out.simulatedSeconds = simulated;
  if (simulated > 0.0) {
    out.wallPerSimSecond = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count() / simulated;
    out.cpuPerSimSecond = (threadCpuSeconds() - cpu0) / simulated;
  }
  if (out.steps > 0) {
    out.meanBudgetSpent = budgetSpentSum / out.steps;
    out.meanNarrowMicros = narrowSeconds * 1e6 / out.steps;
  }
  const RigidBodyState final = world.state(tracked);
  out.finalCenter = centreOfMass(tracked);
  out.speed = final.velocity.norm();
  if (out.fellThrough) out.failures.push_back(throughMessage);
  judgeScenario(out, c0, tiltDeg(q0, final.orientation), reference);
  return out;
}

void judgeScenario(ScenarioOutcome& out, const Vec3& c0, double finalTiltDeg, const ScenarioOutcome* reference) {
  const ScenarioKind kind = out.kind;
  const bool drop = isDropScenario(kind);
  const double simulated = out.simulatedSeconds;
  out.displacement = (out.finalCenter - c0).norm();
  out.tiltDeg = finalTiltDeg;
  const std::string who = drop ? std::string(scenarioName(kind)).substr(5) : isStack(kind) ? "top box" : "box";  // as dropBody's name
  auto check = [&](bool ok, const std::string& message) {
    if (!ok) out.failures.push_back(message);
  };
  if (isStack(kind)) {
    const bool pyramid = kind == ScenarioKind::kPyramid10;
    const double moveLimit = pyramid ? kPyramidMoveLimit : kStackMoveLimit;
    const double tiltLimit = pyramid ? kPyramidTiltLimitDeg : kStackTiltLimitDeg;
    check(out.displacement < moveLimit, format("top box moved %.3g m (limit %g)", out.displacement, moveLimit));
    check(out.tiltDeg < tiltLimit, format("top box tilted %.3g deg (limit %g)", out.tiltDeg, tiltLimit));
    check(out.speed < kRestSpeedLimit, format("top box moving at %.3g m/s (limit %g)", out.speed, kRestSpeedLimit));
    out.error = out.displacement;
  } else if (kind == ScenarioKind::kSlide || kind == ScenarioKind::kSlopeSlide) {
    const bool slide = kind == ScenarioKind::kSlide;
    const Vec3 direction = slide ? Vec3::UnitX() : Vec3(slopeRotation(kind) * Vec3::UnitX());
    if (slide) {
      out.expectedDistance = kSlideSpeed * kSlideSpeed / (2.0 * kSlideFriction * kGravity);
    } else {
      const double theta = kSlopeSlideDeg * kPi / 180.0;
      const double a = kGravity * (std::sin(theta) - kSlopeSlideFriction * std::cos(theta));
      out.expectedDistance = 0.5 * a * simulated * simulated;
    }
    out.distance = (out.finalCenter - c0).dot(direction);
    const double off = std::abs(out.distance - out.expectedDistance);
    check(off <= kDistanceTolerance * out.expectedDistance,
          format("box travelled %.3g m, expected %.3g m (limit +-%g %%)", out.distance, out.expectedDistance, kDistanceTolerance * 100));
    if (slide) {
      check(out.speed < kRestSpeedLimit, format("box still moving at %.3g m/s (limit %g)", out.speed, kRestSpeedLimit));
      check(out.maxTiltDeg < kSlideTiltLimitDeg, format("box tilted %.3g deg while sliding (limit %g)", out.maxTiltDeg, kSlideTiltLimitDeg));
    }
    out.error = (out.finalCenter - (c0 + out.expectedDistance * direction)).norm();
  } else if (kind == ScenarioKind::kSlopeRest) {
    check(out.displacement < kSlopeRestMoveLimit, format("box moved %.3g m on the slope (limit %g)", out.displacement, kSlopeRestMoveLimit));
    out.error = out.displacement;
  } else {
    check(out.maxSinkRel <= kSinkLimitRel,
          who + format(" sank %.3g %% of its diagonal below the ground (limit %g %%)", out.maxSinkRel * 100, kSinkLimitRel * 100));
    out.error = reference ? (out.finalCenter - reference->finalCenter).norm() : std::numeric_limits<double>::quiet_NaN();
  }
  if (out.diverged) out.error = std::numeric_limits<double>::quiet_NaN();
  out.plausible = out.failures.empty();
}

}  // namespace clod
