// The Python module clod._clod, part two: the anytime narrow phase (query, query_batch), the
// rigid-body World (from a scene file or built in code) and the degradation experiment.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "bindings.h"
#include "clod/contact.h"
#include "clod/degradation.h"
#include "clod/mass_properties.h"
#include "clod/quaternion.h"
#include "clod/query.h"
#include "clod/scene.h"
#include "clod/world.h"

namespace clod::python {
namespace {

/// QuerySettings from the keyword arguments shared by query and query_batch.
QuerySettings querySettings(const std::string& model, std::optional<long long> budget, std::uint32_t maxContacts,
                            std::optional<long long> maxLevel, double margin) {
  QuerySettings settings;
  if (!(margin >= 0.0) || !std::isfinite(margin)) invalidArgument("margin: must be finite and >= 0, got " + std::to_string(margin));
  settings.marginAbs = margin;
  settings.model = parseContactModel(model);
  if (budget) {
    const long long tests = *budget;
    if (tests < 1) invalidArgument("budget: at least 1 test (None for unlimited), got " + std::to_string(tests));
    settings.budget.maxTests = static_cast<std::uint64_t>(tests);
  }
  if (maxContacts < 1 || maxContacts > 1024) invalidArgument("max_contacts: must be 1..1024, got " + std::to_string(maxContacts));
  settings.maxContacts = maxContacts;
  if (maxLevel) {
    const long long level = *maxLevel;
    if (level < 0) invalidArgument("max_level: must be >= 0 (None for no cap), got " + std::to_string(level));
    settings.maxLevel = static_cast<std::uint32_t>(std::min<long long>(level, UINT32_MAX));
  }
  return settings;
}

std::optional<double> deadlineMicros(std::optional<double> deadlineUs) {
  if (!deadlineUs) return std::nullopt;
  const double us = *deadlineUs;
  if (!std::isfinite(us) || us < 0.0) invalidArgument("deadline_us: must be finite and >= 0 (None for no deadline)");
  return us;
}

/// A query's answer as arrays (clod.QueryResult).
struct PyQueryResult {
  py::array pos, normal, penetrationDepth, level, errorBound;
  py::array featureKind, featureA, featureB, pointOnA, pointOnB;
  std::uint64_t budgetUsed = 0, sphereTests = 0, triangleTests = 0, rawContacts = 0, fallbackPairs = 0, frontierPairs = 0;
  bool finished = false, colliding = false;
  std::string stop, model;
  std::uint32_t minLevel = 0, maxLevel = 0;
  double seconds = 0.0;
};

/// Contact arrays of contacts[begin, end) of each result, concatenated: one array per field of
/// clod::Contact, plus contactPointOnA / contactPointOnB (contact.h).
struct ContactArrays {
  py::array_t<double> pos, normal, depth, errorBound, pointOnA, pointOnB;
  py::array_t<std::uint32_t> level, featureA, featureB;
  py::array_t<std::uint8_t> featureKind;
  explicit ContactArrays(std::size_t n)
      : pos({py::ssize_t(n), py::ssize_t(3)}), normal({py::ssize_t(n), py::ssize_t(3)}), depth(py::ssize_t(n)),
        errorBound(py::ssize_t(n)), pointOnA({py::ssize_t(n), py::ssize_t(3)}), pointOnB({py::ssize_t(n), py::ssize_t(3)}),
        level(py::ssize_t(n)), featureA(py::ssize_t(n)), featureB(py::ssize_t(n)), featureKind(py::ssize_t(n)) {}
  void set(std::size_t i, const Contact& c) {
    const Vec3 onA = contactPointOnA(c), onB = contactPointOnB(c);
    for (int k = 0; k < 3; ++k) {
      pos.mutable_data()[3 * i + k] = c.point[k];
      normal.mutable_data()[3 * i + k] = c.normal[k];
      pointOnA.mutable_data()[3 * i + k] = onA[k];
      pointOnB.mutable_data()[3 * i + k] = onB[k];
    }
    depth.mutable_data()[i] = c.depth;
    errorBound.mutable_data()[i] = c.errorBound;
    level.mutable_data()[i] = c.level;
    featureKind.mutable_data()[i] = static_cast<std::uint8_t>(c.featureKind);
    featureA.mutable_data()[i] = c.featureA;
    featureB.mutable_data()[i] = c.featureB;
  }
  /// The feature and two-point arrays as a dict (StepReport.contact_features, the callback's).
  py::dict features() const {
    py::dict out;
    out["feature_kind"] = featureKind;
    out["feature_a"] = featureA;
    out["feature_b"] = featureB;
    out["point_on_a"] = pointOnA;
    out["point_on_b"] = pointOnB;
    return out;
  }
};

/// Copies the feature and two-point arrays into a result struct with those five members.
template <typename Result>
void putContactFeatures(const ContactArrays& arrays, Result& out) {
  out.featureKind = arrays.featureKind;
  out.featureA = arrays.featureA;
  out.featureB = arrays.featureB;
  out.pointOnA = arrays.pointOnA;
  out.pointOnB = arrays.pointOnB;
}

PyQueryResult packQueryResult(const QueryResult& r, ContactModel model) {
  ContactArrays arrays(r.contacts.size());
  for (std::size_t i = 0; i < r.contacts.size(); ++i) arrays.set(i, r.contacts[i]);
  PyQueryResult out;
  out.pos = arrays.pos;
  out.normal = arrays.normal;
  out.penetrationDepth = arrays.depth;
  out.level = arrays.level;
  out.errorBound = arrays.errorBound;
  putContactFeatures(arrays, out);
  out.budgetUsed = r.tests;
  out.sphereTests = r.sphereTests;
  out.triangleTests = r.triangleTests;
  out.rawContacts = r.rawContacts;
  out.fallbackPairs = r.fallbackPairs;
  out.frontierPairs = r.frontier.size();
  out.finished = r.finished;
  out.colliding = r.colliding;
  out.stop = std::string(queryStopName(r.stop));
  out.model = std::string(contactModelName(model));
  out.minLevel = r.minLevel;
  out.maxLevel = r.maxLevel;
  out.seconds = r.seconds;
  return out;
}

PyQueryResult runQuery(const PyBake& a, const ArrayLike& poseA, const PyBake& b, const ArrayLike& poseB, const std::string& model,
                       std::optional<long long> budget, std::optional<double> deadlineUs, std::uint32_t maxContacts,
                       std::optional<long long> maxLevel, double margin) {
  QuerySettings settings = querySettings(model, budget, maxContacts, maxLevel, margin);
  const Pose xfA = parsePose(poseA, "pose_a");
  const Pose xfB = parsePose(poseB, "pose_b");
  const std::optional<double> deadline = deadlineMicros(deadlineUs);
  QueryResult result;
  {
    py::gil_scoped_release release;
    // One scratch per thread: no allocation in steady state, and the deadline's learned
    // per-pair answer cost (QueryScratch::answerSecondsPerPair) carries over between calls.
    thread_local QueryScratch scratch;
    if (deadline) settings.budget.deadline = QueryBudget::microsecondsFromNow(*deadline).deadline;
    queryContacts(*a.body, xfA, *b.body, xfB, settings, scratch, result);
  }
  return packQueryResult(result, settings.model);
}

/// The answers of P queries (clod.BatchQueryResult): contacts of query i are rows
/// offsets[i]..offsets[i+1] of the contact arrays.
struct PyBatchResult {
  py::array offsets, pos, normal, penetrationDepth, level, errorBound;
  py::array featureKind, featureA, featureB, pointOnA, pointOnB;
  py::array budgetUsed, finished, colliding, stop, seconds, minLevel, maxLevel;
  std::string model;
  double wallSeconds = 0.0;
};

PyBatchResult runQueryBatch(const PyBake& a, const ArrayLike& posesAObj, const PyBake& b, const ArrayLike& posesBObj,
                            const std::string& model, std::optional<long long> budget, std::optional<double> deadlineUs,
                            std::uint32_t maxContacts, std::optional<long long> maxLevel, double margin) {
  const QuerySettings settings = querySettings(model, budget, maxContacts, maxLevel, margin);
  const std::vector<Pose> posesA = parsePoses(posesAObj, "poses_a");
  const std::vector<Pose> posesB = parsePoses(posesBObj, "poses_b");
  const std::size_t count = std::max(posesA.size(), posesB.size());
  if ((posesA.size() != 1 && posesA.size() != count) || (posesB.size() != 1 && posesB.size() != count)) {
    invalidArgument("poses_a has " + std::to_string(posesA.size()) + " poses and poses_b " + std::to_string(posesB.size()) +
                    ": expected the same count, or one pose for all");
  }
  const std::optional<double> deadline = deadlineMicros(deadlineUs);
  std::vector<QueryResult> results(count);
  double wall = 0.0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    tbb::enumerable_thread_specific<QueryScratch> scratch;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 16), [&](const tbb::blocked_range<std::size_t>& range) {
      QueryScratch& local = scratch.local();
      QuerySettings s = settings;
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        if (deadline) s.budget.deadline = QueryBudget::microsecondsFromNow(*deadline).deadline;
        queryContacts(*a.body, posesA[posesA.size() == 1 ? 0 : i], *b.body, posesB[posesB.size() == 1 ? 0 : i], s, local, results[i]);
      }
    });
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  const py::ssize_t p = static_cast<py::ssize_t>(count);
  py::array_t<std::int64_t> offsets(p + 1);
  std::int64_t total = 0;
  for (std::size_t i = 0; i < count; ++i) {
    offsets.mutable_data()[i] = total;
    total += static_cast<std::int64_t>(results[i].contacts.size());
  }
  offsets.mutable_data()[count] = total;
  ContactArrays arrays(static_cast<std::size_t>(total));
  py::array_t<std::uint64_t> budgetUsed(p);
  py::array_t<bool> finished(p), colliding(p);
  py::array_t<std::uint8_t> stop(p);
  py::array_t<double> seconds(p);
  py::array_t<std::uint32_t> minLevels(p), maxLevels(p);
  std::size_t row = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const QueryResult& r = results[i];
    for (const Contact& c : r.contacts) arrays.set(row++, c);
    budgetUsed.mutable_data()[i] = r.tests;
    finished.mutable_data()[i] = r.finished;
    colliding.mutable_data()[i] = r.colliding;
    stop.mutable_data()[i] = static_cast<std::uint8_t>(r.stop);
    seconds.mutable_data()[i] = r.seconds;
    minLevels.mutable_data()[i] = r.minLevel;
    maxLevels.mutable_data()[i] = r.maxLevel;
  }
  PyBatchResult out;
  out.offsets = offsets;
  out.pos = arrays.pos;
  out.normal = arrays.normal;
  out.penetrationDepth = arrays.depth;
  out.level = arrays.level;
  out.errorBound = arrays.errorBound;
  putContactFeatures(arrays, out);
  out.budgetUsed = budgetUsed;
  out.finished = finished;
  out.colliding = colliding;
  out.stop = stop;
  out.seconds = seconds;
  out.minLevel = minLevels;
  out.maxLevel = maxLevels;
  out.model = std::string(contactModelName(settings.model));
  out.wallSeconds = wall;
  return out;
}

// ---------------------------------------------------------------------------------------------
// World.

/// clod.World: a World plus the frame time and step count its scene asked for.
struct PyWorld {
  World world;
  double dt = 1.0 / 60.0;
  std::uint32_t steps = 120;
  explicit PyWorld(World w) : world(std::move(w)) {}
};

Vec3 vec3Arg(py::handle obj, const char* name) {
  DoubleArray a = toDoubleArray(obj, name);
  if (a.size() != 3 || a.ndim() != 1) invalidArgument(std::string(name) + ": expected 3 numbers, got shape " + shapeText(a));
  requireFinite(a, name, 3);
  return Vec3(a.data()[0], a.data()[1], a.data()[2]);
}

BodyType parseBodyType(const std::string& type) {
  if (type == "dynamic") return BodyType::kDynamic;
  if (type == "static") return BodyType::kStatic;
  if (type == "kinematic") return BodyType::kKinematic;
  invalidArgument("type \"" + type + "\": expected \"dynamic\", \"static\" or \"kinematic\"");
}

const char* bodyTypeName(BodyType type) {
  switch (type) {
    case BodyType::kDynamic: return "dynamic";
    case BodyType::kStatic: return "static";
    case BodyType::kKinematic: return "kinematic";
  }
  return "unknown";
}

std::unique_ptr<PyWorld> makeWorld(const ArrayLike& gravity, const std::string& model, std::uint64_t budget, double budgetUs, double dt,
                                   std::uint32_t maxContacts, std::uint32_t minSubsteps, std::uint32_t maxSubsteps,
                                   std::uint32_t velocityIterations, std::uint32_t positionIterations, std::uint32_t frontierPairCost,
                                   double restitutionThreshold, double rollingResistance) {
  WorldSettings s;
  s.gravity = vec3Arg(gravity, "gravity");
  s.model = parseContactModel(model);
  s.budgetTests = budget;
  s.budgetMicros = budgetUs;
  s.maxContacts = maxContacts;
  s.minSubsteps = minSubsteps;
  s.maxSubsteps = maxSubsteps;
  s.velocityIterations = velocityIterations;
  s.positionIterations = positionIterations;
  s.frontierPairCost = frontierPairCost;
  s.restitutionThreshold = restitutionThreshold;
  s.rollingResistanceRel = rollingResistance;
  if (!std::isfinite(dt) || !(dt > 0.0)) invalidArgument("dt: must be finite and > 0");
  auto w = std::make_unique<PyWorld>(World(s));
  w->dt = dt;
  w->steps = 0;
  return w;
}

std::unique_ptr<PyWorld> worldFromScene(SceneDescription scene, const std::optional<std::string>& model,
                                        std::optional<long long> budget, std::optional<double> budgetUs,
                                        const std::string& cacheDir) {
  if (model) scene.world.model = parseContactModel(*model);
  if (budget) {
    const long long tests = *budget;
    if (tests < 0) invalidArgument("budget: tests per step, >= 0 (0 = unlimited)");
    scene.world.budgetTests = static_cast<std::uint64_t>(tests);
  }
  if (budgetUs) scene.world.budgetMicros = *budgetUs;
  std::unique_ptr<PyWorld> result;
  {
    py::gil_scoped_release release;
    result = std::make_unique<PyWorld>(buildWorld(scene, cacheDir));
  }
  result->dt = scene.dt;
  result->steps = scene.steps;
  return result;
}

BodyId addBody(PyWorld& w, const PyBake& shape, std::optional<double> mass, double density, const std::string& type,
               const ArrayLike& position, const ArrayLike& orientation, const ArrayLike& velocity,
               const ArrayLike& angularVelocity, double restitution, double friction,
               const std::string& name, double scale) {
  RigidBodyDesc desc;
  desc.name = name.empty() ? "body " + std::to_string(w.world.bodyCount()) : name;
  desc.shape = shape.body;
  desc.type = parseBodyType(type);
  desc.position = vec3Arg(position, "position");
  DoubleArray q = toDoubleArray(orientation, "orientation");
  if (q.size() != 4 || q.ndim() != 1) invalidArgument("orientation: expected a quaternion (w, x, y, z), got shape " + shapeText(q));
  requireFinite(q, "orientation", 4);
  const std::optional<Quat> unit = unitQuaternion(q.data()[0], q.data()[1], q.data()[2], q.data()[3]);
  if (!unit) invalidArgument("orientation: the quaternion is zero");
  desc.orientation = *unit;
  desc.velocity = vec3Arg(velocity, "velocity");
  desc.angularVelocity = vec3Arg(angularVelocity, "angular_velocity");
  desc.restitution = restitution;
  desc.friction = friction;
  if (desc.type == BodyType::kDynamic) {
    if (!std::isfinite(density) || !(density > 0.0)) invalidArgument("density: must be finite and > 0");
    MassProperties p = computeMassPropertiesOrBoundingBox(shape.contents->mesh, density);
    // The scaled body at the same density (World::addBody with a scale takes the scaled body's).
    if (std::isfinite(scale) && scale > 0.0) {
      p.mass *= scale * scale * scale;
      p.inertia *= std::pow(scale, 5);
      p.centerOfMass *= scale;
    }
    if (mass) {
      const double m = *mass;
      if (!std::isfinite(m) || !(m > 0.0)) invalidArgument("mass: must be finite and > 0");
      p.inertia *= m / p.mass;
      p.mass = m;
    }
    desc.mass = p.mass;
    desc.inertia = p.inertia;
    desc.centerOfMass = p.centerOfMass;
  }
  return w.world.addBody(desc, scale);
}

/// A body's state, or NaN everywhere for a removed id (the arrays keep one row per id).
RigidBodyState stateOrNan(const World& world, BodyId id) {
  if (world.contains(id)) return world.state(id);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return RigidBodyState{Vec3::Constant(nan), Quat(nan, nan, nan, nan), Vec3::Constant(nan), Vec3::Constant(nan)};
}

Quat quatArg(py::handle obj, const char* name) {
  DoubleArray q = toDoubleArray(obj, name);
  if (q.size() != 4 || q.ndim() != 1) invalidArgument(std::string(name) + ": expected a quaternion (w, x, y, z), got shape " + shapeText(q));
  requireFinite(q, name, 4);
  return Quat(q.data()[0], q.data()[1], q.data()[2], q.data()[3]);
}

void setBodyState(PyWorld& w, BodyId id, const std::optional<ArrayLike>& position, const std::optional<ArrayLike>& orientation,
                  const std::optional<ArrayLike>& velocity, const std::optional<ArrayLike>& angularVelocity) {
  RigidBodyState s = w.world.state(id);
  if (position) s.position = vec3Arg(*position, "position");
  if (orientation) s.orientation = quatArg(*orientation, "orientation");
  if (velocity) s.velocity = vec3Arg(*velocity, "velocity");
  if (angularVelocity) s.angularVelocity = vec3Arg(*angularVelocity, "angular_velocity");
  w.world.setState(id, s);
}

/// World position of a body's centre of mass (where a force without a point acts).
Vec3 centreOfMass(const World& world, BodyId id) {
  const RigidBodyState s = world.state(id);
  return s.position + s.orientation * world.desc(id).centerOfMass;
}

py::dict separationDict(const Separation& r) {
  py::dict out;
  out["distance"] = r.distance;
  out["within_max"] = r.withinMax;
  out["overlapping"] = r.overlapping;
  out["point_a"] = py::make_tuple(r.pointA.x(), r.pointA.y(), r.pointA.z());
  out["point_b"] = py::make_tuple(r.pointB.x(), r.pointB.y(), r.pointB.z());
  out["triangle_a"] = r.triangleA;
  out["triangle_b"] = r.triangleB;
  return out;
}

/// World.set_contact_callback: the Python callable gets (a, b, pos (C, 3), normal (C, 3), depth
/// (C,), substep), and with features=True a seventh argument, the dict of ContactArrays::features,
/// and returns a truth value (False disables the pair for the step). It runs inside step(),
/// which released the GIL: the wrapper takes it back for the call.
void setContactCallback(PyWorld& w, const py::object& callback, bool features) {
  if (callback.is_none()) {
    w.world.setContactCallback({});
    return;
  }
  if (!PyCallable_Check(callback.ptr())) invalidArgument("callback: expected a callable or None");
  auto held = std::make_shared<py::object>(callback);
  w.world.setContactCallback([held, features](const ContactPairEvent& e) {
    py::gil_scoped_acquire acquire;
    ContactArrays arrays(e.contacts.size());
    for (std::size_t i = 0; i < e.contacts.size(); ++i) arrays.set(i, e.contacts[i]);
    // A Python exception becomes py::error_already_set and leaves step() with it.
    const py::object answer = features ? (*held)(e.a, e.b, arrays.pos, arrays.normal, arrays.depth, e.substep, arrays.features())
                                       : (*held)(e.a, e.b, arrays.pos, arrays.normal, arrays.depth, e.substep);
    return py::bool_(answer).cast<bool>();
  });
}

template <typename Get>
py::array_t<double> stateArray(const World& world, int width, Get get) {
  const std::size_t n = world.bodyCount();
  py::array_t<double> out({py::ssize_t(n), py::ssize_t(width)});
  for (std::size_t i = 0; i < n; ++i) get(stateOrNan(world, static_cast<BodyId>(i)), out.mutable_data() + width * i);
  return out;
}

void putPosition(const RigidBodyState& s, double* out) {
  for (int k = 0; k < 3; ++k) out[k] = s.position[k];
}
void putOrientation(const RigidBodyState& s, double* out) {
  out[0] = s.orientation.w();
  out[1] = s.orientation.x();
  out[2] = s.orientation.y();
  out[3] = s.orientation.z();
}

/// World.run: `steps` steps with the GIL released, recording states and per-step counters.
py::dict runWorld(PyWorld& w, std::optional<long long> stepsArg, std::optional<double> dtArg) {
  const long long steps = stepsArg ? *stepsArg : static_cast<long long>(w.steps);
  if (steps < 0) invalidArgument("steps: must be >= 0");
  const double dt = dtArg ? *dtArg : w.dt;
  if (!std::isfinite(dt) || !(dt > 0.0)) invalidArgument("dt: must be finite and > 0");
  const std::size_t n = w.world.bodyCount();
  const std::size_t s = static_cast<std::size_t>(steps);
  py::array_t<double> positions({py::ssize_t(s), py::ssize_t(n), py::ssize_t(3)});
  py::array_t<double> orientations({py::ssize_t(s), py::ssize_t(n), py::ssize_t(4)});
  const py::ssize_t rows = static_cast<py::ssize_t>(s);
  py::array_t<std::uint64_t> tests{rows}, budgetSpent{rows};
  py::array_t<std::uint32_t> substeps{rows}, contacts{rows};
  py::array_t<double> narrowSeconds{rows};
  double* pos = positions.mutable_data();
  double* ori = orientations.mutable_data();
  std::uint64_t* testsOut = tests.mutable_data();
  std::uint64_t* budgetOut = budgetSpent.mutable_data();
  std::uint32_t* substepsOut = substeps.mutable_data();
  std::uint32_t* contactsOut = contacts.mutable_data();
  double* narrowOut = narrowSeconds.mutable_data();
  {
    py::gil_scoped_release release;
    for (std::size_t k = 0; k < s; ++k) {
      const StepReport& report = w.world.step(dt);
      testsOut[k] = report.testsSpent;
      budgetOut[k] = report.budgetSpent;
      substepsOut[k] = report.substeps;
      contactsOut[k] = static_cast<std::uint32_t>(report.contacts.size());
      narrowOut[k] = report.narrowPhaseSeconds;
      for (std::size_t i = 0; i < n; ++i) {
        const RigidBodyState state = stateOrNan(w.world, static_cast<BodyId>(i));
        putPosition(state, pos + (k * n + i) * 3);
        putOrientation(state, ori + (k * n + i) * 4);
      }
    }
  }
  py::dict out;
  out["positions"] = positions;
  out["orientations"] = orientations;
  out["tests_spent"] = tests;
  out["budget_spent"] = budgetSpent;
  out["substeps"] = substeps;
  out["contacts"] = contacts;
  out["narrow_phase_seconds"] = narrowSeconds;
  return out;
}

// ---------------------------------------------------------------------------------------------
// The degradation experiment (degradation.h): rows of (scenario, model, budget, rate) runs.

py::dict degradationTable(const std::vector<std::string>& scenarioNames, const std::vector<std::string>& modelNames,
                          std::vector<std::uint64_t> budgets, std::vector<double> budgetsUs, const std::vector<double>& rates,
                          double seconds, const std::string& meshDir, const std::string& cacheDir) {
  std::vector<ScenarioKind> kinds;
  for (const std::string& name : scenarioNames) kinds.push_back(parseScenarioKind(name));
  std::vector<ContactModel> models;
  for (const std::string& name : modelNames) models.push_back(parseContactModel(name));
  if (rates.empty()) invalidArgument("rates: no rate given");
  for (double r : rates)
    if (!std::isfinite(r) || !(r > 0.0)) invalidArgument("rates: every rate must be finite and > 0");
  for (double b : budgetsUs)
    if (!std::isfinite(b) || b < 0.0) invalidArgument("budgets_us: every budget must be finite and >= 0");
  if (!std::isfinite(seconds) || seconds < 0.0) invalidArgument("seconds: must be finite and >= 0 (0 = the scenario's)");
  // Ascending, unlimited (0) last: each row is judged against the next smaller budget.
  auto order = [](auto& values) {
    std::sort(values.begin(), values.end(), [](auto x, auto y) { return x != 0 && (y == 0 || x < y); });
  };
  order(budgets);
  order(budgetsUs);
  struct Row {
    ScenarioKind kind;
    ContactModel model;
    bool timeBudget;
    double budget;
    double rate;
    int previous;
    int reference;
    ScenarioOutcome outcome;
  };
  std::vector<Row> rows;
  struct Reference {
    ScenarioKind kind;
    double rate;
    ScenarioOutcome outcome;
  };
  std::vector<Reference> references;
  for (ScenarioKind kind : kinds)
    for (ContactModel model : models)
      for (double rate : rates) {
        int reference = -1;
        if (isDropScenario(kind)) {
          for (std::size_t i = 0; i < references.size(); ++i)
            if (references[i].kind == kind && references[i].rate == rate) reference = static_cast<int>(i);
          if (reference < 0) {
            references.push_back({kind, rate, {}});
            reference = static_cast<int>(references.size()) - 1;
          }
        }
        int previous = -1;
        for (std::uint64_t b : budgets) {
          rows.push_back({kind, model, false, double(b), rate, previous, reference, {}});
          previous = static_cast<int>(rows.size()) - 1;
        }
        previous = -1;
        for (double b : budgetsUs) {
          rows.push_back({kind, model, true, b, rate, previous, reference, {}});
          previous = static_cast<int>(rows.size()) - 1;
        }
      }
  auto settingsOf = [&](ScenarioKind kind, ContactModel model, bool timeBudget, double budget, double rate) {
    ScenarioSettings s;
    s.model = model;
    if (timeBudget) s.budgetMicros = budget;
    else s.budgetTests = static_cast<std::uint64_t>(budget);
    s.rateHz = rate;
    s.seconds = seconds;
    s.meshDir = meshDir;
    return s;
  };
  {
    py::gil_scoped_release release;
    // Bake every shape once before the parallel runs (as `clod experiment degradation` does), so
    // they only read the cache instead of all baking the same shapes at once.
    for (ScenarioKind kind : kinds)
      for (ContactModel model : models) buildWorld(makeScenario(kind, settingsOf(kind, model, false, 0, rates[0])), cacheDir);
    tbb::parallel_for(std::size_t(0), references.size(), [&](std::size_t i) {
      references[i].outcome = runScenario(references[i].kind, settingsOf(references[i].kind, ContactModel::kExact, false, 0, references[i].rate), cacheDir);
    });
    tbb::parallel_for(std::size_t(0), rows.size(), [&](std::size_t i) {
      Row& r = rows[i];
      const ScenarioOutcome* reference = r.reference >= 0 ? &references[static_cast<std::size_t>(r.reference)].outcome : nullptr;
      r.outcome = runScenario(r.kind, settingsOf(r.kind, r.model, r.timeBudget, r.budget, r.rate), cacheDir, reference);
    });
  }
  const py::ssize_t n = static_cast<py::ssize_t>(rows.size());
  py::list scenario, model, budgetKind, failures;
  py::array_t<double> budget(n), rate(n), error(n), displacement(n), tilt(n), maxTilt(n), speed(n), distance(n), expected(n), sink(n),
      wallPerSim(n), cpuPerSim(n), meanBudget(n), meanNarrow(n);
  py::array_t<bool> plausible(n), monotone(n), diverged(n), fellThrough(n);
  py::array_t<std::uint64_t> testsSpent(n), maxBudget(n), skipped(n), interrupted(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const Row& r = rows[static_cast<std::size_t>(i)];
    const ScenarioOutcome& o = r.outcome;
    scenario.append(std::string(scenarioName(r.kind)));
    model.append(std::string(contactModelName(r.model)));
    budgetKind.append(r.timeBudget ? "us" : "tests");
    std::string failed;
    for (const std::string& f : o.failures) failed += (failed.empty() ? "" : "; ") + f;
    failures.append(failed);
    budget.mutable_data()[i] = r.budget;
    rate.mutable_data()[i] = r.rate;
    error.mutable_data()[i] = o.error;
    displacement.mutable_data()[i] = o.displacement;
    tilt.mutable_data()[i] = o.tiltDeg;
    maxTilt.mutable_data()[i] = o.maxTiltDeg;
    speed.mutable_data()[i] = o.speed;
    distance.mutable_data()[i] = o.distance;
    expected.mutable_data()[i] = o.expectedDistance;
    sink.mutable_data()[i] = o.maxSinkRel;
    wallPerSim.mutable_data()[i] = o.wallPerSimSecond;
    cpuPerSim.mutable_data()[i] = o.cpuPerSimSecond;
    meanBudget.mutable_data()[i] = o.meanBudgetSpent;
    meanNarrow.mutable_data()[i] = o.meanNarrowMicros;
    plausible.mutable_data()[i] = o.plausible;
    monotone.mutable_data()[i] =
        r.previous < 0 || degradesMonotonically(rows[static_cast<std::size_t>(r.previous)].outcome.error, o.error);
    diverged.mutable_data()[i] = o.diverged;
    fellThrough.mutable_data()[i] = o.fellThrough;
    testsSpent.mutable_data()[i] = o.testsSpent;
    maxBudget.mutable_data()[i] = o.maxBudgetSpent;
    skipped.mutable_data()[i] = o.pairsSkipped;
    interrupted.mutable_data()[i] = o.pairsInterrupted;
  }
  py::dict out;
  out["scenario"] = scenario;
  out["model"] = model;
  out["budget_kind"] = budgetKind;
  out["budget"] = budget;
  out["rate_hz"] = rate;
  out["plausible"] = plausible;
  out["monotone_ok"] = monotone;
  out["error"] = error;
  out["displacement"] = displacement;
  out["tilt_deg"] = tilt;
  out["max_tilt_deg"] = maxTilt;
  out["speed"] = speed;
  out["distance"] = distance;
  out["expected_distance"] = expected;
  out["max_sink_rel"] = sink;
  out["diverged"] = diverged;
  out["fell_through"] = fellThrough;
  out["wall_per_sim_second"] = wallPerSim;
  out["cpu_per_sim_second"] = cpuPerSim;
  out["tests_spent"] = testsSpent;
  out["mean_budget_spent"] = meanBudget;
  out["max_budget_spent"] = maxBudget;
  out["pairs_skipped"] = skipped;
  out["pairs_interrupted"] = interrupted;
  out["mean_narrow_micros"] = meanNarrow;
  out["failures"] = failures;
  return out;
}

}  // namespace

void bindDynamics(py::module_& mod) {
  py::list modelNames;
  for (ContactModel model : allContactModels()) modelNames.append(std::string(contactModelName(model)));
  mod.attr("contact_models") = modelNames;
  // What QueryResult.feature_a / feature_b index (contact.h ContactFeature).
  mod.attr("CONTACT_FEATURE_NONE") = static_cast<int>(ContactFeature::kNone);
  mod.attr("CONTACT_FEATURE_TRIANGLE") = static_cast<int>(ContactFeature::kTriangle);
  mod.attr("CONTACT_FEATURE_SPHERE") = static_cast<int>(ContactFeature::kSphere);
  mod.attr("CONTACT_FEATURE_CELL") = static_cast<int>(ContactFeature::kCell);
  mod.attr("NO_CONTACT_FEATURE") = kNoContactFeature;

  py::class_<PyQueryResult>(mod, "QueryResult",
                            "Contacts between two bodies (clod.query), world frame, as arrays with one row per contact,\n"
                            "deepest first. Normals point from body B toward body A; depth > 0 means penetration.")
      .def_readonly("pos", &PyQueryResult::pos, "(C, 3) float64: contact points")
      .def_readonly("normal", &PyQueryResult::normal, "(C, 3) float64: unit normals, from B toward A")
      .def_readonly("penetration_depth", &PyQueryResult::penetrationDepth, "(C,) float64: depth, > 0 when penetrating")
      .def_readonly("level", &PyQueryResult::level, "(C,) uint32: hierarchy level the contact came from (0 = roots)")
      .def_readonly("error_bound", &PyQueryResult::errorBound,
                    "(C,) float64: how far the contact may be off (length units; 0 for exact contacts)")
      .def_readonly("feature_kind", &PyQueryResult::featureKind,
                    "(C,) uint8: what feature_a / feature_b index: CONTACT_FEATURE_NONE (0), _TRIANGLE (1, mesh\n"
                    "triangles: the exact model), _SPHERE (2, sphere-tree spheres: dos, average, cfm) or _CELL (3,\n"
                    "contact-tree nodes)")
      .def_readonly("feature_a", &PyQueryResult::featureA,
                    "(C,) uint32: the feature of body A the contact came from (NO_CONTACT_FEATURE when unknown)")
      .def_readonly("feature_b", &PyQueryResult::featureB, "(C,) uint32: the feature of body B")
      .def_readonly("point_on_a", &PyQueryResult::pointOnA,
                    "(C, 3) float64: the contact's point on A, pos - depth / 2 * normal (contact.h contactPointOnA)")
      .def_readonly("point_on_b", &PyQueryResult::pointOnB,
                    "(C, 3) float64: the contact's point on B, pos + depth / 2 * normal; (a - b) . normal = -depth")
      .def_readonly("budget_used", &PyQueryResult::budgetUsed, "tests made (sphere + triangle), never more than the budget")
      .def_readonly("sphere_tests", &PyQueryResult::sphereTests, "sphere-sphere tests of the traversal")
      .def_readonly("triangle_tests", &PyQueryResult::triangleTests, "triangle-triangle tests (exact model)")
      .def_readonly("finished", &PyQueryResult::finished, "True when the traversal reached the leaves (nothing left to refine)")
      .def_readonly("colliding", &PyQueryResult::colliding, "the bodies touch as far as the level reached can tell (query.h)")
      .def_readonly("stop", &PyQueryResult::stop, "why it stopped: \"finished\", \"test_budget\" or \"deadline\"")
      .def_readonly("model", &PyQueryResult::model, "the contact model that answered")
      .def_readonly("min_level", &PyQueryResult::minLevel, "shallowest pair level of the answer frontier")
      .def_readonly("max_level", &PyQueryResult::maxLevel, "deepest pair level of the answer frontier")
      .def_readonly("frontier_pairs", &PyQueryResult::frontierPairs, "node pairs of the frontier the contacts were built from")
      .def_readonly("raw_contacts", &PyQueryResult::rawContacts, "contacts before the manifold reduction")
      .def_readonly("fallback_pairs", &PyQueryResult::fallbackPairs, "exact model: frontier pairs answered by the cfm/dos fallback")
      .def_readonly("seconds", &PyQueryResult::seconds, "wall-clock seconds of the query")
      .def("__len__", [](const PyQueryResult& r) { return r.penetrationDepth.shape(0); })
      .def("__repr__", [](const PyQueryResult& r) {
        return "<clod.QueryResult " + r.model + ": " + std::to_string(r.penetrationDepth.shape(0)) + " contacts, " +
               std::to_string(r.budgetUsed) + " tests, " + r.stop + ">";
      });

  const QuerySettings defaults;
  mod.def("query", &runQuery, py::arg("bake_a"), py::arg("pose_a"), py::arg("bake_b"), py::arg("pose_b"), py::kw_only(),
        py::arg("model") = "cfm", py::arg("budget") = py::none(), py::arg("deadline_us") = py::none(),
        py::arg("max_contacts") = defaults.maxContacts, py::arg("max_level") = py::none(), py::arg("margin") = 0.0,
        "Contacts between body A (bake_a placed by pose_a) and body B, from the anytime narrow phase.\n\n"
        "pose: (7,) \"tx ty tz qw qx qy qz\" (mesh -> world) or a (4, 4) rigid transform.\n"
        "model: \"dos\", \"average\", \"cfm\" (closest feature maps), \"contact-tree\" or \"exact\" (clod.contact_models).\n"
        "budget: most sphere/triangle tests (>= 1; None = unlimited). deadline_us: wall-clock microseconds from\n"
        "the start of the query (None = none). Running out is not an error: the result holds the contacts of\n"
        "the level reached, finished=False and stop says why. max_contacts: manifold size 1..1024.\n"
        "max_level: deepest hierarchy level to descend to (None = leaves).\n"
        "margin: contact margin (>= 0, bake units): bodies apart by at most this get a speculative contact at\n"
        "their exact closest points (penetration_depth = -gap; QuerySettings::marginAbs).\n"
        "Raises clod.Error(bake_missing_section) when a bake lacks what the model needs, and\n"
        "clod.InvalidArgumentError for bad poses or options. GIL released.");

  py::class_<PyBatchResult>(mod, "BatchQueryResult",
                            "The answers of P queries (clod.query_batch) as arrays: contacts of query i are the rows\n"
                            "offsets[i]:offsets[i + 1] of pos, normal, penetration_depth, level, error_bound;\n"
                            "per-query arrays have P entries.")
      .def_readonly("offsets", &PyBatchResult::offsets, "(P + 1,) int64: CSR offsets into the contact arrays")
      .def_readonly("pos", &PyBatchResult::pos, "(C, 3) float64")
      .def_readonly("normal", &PyBatchResult::normal, "(C, 3) float64, from B toward A")
      .def_readonly("penetration_depth", &PyBatchResult::penetrationDepth, "(C,) float64")
      .def_readonly("level", &PyBatchResult::level, "(C,) uint32")
      .def_readonly("error_bound", &PyBatchResult::errorBound, "(C,) float64")
      .def_readonly("feature_kind", &PyBatchResult::featureKind, "(C,) uint8, as QueryResult.feature_kind")
      .def_readonly("feature_a", &PyBatchResult::featureA, "(C,) uint32")
      .def_readonly("feature_b", &PyBatchResult::featureB, "(C,) uint32")
      .def_readonly("point_on_a", &PyBatchResult::pointOnA, "(C, 3) float64")
      .def_readonly("point_on_b", &PyBatchResult::pointOnB, "(C, 3) float64")
      .def_readonly("budget_used", &PyBatchResult::budgetUsed, "(P,) uint64: tests per query")
      .def_readonly("finished", &PyBatchResult::finished, "(P,) bool")
      .def_readonly("colliding", &PyBatchResult::colliding, "(P,) bool")
      .def_readonly("stop", &PyBatchResult::stop, "(P,) uint8: 0 finished, 1 test budget, 2 deadline")
      .def_readonly("seconds", &PyBatchResult::seconds, "(P,) float64: each query's wall time")
      .def_readonly("min_level", &PyBatchResult::minLevel, "(P,) uint32")
      .def_readonly("max_level", &PyBatchResult::maxLevel, "(P,) uint32")
      .def_readonly("model", &PyBatchResult::model, "the contact model of the queries")
      .def_readonly("wall_seconds", &PyBatchResult::wallSeconds, "wall time of the parallel queries (no packing)")
      .def("__len__", [](const PyBatchResult& r) { return r.finished.shape(0); })
      .def("__repr__", [](const PyBatchResult& r) {
        return "<clod.BatchQueryResult " + r.model + ": " + std::to_string(r.finished.shape(0)) + " queries, " +
               std::to_string(r.penetrationDepth.shape(0)) + " contacts>";
      });
  mod.def("query_batch", &runQueryBatch, py::arg("bake_a"), py::arg("poses_a"), py::arg("bake_b"), py::arg("poses_b"), py::kw_only(),
        py::arg("model") = "cfm", py::arg("budget") = py::none(), py::arg("deadline_us") = py::none(),
        py::arg("max_contacts") = defaults.maxContacts, py::arg("max_level") = py::none(), py::arg("margin") = 0.0,
        "clod.query for P pose pairs at once, in parallel (TBB, GIL released): poses_a and poses_b are (P, 7) or\n"
        "(P, 4, 4) (or one pose, used for every query). Each query gets the whole budget and deadline. Returns a\n"
        "BatchQueryResult (contacts in CSR form); query i equals clod.query with the i-th poses.");

  py::class_<StepReport>(mod, "StepReport", "What one World.step did (world.h StepReport).")
      .def_readonly("substeps", &StepReport::substeps, "substeps the step took (anti-tunnelling, world.h)")
      .def_readonly("candidate_pairs", &StepReport::candidatePairs, "broad-phase pairs, summed over substeps")
      .def_readonly("tests_spent", &StepReport::testsSpent, "narrow-phase tests, all pairs and substeps")
      .def_readonly("tests_budget", &StepReport::testsBudget, "the step's budget in tests (0 = unlimited)")
      .def_readonly("budget_spent", &StepReport::budgetSpent, "tests + frontier_pair_cost x frontier pairs")
      .def_readonly("time_budget_micros", &StepReport::timeBudgetMicros, "the world's budget_us (0 = no time limit)")
      .def_readonly("time_spent_micros", &StepReport::timeSpentMicros, "narrow-phase time the time budget counted")
      .def_readonly("pairs_skipped", &StepReport::pairsSkipped, "pair queries skipped for lack of budget (old contacts kept)")
      .def_readonly("pairs_interrupted", &StepReport::pairsInterrupted, "queries that stopped before the leaves")
      .def_readonly("pairs_reused", &StepReport::pairsReused, "pair queries saved by manifold reuse")
      .def_readonly("pairs_proven_apart", &StepReport::pairsProvenApart, "pair queries saved by a gap the last query proved")
      .def_readonly("fallback_pairs", &StepReport::fallbackPairs, "exact model: frontier pairs answered by the cfm/dos fallback")
      .def_readonly("solver_iterations", &StepReport::solverIterations, "velocity iterations, summed over substeps")
      .def_readonly("cold_restarts", &StepReport::coldRestarts, "substeps whose warm-started solve was redone from zero")
      .def_readonly("narrow_phase_seconds", &StepReport::narrowPhaseSeconds, "wall seconds in the narrow phase")
      .def_readonly("solver_seconds", &StepReport::solverSeconds, "wall seconds in the velocity and position solves")
      .def_readonly("broad_phase_seconds", &StepReport::broadPhaseSeconds, "wall seconds in the broad phase and budget division")
      .def_readonly("frontier_pairs", &StepReport::frontierPairs, "frontier pairs answered, summed over substeps")
      .def_readonly("raw_contacts", &StepReport::rawContacts, "contacts before manifold reduction, summed")
      .def_readonly("solver_contacts", &StepReport::solverContacts, "contacts in the velocity solve, summed")
      .def_readonly("left_bounds", &StepReport::leftBounds, "ids of bodies that left the world's bounds this step")
      .def_property_readonly(
          "contact_pos", [](const StepReport& r) {
            py::array_t<double> out({py::ssize_t(r.contacts.size()), py::ssize_t(3)});
            for (std::size_t i = 0; i < r.contacts.size(); ++i)
              for (int k = 0; k < 3; ++k) out.mutable_data()[3 * i + k] = r.contacts[i].point[k];
            return out;
          },
          "(C, 3) float64: the last substep's contacts")
      .def_property_readonly(
          "contact_normal", [](const StepReport& r) {
            py::array_t<double> out({py::ssize_t(r.contacts.size()), py::ssize_t(3)});
            for (std::size_t i = 0; i < r.contacts.size(); ++i)
              for (int k = 0; k < 3; ++k) out.mutable_data()[3 * i + k] = r.contacts[i].normal[k];
            return out;
          },
          "(C, 3) float64, from the pair's body b toward body a")
      .def_property_readonly(
          "contact_depth", [](const StepReport& r) {
            py::array_t<double> out(py::ssize_t(r.contacts.size()));
            for (std::size_t i = 0; i < r.contacts.size(); ++i) out.mutable_data()[i] = r.contacts[i].depth;
            return out;
          },
          "(C,) float64")
      .def_property_readonly(
          "contact_bodies", [](const StepReport& r) {
            py::array_t<std::uint32_t> out({py::ssize_t(r.contactBodies.size()), py::ssize_t(2)});
            for (std::size_t i = 0; i < r.contactBodies.size(); ++i) {
              out.mutable_data()[2 * i] = r.contactBodies[i][0];
              out.mutable_data()[2 * i + 1] = r.contactBodies[i][1];
            }
            return out;
          },
          "(C, 2) uint32: body ids (a, b) of each contact")
      .def_property_readonly(
          "contact_points", [](const StepReport& r) {
            py::array_t<double> out({py::ssize_t(r.contactPoints.size()), py::ssize_t(2), py::ssize_t(3)});
            for (std::size_t i = 0; i < r.contactPoints.size(); ++i)
              for (int j = 0; j < 2; ++j)
                for (int k = 0; k < 3; ++k) out.mutable_data()[6 * i + 3 * j + k] = r.contactPoints[i][j][k];
            return out;
          },
          "(C, 2, 3) float64: per contact the point on body a and the point on body b the solver holds apart")
      .def_property_readonly(
          "contact_features", [](const StepReport& r) {
            ContactArrays arrays(r.contacts.size());
            for (std::size_t i = 0; i < r.contacts.size(); ++i) arrays.set(i, r.contacts[i]);
            return arrays.features();
          },
          "the last substep's contacts' features as a dict of arrays: feature_kind (C,) uint8, feature_a and\n"
          "feature_b (C,) uint32 (features of contact_bodies' a and b), point_on_a and point_on_b (C, 3) float64\n"
          "(contact.h contactPointOnA/B; contact_points are where the solver anchored them)")
      .def_property_readonly(
          "pairs", [](const StepReport& r) {
            const py::ssize_t n = static_cast<py::ssize_t>(r.pairs.size());
            py::array_t<std::uint32_t> bodies({n, py::ssize_t(2)}), level(n), contacts(n);
            py::array_t<std::uint64_t> tests(n), fallbackPairs(n);
            py::array_t<bool> finished(n), skipped(n), reused(n), provenApart(n), keptFiner(n);
            for (py::ssize_t i = 0; i < n; ++i) {
              const PairReport& p = r.pairs[static_cast<std::size_t>(i)];
              bodies.mutable_data()[2 * i] = p.a;
              bodies.mutable_data()[2 * i + 1] = p.b;
              level.mutable_data()[i] = p.level;
              contacts.mutable_data()[i] = p.contacts;
              tests.mutable_data()[i] = p.tests;
              fallbackPairs.mutable_data()[i] = p.fallbackPairs;
              finished.mutable_data()[i] = p.finished;
              skipped.mutable_data()[i] = p.skipped;
              reused.mutable_data()[i] = p.reused;
              provenApart.mutable_data()[i] = p.provenApart;
              keptFiner.mutable_data()[i] = p.keptFiner;
            }
            py::dict out;
            out["bodies"] = bodies;
            out["tests"] = tests;
            out["level"] = level;
            out["finished"] = finished;
            out["skipped"] = skipped;
            out["reused"] = reused;
            out["proven_apart"] = provenApart;
            out["kept_finer"] = keptFiner;
            out["fallback_pairs"] = fallbackPairs;
            out["contacts"] = contacts;
            return out;
          },
          "per-pair report as a dict of arrays (include/clod/world.h, PairReport): bodies (n, 2), tests, level,\n"
          "finished, skipped, reused (manifold reuse), proven_apart, kept_finer (an interrupted answer held back by\n"
          "a finer manifold), fallback_pairs, contacts")
      .def("__repr__", [](const StepReport& r) {
        return "<clod.StepReport " + std::to_string(r.substeps) + " substeps, " + std::to_string(r.testsSpent) + " tests, " +
               std::to_string(r.contacts.size()) + " contacts>";
      });

  const WorldSettings w;
  py::class_<PyWorld>(mod, "World",
                      "A rigid-body world with a per-step collision budget (docs/dynamics.md). Build it from a scene\n"
                      "file (World.from_scene) or in code: World(...) then add_body(bake, ...). Deterministic for test\n"
                      "budgets: the same scene and settings give bit-identical states.")
      .def(py::init(&makeWorld), py::kw_only(), py::arg("gravity") = py::make_tuple(w.gravity.x(), w.gravity.y(), w.gravity.z()),
           py::arg("model") = std::string(contactModelName(w.model)), py::arg("budget") = w.budgetTests,
           py::arg("budget_us") = w.budgetMicros, py::arg("dt") = 1.0 / 60.0, py::arg("max_contacts") = w.maxContacts,
           py::arg("min_substeps") = w.minSubsteps, py::arg("max_substeps") = w.maxSubsteps,
           py::arg("velocity_iterations") = w.velocityIterations, py::arg("position_iterations") = w.positionIterations,
           py::arg("frontier_pair_cost") = w.frontierPairCost, py::arg("restitution_threshold") = w.restitutionThreshold,
           py::arg("rolling_resistance") = w.rollingResistanceRel,
           "An empty world. budget: tests per step (0 = unlimited); budget_us: narrow-phase microseconds per step\n"
           "(0 = none; not repeatable bit for bit); dt: the default step length of step() and run().\n"
           "Out-of-range settings raise clod.InvalidArgumentError naming the setting.")
      .def_static(
          "from_scene", [](const std::string& path, const std::optional<std::string>& model, std::optional<long long> budget,
                           std::optional<double> budgetUs, const std::string& cacheDir) {
            SceneDescription scene;
            {
              py::gil_scoped_release release;
              scene = loadScene(path);
            }
            return worldFromScene(std::move(scene), model, budget, budgetUs, cacheDir);
          },
          py::arg("path"), py::kw_only(), py::arg("model") = py::none(), py::arg("budget") = py::none(),
          py::arg("budget_us") = py::none(), py::arg("cache_dir") = "",
          "The world of a JSON scene file (scenes/*.json, format in docs/dynamics.md): meshes loaded and baked\n"
          "(cached in cache_dir when given), bodies added in scene order. model / budget / budget_us override\n"
          "the scene's. dt and steps come from the scene. Raises clod.Error(scene_error) naming the key path.")
      .def_static(
          "from_json", [](const std::string& text, const std::string& baseDir, const std::optional<std::string>& model,
                          std::optional<long long> budget, std::optional<double> budgetUs, const std::string& cacheDir) {
            return worldFromScene(parseScene(text, baseDir, "scene"), model, budget, budgetUs, cacheDir);
          },
          py::arg("text"), py::arg("base_dir") = ".", py::kw_only(), py::arg("model") = py::none(), py::arg("budget") = py::none(),
          py::arg("budget_us") = py::none(), py::arg("cache_dir") = "",
          "As from_scene, from the scene's JSON text; relative mesh paths are resolved against base_dir.")
      .def("add_body", &addBody, py::arg("shape"), py::kw_only(), py::arg("mass") = py::none(), py::arg("density") = 1000.0,
           py::arg("type") = "dynamic", py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
           py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0), py::arg("velocity") = py::make_tuple(0.0, 0.0, 0.0),
           py::arg("angular_velocity") = py::make_tuple(0.0, 0.0, 0.0), py::arg("restitution") = 0.0, py::arg("friction") = 0.5,
           py::arg("name") = "", py::arg("scale") = 1.0,
           "Adds a body with shape (a clod.Bake; shared, not copied) and returns its id (0, 1, ...).\n"
           "scale: uniform scale of the shape (> 0), without baking again (mass properties follow at `density`).\n"
           "type: \"dynamic\", \"static\" or \"kinematic\". Mass properties are the mesh's at `density` (an open mesh:\n"
           "its bounding box's); `mass` rescales them. position: where the mesh origin goes; orientation (w, x, y, z);\n"
           "velocity of the centre of mass; angular_velocity in the world frame (rad/s).")
      .def(
          "step", [](PyWorld& self, std::optional<double> dt) {
            const double h = dt ? *dt : self.dt;
            py::gil_scoped_release release;
            return StepReport(self.world.step(h));
          },
          py::arg("dt") = py::none(),
          "Advances by dt (default: the world's dt) and returns the StepReport. Raises\n"
          "clod.Error(simulation_diverged) naming the body if a state becomes NaN/Inf. GIL released.")
      .def("run", &runWorld, py::arg("steps") = py::none(), py::arg("dt") = py::none(),
           "Runs `steps` steps (default: the scene's step count) with the GIL released and returns a dict of arrays:\n"
           "positions (S, n, 3), orientations (S, n, 4) (w, x, y, z) after each step, and per step tests_spent,\n"
           "budget_spent, substeps, contacts (count), narrow_phase_seconds.")
      .def_readonly("dt", &PyWorld::dt, "default step length (s)")
      .def_readonly("steps", &PyWorld::steps, "the scene's step count (0 for a world built in code)")
      .def_property_readonly("body_count", [](const PyWorld& self) { return self.world.bodyCount(); }, "bodies in the world (ids 0 .. n-1)")
      .def_property_readonly(
          "names", [](const PyWorld& self) {
            std::vector<std::string> names;
            for (std::size_t i = 0; i < self.world.bodyCount(); ++i)
              names.push_back(self.world.contains(BodyId(i)) ? self.world.desc(static_cast<BodyId>(i)).name : std::string());
            return names;
          },
          "body names, by id")
      .def_property_readonly(
          "types", [](const PyWorld& self) {
            std::vector<std::string> types;
            for (std::size_t i = 0; i < self.world.bodyCount(); ++i)
              types.push_back(self.world.contains(BodyId(i)) ? bodyTypeName(self.world.type(static_cast<BodyId>(i))) : "removed");
            return types;
          },
          "current body types (a body that left the bounds is \"static\")")
      .def_property_readonly(
          "masses", [](const PyWorld& self) {
            py::array_t<double> out(py::ssize_t(self.world.bodyCount()));
            for (std::size_t i = 0; i < self.world.bodyCount(); ++i)
              out.mutable_data()[i] = self.world.contains(BodyId(i)) ? self.world.mass(static_cast<BodyId>(i)) : 0.0;
            return out;
          },
          "(n,) float64 (0 for static and kinematic bodies)")
      .def_property_readonly("positions", [](const PyWorld& self) { return stateArray(self.world, 3, putPosition); },
                             "(n, 3) float64: world position of each body's mesh origin")
      .def_property_readonly("orientations", [](const PyWorld& self) { return stateArray(self.world, 4, putOrientation); },
                             "(n, 4) float64: unit quaternions (w, x, y, z), mesh -> world")
      .def_property_readonly(
          "velocities", [](const PyWorld& self) {
            return stateArray(self.world, 3, [](const RigidBodyState& s, double* o) {
              for (int k = 0; k < 3; ++k) o[k] = s.velocity[k];
            });
          },
          "(n, 3) float64: centre-of-mass velocities")
      .def_property_readonly(
          "angular_velocities", [](const PyWorld& self) {
            return stateArray(self.world, 3, [](const RigidBodyState& s, double* o) {
              for (int k = 0; k < 3; ++k) o[k] = s.angularVelocity[k];
            });
          },
          "(n, 3) float64: world frame, rad/s")
      .def("kinetic_energy", [](const PyWorld& self) { return self.world.kineticEnergy(); })
      .def("potential_energy", [](const PyWorld& self) { return self.world.potentialEnergy(); })
      .def("state_hash", [](const PyWorld& self) { return self.world.stateHash(); },
           "64-bit hash of every body's state bits (equal hashes: bit-identical states)")
      .def("set_model", [](PyWorld& self, const std::string& model) { self.world.setModel(parseContactModel(model)); }, py::arg("model"),
           "Changes the contact model between steps (the model's data must be in the bodies' bakes).")
      .def("set_budget", [](PyWorld& self, std::uint64_t tests) { self.world.setBudgetTests(tests); }, py::arg("tests"),
           "Changes the tests-per-step budget between steps (0 = unlimited).")
      .def("remove_body", [](PyWorld& self, BodyId id) { self.world.removeBody(id); }, py::arg("id"),
           "Removes a body. Its id is retired, never reused; every other id stays valid. The state arrays keep\n"
           "a row per id (NaN for removed ones), types says \"removed\".")
      .def("contains", [](const PyWorld& self, BodyId id) { return self.world.contains(id); }, py::arg("id"),
           "True when id names a body that was added and not removed.")
      .def("set_state", &setBodyState, py::arg("id"), py::kw_only(), py::arg("position") = py::none(),
           py::arg("orientation") = py::none(), py::arg("velocity") = py::none(), py::arg("angular_velocity") = py::none(),
           "Sets what is given of a body's state (the rest stays). orientation (w, x, y, z) must be a unit\n"
           "quaternion to within 1e-3; a static body's velocities must stay zero (clod.InvalidArgumentError).")
      .def(
          "apply_force", [](PyWorld& self, BodyId id, const ArrayLike& force, const std::optional<ArrayLike>& point) {
            const Vec3 f = vec3Arg(force, "force");
            self.world.applyForce(id, f, point ? vec3Arg(*point, "point") : centreOfMass(self.world, id));
          },
          py::arg("id"), py::arg("force"), py::arg("point") = py::none(),
          "Force (world frame) on a dynamic body during the next step, at `point` (world; default the centre\n"
          "of mass). Accumulates until the step, then clears. Ignored for static and kinematic bodies.")
      .def("apply_torque", [](PyWorld& self, BodyId id, const ArrayLike& torque) { self.world.applyTorque(id, vec3Arg(torque, "torque")); },
           py::arg("id"), py::arg("torque"), "Torque (world frame) during the next step, like apply_force.")
      .def(
          "apply_impulse", [](PyWorld& self, BodyId id, const ArrayLike& impulse, const std::optional<ArrayLike>& point) {
            const Vec3 j = vec3Arg(impulse, "impulse");
            self.world.applyImpulse(id, j, point ? vec3Arg(*point, "point") : centreOfMass(self.world, id));
          },
          py::arg("id"), py::arg("impulse"), py::arg("point") = py::none(),
          "Impulse at `point` (world; default the centre of mass), applied to the velocities at once.")
      .def(
          "set_filter", [](PyWorld& self, BodyId id, std::uint32_t group, std::uint32_t mask) {
            self.world.setFilter(id, CollisionFilter{group, mask});
          },
          py::arg("id"), py::kw_only(), py::arg("group") = 1u, py::arg("mask") = 0xffffffffu,
          "Collision filter: bodies a and b collide only if (a.group & b.mask) and (b.group & a.mask).")
      .def(
          "filter", [](const PyWorld& self, BodyId id) {
            const CollisionFilter f = self.world.filter(id);
            return py::make_tuple(f.group, f.mask);
          },
          py::arg("id"), "(group, mask) of a body")
      .def("set_contact_callback", &setContactCallback, py::arg("callback"), py::kw_only(), py::arg("features") = false,
           "callback(a, b, pos, normal, depth, substep) -> bool, called per pair with contacts in every substep\n"
           "(pos, normal (C, 3), depth (C,)); False disables the pair for the rest of the step. None removes it.\n"
           "features=True adds a seventh argument: a dict of feature_kind (C,) uint8, feature_a, feature_b (C,)\n"
           "uint32 and point_on_a, point_on_b (C, 3), as in QueryResult (body a is the contacts' A).\n"
           "It must not edit the world. Slows stepping: the GIL is taken for each call.")
      .def(
          "separation", [](const PyWorld& self, BodyId a, BodyId b, double maxDistance) {
            Separation r;
            {
              py::gil_scoped_release release;
              r = self.world.separation(a, b, maxDistance);
            }
            return separationDict(r);
          },
          py::arg("a"), py::arg("b"), py::kw_only(), py::arg("max_distance") = std::numeric_limits<double>::infinity(),
          "Exact closest distance between two bodies' surfaces as placed now: a dict with distance, within_max,\n"
          "overlapping, point_a, point_b (world), triangle_a, triangle_b (world.h Separation). GIL released.")
      .def_property_readonly("model", [](const PyWorld& self) { return std::string(contactModelName(self.world.settings().model)); },
                             "the contact model of every pair")
      .def_property_readonly("budget", [](const PyWorld& self) { return self.world.settings().budgetTests; }, "tests per step (0 = unlimited)")
      .def("__repr__", [](const PyWorld& self) {
        return "<clod.World " + std::to_string(self.world.bodyCount()) + " bodies, model " +
               std::string(contactModelName(self.world.settings().model)) + ">";
      });

  py::list scenarios;
  for (ScenarioKind kind : kAllScenarios) scenarios.append(std::string(scenarioName(kind)));
  mod.attr("scenarios") = scenarios;
  mod.def("_degradation_table", &degradationTable, py::arg("scenarios"), py::arg("models"), py::arg("budgets"), py::arg("budgets_us"),
        py::arg("rates"), py::arg("seconds"), py::arg("mesh_dir"), py::arg("cache_dir"),
        "The degradation experiment's table (clod.experiment(\"degradation\", ...) documents it).");
}

}  // namespace clod::python
