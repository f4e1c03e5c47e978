#include "clod/mujoco/collider.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>
#include <vector>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/contact_tree_builder.h"
#include "clod/error.h"
#include "clod/mesh_weld.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/query.h"

namespace clod::mujoco {

namespace {

using Clock = std::chrono::steady_clock;

// Adds one step's counts to running totals; the time is the later step's.
void accumulate(StepStats& t, const StepStats& c) {
  t.time = c.time;
  t.pairs += c.pairs;
  t.pairsSkipped += c.pairsSkipped;
  t.pairsInterrupted += c.pairsInterrupted;
  t.pairsFallback += c.pairsFallback;
  t.testsSpent += c.testsSpent;
  t.budgetSpent += c.budgetSpent;
  t.testsBudget += c.testsBudget;
  t.contacts += c.contacts;
  t.seconds += c.seconds;
}

// A contact kept for a pair the budget skips later: each surface point anchored in its own
// geom, the normal (geom1 -> geom2) in geom1's frame (docs/engines-mujoco.md).
struct Anchor {
  Vec3 local1, local2, normal1;
};

struct PairState {
  CoherenceCache cache;
  std::vector<Anchor> anchors;
  // The step plan (Impl::planStep): units set aside for this pair, how many steps it has waited
  // for a query, its last deepest depth (priority), and whether its front is dropped.
  std::uint64_t allot = 0;
  std::uint32_t age = 0;
  double priority = 0.0;
  bool planned = false;
  bool restart = false;
};

struct DataState {
  const mjModel* model = nullptr;
  bool started = false;
  double time = 0.0;
  StepStats current, last, totals;
  bool hasLast = false;
  std::uint64_t pool = 0;  // units of a limited step budget not set aside for a pair, or left over
  bool limited = false;
  std::vector<std::uint64_t> calledThisStep, calledLastStep;  // pair keys in call order
  Clock::time_point stepStart;
  std::unordered_map<std::uint64_t, PairState> pairs;  // key: g1 << 32 | g2
};

struct ModelState {
  std::vector<const CollisionBody*> geomBody;  // null: not answered by clod
};

Pose geomPose(const mjData* d, int g) {
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation(d->geom_xmat + 9 * g);
  Pose pose;
  pose.rotation = Quat(Mat3(rotation)).normalized();
  pose.translation = Vec3(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
  return pose;
}

// Rows n, t1, t2 of a right-handed orthonormal frame (t2 = n x t1), t1 built from the world axis
// least aligned with n, so the frame is a continuous function of n away from those switches.
void writeFrame(const Vec3& n, mjtNum frame[9]) {
  Vec3 axis = Vec3::UnitX();
  if (std::abs(n.y()) < std::abs(n.x()) && std::abs(n.y()) <= std::abs(n.z())) axis = Vec3::UnitY();
  else if (std::abs(n.z()) < std::abs(n.x()) && std::abs(n.z()) < std::abs(n.y())) axis = Vec3::UnitZ();
  const Vec3 t1 = n.cross(axis).normalized();
  const Vec3 t2 = n.cross(t1);
  for (int k = 0; k < 3; ++k) {
    frame[k] = n[k];
    frame[3 + k] = t1[k];
    frame[6 + k] = t2[k];
  }
}

bool chargesFrontier(ContactModel model) { return model != ContactModel::kDos && model != ContactModel::kAverage; }

// Budget units per microsecond are learned from the steps; this seed is a sphere-tree test plus
// a share of its answer on this machine class (docs/engines-mujoco.md).
constexpr double kSeedMicrosPerUnit = 0.05;

}  // namespace

struct Collider::Impl {
  ColliderSettings settings;
  std::unordered_map<std::uint64_t, std::shared_ptr<const CollisionBody>> shapes;  // by mesh hash
  std::unordered_map<const mjModel*, ModelState> models;
  std::unordered_map<const mjData*, DataState> data;
  std::vector<std::pair<const std::uint64_t, PairState>*> planOrder;  // planStep's scratch
  QueryScratch scratch;
  QueryResult result;
  QuerySettings query;
  std::string lastError;
  double microsPerUnit = kSeedMicrosPerUnit;
  bool installed = false;
  mjfCollision saved[mjNGEOMTYPES][mjNGEOMTYPES] = {};

  const CollisionBody* bake(const TriangleMesh& mesh, const std::string& name);
  DataState& stateFor(const mjModel* m, const mjData* d);
  void finishStep(DataState& ds);
  void planStep(DataState& ds, std::uint64_t units);
  int collide(const mjModel* m, const mjData* d, mjContact* con, int g1, int g2, mjtNum margin);
  int replay(const PairState& ps, const Pose& pose1, const Pose& pose2, mjContact* con, mjtNum margin) const;
};

namespace {

Collider::Impl* gActive = nullptr;

// The one function clod puts into mjCOLLISIONFUNC. Never lets an exception into MuJoCo.
int collideTrampoline(const mjModel* m, const mjData* d, mjContact* con, int g1, int g2, mjtNum margin) {
  Collider::Impl* impl = gActive;
  if (impl) {
    int n = -1;
    try {
      n = impl->collide(m, d, con, g1, g2, margin);
    } catch (const std::exception& e) {
      impl->lastError = e.what();
    }
    if (n >= 0) return n;
    auto found = impl->data.find(d);
    if (found != impl->data.end() && impl->models.count(m)) ++found->second.current.pairsFallback;
    const mjfCollision own = impl->saved[m->geom_type[g1]][m->geom_type[g2]];
    return own ? own(m, d, con, g1, g2, margin) : 0;
  }
  const mjfCollision own = mjCOLLISIONFUNC[m->geom_type[g1]][m->geom_type[g2]];
  return own && own != &collideTrampoline ? own(m, d, con, g1, g2, margin) : 0;
}

}  // namespace

const CollisionBody* Collider::Impl::bake(const TriangleMesh& mesh, const std::string& name) {
  const std::uint64_t hash = meshContentHash(mesh);
  auto found = shapes.find(hash);
  if (found != shapes.end()) return found->second.get();
  BakeSettings bs;
  bs.sphereTree = settings.sphereTree;
  bs.measureFit = false;
  bs.buildContactTree = false;  // below, only when the model needs it
  bs.sourceName = name;
  BakeResult baked = bakeMesh(mesh, bs);
  auto body = std::make_shared<CollisionBody>(CollisionBody::fromBake(baked.contents));
  body->setName(name);
  if (settings.model == ContactModel::kContactTree) {
    ContactTreeSettings ct;
    ct.maxDepth = settings.contactTreeDepth;
    body->setContactTree(buildContactTree(MeshDistance(mesh), ct));
  }
  return shapes.emplace(hash, std::move(body)).first->second.get();
}

DataState& Collider::Impl::stateFor(const mjModel* m, const mjData* d) {
  DataState& ds = data[d];
  if (ds.model != m || (ds.started && d->time < ds.time)) {
    ds = DataState{};  // another model at this address, or a reset: start over
    ds.model = m;
  }
  if (!ds.started || d->time != ds.time) {
    if (ds.started) finishStep(ds);
    ds.started = true;
    ds.time = d->time;
    ds.current = StepStats{};
    ds.current.time = d->time;
    ds.stepStart = Clock::now();
    std::uint64_t units = settings.budgetTests;
    if (settings.budgetMicros > 0.0) {
      const double fromTime = std::max(1.0, std::floor(settings.budgetMicros / microsPerUnit));
      const std::uint64_t timeUnits = fromTime >= 1e18 ? std::uint64_t(1e18) : std::uint64_t(fromTime);
      units = units == 0 ? timeUnits : std::min(units, timeUnits);
    }
    ds.limited = units != 0;
    ds.current.testsBudget = units;
    if (ds.limited) planStep(ds, units);
  }
  return ds;
}

void Collider::Impl::finishStep(DataState& ds) {
  StepStats& c = ds.current;
  if (settings.budgetMicros > 0.0 && c.budgetSpent > 0) {
    // Exponential average of the measured cost of a budget unit, as World does for budgetMicros.
    const double measured = c.seconds * 1e6 / double(c.budgetSpent);
    microsPerUnit = 0.7 * microsPerUnit + 0.3 * std::max(measured, 1e-4);
  }
  std::swap(ds.calledLastStep, ds.calledThisStep);
  ds.calledThisStep.clear();
  ds.last = c;
  ds.hasLast = true;
  accumulate(ds.totals, c);
}

// World's division (world.h), planned at the first call of a step from the pairs the previous
// step called, since MuJoCo calls the pairs one at a time: rank them by how long they have waited
// for a query (a starved pair first), then by their last depth; walking down, each gets
// ceil(units left / pairs left), at least what one test costs it (its cached front's answer, the
// test and the pair it may add), while units are left. A pair whose front costs more than an
// even share restarts from the roots. What is not set aside (and what a pair leaves) is a pool
// that pairs called later in the step draw on, new pairs included.
void Collider::Impl::planStep(DataState& ds, std::uint64_t units) {
  planOrder.clear();
  for (std::uint64_t key : ds.calledLastStep) {
    auto it = ds.pairs.find(key);
    if (it != ds.pairs.end()) planOrder.push_back(&*it);
  }
  std::sort(planOrder.begin(), planOrder.end(), [](const auto* a, const auto* b) {
    if (a->second.age != b->second.age) return a->second.age > b->second.age;
    if (a->second.priority != b->second.priority) return a->second.priority > b->second.priority;
    return a->first < b->first;
  });
  const std::uint64_t cost = chargesFrontier(settings.model) ? settings.frontierPairCost : 0;
  const std::uint64_t evenShare = planOrder.empty() ? units : units / planOrder.size();
  std::uint64_t left = units;
  for (std::size_t i = 0; i < planOrder.size(); ++i) {
    PairState& ps = planOrder[i]->second;
    const std::uint64_t share = (left + (planOrder.size() - i) - 1) / (planOrder.size() - i);
    std::uint64_t front = settings.coherence ? std::max<std::size_t>(1, ps.cache.frontSize()) : 1;
    ps.restart = front > 1 && cost * front > evenShare;
    if (ps.restart) front = 1;
    const std::uint64_t need = cost * front + 1 + cost;
    ps.allot = left >= need ? std::max(share, need) : 0;
    ps.planned = true;
    left -= ps.allot;
  }
  ds.pool = left;
}

int Collider::Impl::replay(const PairState& ps, const Pose& pose1, const Pose& pose2, mjContact* con,
                           mjtNum margin) const {
  int n = 0;
  for (const Anchor& a : ps.anchors) {
    const Vec3 p1 = pose1.apply(a.local1), p2 = pose2.apply(a.local2);
    const Vec3 normal = pose1.rotation * a.normal1;
    const double dist = -(p1 - p2).dot(normal);
    if (dist > margin) continue;
    mjContact& out = con[n++];
    out.dist = dist;
    const Vec3 mid = 0.5 * (p1 + p2);
    for (int k = 0; k < 3; ++k) out.pos[k] = mid[k];
    writeFrame(normal, out.frame);
  }
  return n;
}

int Collider::Impl::collide(const mjModel* m, const mjData* d, mjContact* con, int g1, int g2, mjtNum margin) {
  auto modelIt = models.find(m);
  if (modelIt == models.end()) return -1;
  const ModelState& ms = modelIt->second;
  if (g1 < 0 || g2 < 0 || std::size_t(g1) >= ms.geomBody.size() || std::size_t(g2) >= ms.geomBody.size()) return -1;
  const CollisionBody* body1 = ms.geomBody[g1];
  const CollisionBody* body2 = ms.geomBody[g2];
  if (!body1 || !body2) return -1;
  DataState& ds = stateFor(m, d);
  const auto t0 = Clock::now();
  auto [it, inserted] = ds.pairs.try_emplace(std::uint64_t(std::uint32_t(g1)) << 32 | std::uint32_t(g2));
  PairState& ps = it->second;
  if (inserted) ps.anchors.reserve(settings.maxContacts);
  const Pose pose1 = geomPose(d, g1), pose2 = geomPose(d, g2);
  StepStats& stats = ds.current;
  ++stats.pairs;

  // What this pair may spend: its planned allotment plus the pool (planStep).
  std::uint64_t maxTests = kUnlimitedTests;
  std::uint64_t available = 0;
  bool skip = false;
  const std::uint64_t cost = chargesFrontier(settings.model) ? settings.frontierPairCost : 0;
  if (ds.limited) {
    const bool timeGone = settings.budgetMicros > 0.0 &&
                          std::chrono::duration<double, std::micro>(t0 - ds.stepStart).count() >= settings.budgetMicros;
    available = (ps.planned ? ps.allot : 0) + ds.pool;
    ds.pool = 0;
    if (ps.planned && ps.restart) ps.cache.clear();
    ps.planned = false;
    // A query's frontier is at most its starting front plus its tests, so tests t with
    // t + cost (front + t) <= available keep its charge within what it may spend.
    const std::uint64_t front = settings.coherence ? std::max<std::size_t>(1, ps.cache.frontSize()) : 1;
    maxTests = cost == 0 ? available : (available > cost * front ? (available - cost * front) / (1 + cost) : 0);
    skip = timeGone || maxTests == 0;
    if (skip) ds.pool = available;  // unspent: to the pairs after it
  }
  ds.calledThisStep.push_back(it->first);
  int n = 0;
  if (skip) {
    ++stats.pairsSkipped;
    ++ps.age;
    n = replay(ps, pose1, pose2, con, margin);
  } else {
    query.budget = QueryBudget{};
    query.budget.maxTests = maxTests;
    if (settings.budgetMicros > 0.0)
      query.budget.deadline = ds.stepStart + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double, std::micro>(settings.budgetMicros));
    // MuJoCo's margin: contacts up to `margin` apart count (mjContact::dist > 0), so the query
    // adds the closest points of surfaces within it as a speculative contact (QuerySettings::marginAbs).
    query.marginAbs = margin > 0.0 && std::isfinite(margin) ? double(margin) : 0.0;
    // A is geom1 and B geom2: clod's normals (B -> A) are MuJoCo's (geom1 -> geom2) negated.
    queryContacts(*body1, pose1, *body2, pose2, query, scratch, result, settings.coherence ? &ps.cache : nullptr);
    const std::uint64_t spent = result.tests + cost * result.frontier.size();
    stats.testsSpent += result.tests;
    stats.budgetSpent += spent;
    if (ds.limited) ds.pool = available - std::min(available, spent);
    if (!result.finished) ++stats.pairsInterrupted;
    ps.age = 0;
    ps.priority = result.contacts.empty() ? 0.0 : result.contacts.front().depth;
    ps.anchors.clear();
    const std::size_t limit = std::min<std::size_t>(settings.maxContacts, mjMAXCONPAIR);
    for (const Contact& c : result.contacts) {
      if (std::size_t(n) >= limit) break;
      double depth = c.depth;
      // A speculative contact (depth < 0) keeps its gap: only a penetration has an uncertain part.
      if (settings.depthReport == DepthReport::kCertainDepth && depth > 0.0) depth = std::max(0.0, depth - c.errorBound);
      const Vec3 normal = -c.normal;
      const Vec3 p1 = c.point + 0.5 * depth * normal, p2 = c.point - 0.5 * depth * normal;
      ps.anchors.push_back({pose1.applyInverse(p1), pose2.applyInverse(p2), pose1.rotation.conjugate() * normal});
      if (-depth > margin) continue;
      mjContact& out = con[n++];
      out.dist = -depth;
      for (int k = 0; k < 3; ++k) out.pos[k] = c.point[k];
      writeFrame(normal, out.frame);
    }
  }
  stats.contacts += std::uint32_t(n);
  stats.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  return n;
}

Collider::Collider(const ColliderSettings& settings) : impl_(std::make_unique<Impl>()) {
  auto bad = [](const std::string& what) { throw Error(ErrorCode::kInvalidArgument, "mujoco collider: " + what); };
  if (!(settings.budgetMicros >= 0.0) || !std::isfinite(settings.budgetMicros))
    bad("budgetMicros " + std::to_string(settings.budgetMicros) + " is not a finite number >= 0");
  if (settings.maxContacts < 1 || settings.maxContacts > mjMAXCONPAIR)
    bad("maxContacts " + std::to_string(settings.maxContacts) + " not in [1, " + std::to_string(mjMAXCONPAIR) + "]");
  if (settings.frontierPairCost > 1024)
    bad("frontierPairCost " + std::to_string(settings.frontierPairCost) + " > 1024");
  if (settings.contactTreeDepth < 1 || settings.contactTreeDepth > 20)
    bad("contactTreeDepth " + std::to_string(settings.contactTreeDepth) + " not in [1, 20]");
  impl_->settings = settings;
  impl_->query.model = settings.model;
  impl_->query.maxContacts = settings.maxContacts;
}

Collider::~Collider() { uninstall(); }

void Collider::addModel(const mjModel* m) {
  if (!m) throw Error(ErrorCode::kInvalidArgument, "mujoco collider: addModel(nullptr)");
  ModelState ms;
  ms.geomBody.assign(std::size_t(m->ngeom), nullptr);
  std::vector<const CollisionBody*> meshBody(std::size_t(m->nmesh), nullptr);
  for (int g = 0; g < m->ngeom; ++g) {
    const char* geomName = mj_id2name(m, mjOBJ_GEOM, g);
    const std::string geomLabel = "geom " + std::to_string(g) + (geomName ? std::string(" '") + geomName + "'" : "");
    try {
      if (m->geom_type[g] == mjGEOM_MESH) {
        const int id = m->geom_dataid[g];
        if (id < 0 || id >= m->nmesh) continue;
        if (!meshBody[id]) {
          const char* meshName = mj_id2name(m, mjOBJ_MESH, id);
          const std::string label = meshName ? meshName : "mesh " + std::to_string(id);
          TriangleMesh mesh;
          const int v0 = m->mesh_vertadr[id], nv = m->mesh_vertnum[id];
          const int f0 = m->mesh_faceadr[id], nf = m->mesh_facenum[id];
          mesh.vertices.reserve(std::size_t(nv));
          for (int v = 0; v < nv; ++v) {
            const float* p = m->mesh_vert + 3 * std::size_t(v0 + v);
            mesh.vertices.emplace_back(p[0], p[1], p[2]);
          }
          mesh.triangles.reserve(std::size_t(nf));
          for (int f = 0; f < nf; ++f) {
            const int* t = m->mesh_face + 3 * std::size_t(f0 + f);
            for (int k = 0; k < 3; ++k)
              if (t[k] < 0 || t[k] >= nv)
                throw Error(ErrorCode::kIndexOutOfRange, "face " + std::to_string(f) + ": vertex index " +
                                                             std::to_string(t[k]) + " not below " + std::to_string(nv));
            mesh.triangles.push_back({std::uint32_t(t[0]), std::uint32_t(t[1]), std::uint32_t(t[2])});
          }
          // MuJoCo's OBJ and STL readers give every face its own corners: weld bit-identical
          // positions back together so the mesh is connected (its topology matters to clod).
          weldVertices(mesh, 0.0);
          meshBody[id] = impl_->bake(mesh, label);
        }
        ms.geomBody[g] = meshBody[id];
      } else if (m->geom_type[g] == mjGEOM_BOX && impl_->settings.boxMesh) {
        const mjtNum* s = m->geom_size + 3 * g;
        ms.geomBody[g] = impl_->bake(makeBox(Vec3(s[0], s[1], s[2])), "box");
      }
    } catch (const Error& e) {
      throw Error(e.code(), geomLabel + ": " + e.what());
    }
  }
  impl_->models[m] = std::move(ms);
}

void Collider::removeModel(const mjModel* m) {
  impl_->models.erase(m);
  for (auto it = impl_->data.begin(); it != impl_->data.end();) it = it->second.model == m ? impl_->data.erase(it) : std::next(it);
}

void Collider::forgetData(const mjData* d) { impl_->data.erase(d); }

void Collider::install() {
  if (impl_->installed) return;
  if (gActive) {
    // Restore the other collider's saved table first, so ours saves MuJoCo's own functions.
    for (int i = 0; i < mjNGEOMTYPES; ++i)
      for (int j = 0; j < mjNGEOMTYPES; ++j) mjCOLLISIONFUNC[i][j] = gActive->saved[i][j];
    gActive->installed = false;
    gActive = nullptr;
  }
  for (int i = 0; i < mjNGEOMTYPES; ++i)
    for (int j = 0; j < mjNGEOMTYPES; ++j) impl_->saved[i][j] = mjCOLLISIONFUNC[i][j];
  mjCOLLISIONFUNC[mjGEOM_MESH][mjGEOM_MESH] = &collideTrampoline;
  if (impl_->settings.boxMesh) {
    // MuJoCo orders a pair by geom type (box before mesh); both entries, in case that changes.
    mjCOLLISIONFUNC[mjGEOM_BOX][mjGEOM_MESH] = &collideTrampoline;
    mjCOLLISIONFUNC[mjGEOM_MESH][mjGEOM_BOX] = &collideTrampoline;
  }
  impl_->installed = true;
  gActive = impl_.get();
}

void Collider::uninstall() {
  if (!impl_ || !impl_->installed) return;
  for (int i = 0; i < mjNGEOMTYPES; ++i)
    for (int j = 0; j < mjNGEOMTYPES; ++j) mjCOLLISIONFUNC[i][j] = impl_->saved[i][j];
  impl_->installed = false;
  if (gActive == impl_.get()) gActive = nullptr;
}

bool Collider::installed() const noexcept { return impl_->installed; }

StepStats Collider::lastStep(const mjData* d) const {
  auto it = impl_->data.find(d);
  if (it == impl_->data.end()) return {};
  return it->second.hasLast ? it->second.last : it->second.current;
}

StepStats Collider::totals(const mjData* d) const {
  auto it = impl_->data.find(d);
  if (it == impl_->data.end()) return {};
  StepStats t = it->second.totals;  // finished steps, plus the one in progress
  accumulate(t, it->second.current);
  return t;
}

const std::string& Collider::lastError() const noexcept { return impl_->lastError; }
std::size_t Collider::bakedShapes() const noexcept { return impl_->shapes.size(); }
const ColliderSettings& Collider::settings() const noexcept { return impl_->settings; }

ModelPtr loadModel(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw Error(ErrorCode::kFileNotFound, path.string() + ": no such file");
  if (std::filesystem::is_directory(path, ec))
    throw Error(ErrorCode::kFileUnreadable, path.string() + ": is a directory, not an MJCF file");
  char message[1024] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, message, sizeof message);
  if (!m) {
    std::string text(message);
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    for (char& ch : text)
      if (ch == '\n') ch = ' ';
    throw Error(ErrorCode::kParseError, path.string() + ": MuJoCo could not load the model: " +
                                            (text.empty() ? std::string("no message") : text));
  }
  return ModelPtr(m);
}

}  // namespace clod::mujoco
