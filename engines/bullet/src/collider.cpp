// clod_bullet: the shape, the collision algorithm and the budgeted dispatch (collider.h).
#include "clod/bullet/collider.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <new>
#include <string>
#include <utility>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <BulletCollision/CollisionDispatch/btActivatingCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionConfiguration.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btCollisionWorld.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletCollision/CollisionShapes/btTriangleCallback.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <LinearMath/btAabbUtil2.h>
#include <LinearMath/btPoolAllocator.h>

#include <Eigen/Eigenvalues>

#include "clod/bake.h"
#include "clod/error.h"
#include "clod/mass_properties.h"
#include "clod/primitives.h"

namespace clod::bullet {
namespace {

btVector3 toBt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Vec3 toClod(const btVector3& v) { return Vec3(double(v.x()), double(v.y()), double(v.z())); }

Pose toPose(const btTransform& t) {
  const btQuaternion q = t.getRotation();
  Pose p;
  p.rotation = Quat(double(q.w()), double(q.x()), double(q.y()), double(q.z())).normalized();
  p.translation = toClod(t.getOrigin());
  return p;
}

void checkSettings(const ColliderSettings& s) {
  if (s.maxContacts == 0) throw Error(ErrorCode::kInvalidArgument, "ColliderSettings::maxContacts must be >= 1");
  if (!(s.budgetMicros >= 0.0) || !std::isfinite(s.budgetMicros))
    throw Error(ErrorCode::kInvalidArgument, "ColliderSettings::budgetMicros must be finite and >= 0, got " +
                                                 std::to_string(s.budgetMicros));
}

}  // namespace

// ---- MeshShape ----

MeshShape::MeshShape(std::shared_ptr<const CollisionBody> body, const Pose& shapeFromMesh)
    : body_(std::move(body)), shapeFromMesh_(shapeFromMesh) {
  if (!body_) throw Error(ErrorCode::kInvalidArgument, "clod::bullet::MeshShape: null CollisionBody");
  if (!shapeFromMesh.rotation.coeffs().allFinite() || !shapeFromMesh.translation.allFinite() ||
      std::abs(shapeFromMesh.rotation.norm() - 1.0) > 1e-6)
    throw Error(ErrorCode::kInvalidArgument, "clod::bullet::MeshShape '" + body_->name() +
                                                 "': shapeFromMesh must be finite with a unit quaternion");
  shapeFromMesh_.rotation.normalize();
  m_shapeType = CUSTOM_CONCAVE_SHAPE_TYPE;
  const TriangleMesh& mesh = body_->mesh();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const std::array<std::uint32_t, 3>& t : mesh.triangles)
    for (std::uint32_t v : t) {
      const Vec3 p = shapeFromMesh_.apply(mesh.vertices[v]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  if (mesh.triangles.empty()) lo = hi = Vec3::Zero();
  // Rounded outward to float so the box still contains every vertex.
  localMin_ = btVector3(std::nextafter(btScalar(lo.x()), -1e30f), std::nextafter(btScalar(lo.y()), -1e30f),
                        std::nextafter(btScalar(lo.z()), -1e30f));
  localMax_ = btVector3(std::nextafter(btScalar(hi.x()), 1e30f), std::nextafter(btScalar(hi.y()), 1e30f),
                        std::nextafter(btScalar(hi.z()), 1e30f));
  const MassProperties mp = computeMassPropertiesOrBoundingBox(mesh);
  const Mat3 r = shapeFromMesh_.rotation.toRotationMatrix();
  const Vec3 perMass = mp.mass > 0.0 ? Vec3((r * mp.inertia * r.transpose()).diagonal() / mp.mass) : Vec3::Zero();
  unitInertia_ = toBt(perMass);
}

Pose MeshShape::principalFrame(const TriangleMesh& mesh) {
  const MassProperties mp = computeMassPropertiesOrBoundingBox(mesh);
  Mat3 axes = Mat3::Identity();
  // A tensor already diagonal (boxes, most primitives) keeps the mesh's axes exactly.
  const Mat3& inertia = mp.inertia;
  const double offDiagonal = std::abs(inertia(0, 1)) + std::abs(inertia(0, 2)) + std::abs(inertia(1, 2));
  if (offDiagonal > 1e-12 * inertia.trace()) {
    Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
    axes = eig.eigenvectors();
    if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  }
  Pose p;
  p.rotation = Quat(Mat3(axes.transpose())).normalized();
  p.translation = -(p.rotation * mp.centerOfMass);
  return p;
}

MeshShape::~MeshShape() = default;

void MeshShape::getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const {
  btTransformAabb(localMin_, localMax_, getMargin(), t, aabbMin, aabbMax);
}

void MeshShape::processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin,
                                    const btVector3& aabbMax) const {
  const TriangleMesh& mesh = body_->mesh();
  btVector3 tri[3];
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
    for (int k = 0; k < 3; ++k) {
      tri[k] = toBt(shapeFromMesh_.apply(mesh.vertices[mesh.triangles[i][k]]));
      lo.setMin(tri[k]);
      hi.setMax(tri[k]);
    }
    if (TestAabbAgainstAabb2(lo, hi, aabbMin, aabbMax)) callback->processTriangle(tri, 0, int(i));
  }
}

void MeshShape::setLocalScaling(const btVector3& scaling) {
  if (scaling != btVector3(1, 1, 1))
    throw Error(ErrorCode::kInvalidArgument,
                "clod::bullet::MeshShape '" + body_->name() +
                    "': local scaling other than (1, 1, 1) is not supported (scale the mesh, then bake it)");
}

void MeshShape::calculateLocalInertia(btScalar mass, btVector3& inertia) const { inertia = mass * unitInertia_; }

bool MeshShape::isMeshShape(const btCollisionShape* shape) noexcept {
  return shape && shape->getShapeType() == CUSTOM_CONCAVE_SHAPE_TYPE && dynamic_cast<const MeshShape*>(shape);
}

// ---- the collider's shared state ----

class PairAlgorithm;

struct Collider::Core {
  ColliderSettings settings;
  DispatchReport report;
  btCollisionWorld* world = nullptr;
  btCollisionDispatcher* dispatcher = nullptr;
  btNearCallback previousNearCallback = nullptr;
  std::uint64_t serial = 0;         // dispatches (batches) run
  std::uint64_t modelEpoch = 0;     // bumped by a model change: pairs clear their caches
  QueryScratch scratch;
  QueryResult result;
  // The budget of the query the next processCollision makes (set by the batch; unlimited-ish
  // per-query cap outside it).
  QueryBudget nextBudget;
  bool inBatch = false;
  std::map<std::array<float, 3>, std::shared_ptr<const CollisionBody>> boxBodies;
  struct CreateFunc : btCollisionAlgorithmCreateFunc {
    Core* core = nullptr;
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                   const btCollisionObjectWrapper* w0,
                                                   const btCollisionObjectWrapper* w1) override;
  };
  CreateFunc createFunc;
  struct PlaneCreateFunc : btCollisionAlgorithmCreateFunc {
    Core* core = nullptr;
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                   const btCollisionObjectWrapper* w0,
                                                   const btCollisionObjectWrapper* w1) override;
  };
  PlaneCreateFunc planeCreateFunc;
  std::vector<Contact> planeContacts;  // the plane algorithm's scratch (one thread: the dispatcher's)
  std::vector<double> planeScratch;
  // The batch's pairs, reused (no allocation once grown).
  struct Entry {
    btBroadphasePair* pair;
    PairAlgorithm* algorithm;
  };
  std::vector<Entry> batch;
  std::weak_ptr<Core> self;

  bool handles(const btCollisionShape* s0, const btCollisionShape* s1) const {
    const bool m0 = MeshShape::isMeshShape(s0), m1 = MeshShape::isMeshShape(s1);
    if (m0 && m1) return true;
    if (!settings.collideBoxes) return false;
    return (m0 && s1->getShapeType() == BOX_SHAPE_PROXYTYPE) || (m1 && s0->getShapeType() == BOX_SHAPE_PROXYTYPE);
  }
  std::shared_ptr<const CollisionBody> bodyOf(const btCollisionShape* shape);
  /// World pose of the body's mesh coordinates for a shape placed by `t`.
  static Pose meshPose(const btCollisionShape* shape, const btTransform& t) {
    const Pose shapePose = toPose(t);
    return MeshShape::isMeshShape(shape) ? shapePose * static_cast<const MeshShape*>(shape)->shapeFromMesh() : shapePose;
  }
  void runBatch(btCollisionDispatcher& d, const btDispatcherInfo& info);
};

namespace {

// Near callback -> Core: a near callback is a plain function, so the installed colliders are
// found by their dispatcher (one entry per installed Collider, usually one).
std::mutex gRegistryMutex;
std::vector<std::pair<const btCollisionDispatcher*, Collider::Core*>> gRegistry;

Collider::Core* coreOf(const btCollisionDispatcher* d) {
  std::lock_guard<std::mutex> lock(gRegistryMutex);
  for (const auto& [dispatcher, core] : gRegistry)
    if (dispatcher == d) return core;
  return nullptr;
}

}  // namespace

// ---- the algorithm ----

// One per overlapping pair of (MeshShape, MeshShape) or (MeshShape, btBoxShape). Kept small: the
// dispatcher allocates it from the configuration's pool (checked in Collider::install); the
// per-pair state lives behind a pointer.
class PairAlgorithm : public btActivatingCollisionAlgorithm {
public:
  struct State {
    CoherenceCache cache;
    std::uint64_t modelEpoch = 0;
    std::uint32_t starved = 0;     // substeps without a query
    double priority = 0.0;         // approach speed + deepest depth / dt
    std::uint64_t doneSerial = 0;  // the batch that last handled it
    std::array<btVector3, 16> added;  // points on B handed to Bullet by the last query
  };

  PairAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* w0,
                const btCollisionObjectWrapper* w1, std::shared_ptr<Collider::Core> core)
      : btActivatingCollisionAlgorithm(ci, w0, w1), core_(std::move(core)), state_(std::make_unique<State>()) {
    state_->modelEpoch = core_->modelEpoch;
  }
  ~PairAlgorithm() override {
    if (manifold_ && ownManifold_) m_dispatcher->releaseManifold(manifold_);
  }

  State& state() { return *state_; }
  btPersistentManifold* manifold() { return manifold_; }

  void processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                        const btDispatcherInfo& info, btManifoldResult* resultOut) override;
  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return btScalar(1);  // no continuous collision: clod's world substeps instead
  }
  void getAllContactManifolds(btManifoldArray& manifoldArray) override {
    if (manifold_ && ownManifold_) manifoldArray.push_back(manifold_);
  }

private:
  std::shared_ptr<Collider::Core> core_;
  std::unique_ptr<State> state_;
  btPersistentManifold* manifold_ = nullptr;
  bool ownManifold_ = false;
};

btCollisionAlgorithm* Collider::Core::CreateFunc::CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                                           const btCollisionObjectWrapper* w0,
                                                                           const btCollisionObjectWrapper* w1) {
  if (core->handles(w0->getCollisionShape(), w1->getCollisionShape())) {
    void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(int(sizeof(PairAlgorithm)));
    return new (mem) PairAlgorithm(ci, w0, w1, core->self.lock());
  }
  // Another shape of the same type (e.g. Bullet's btSdfCollisionShape shares the custom concave
  // type): what the configuration would have used.
  btCollisionConfiguration* config = core->dispatcher->getCollisionConfiguration();
  return config->getCollisionAlgorithmCreateFunc(w0->getCollisionShape()->getShapeType(),
                                                 w1->getCollisionShape()->getShapeType())
      ->CreateCollisionAlgorithm(ci, w0, w1);
}

std::shared_ptr<const CollisionBody> Collider::Core::bodyOf(const btCollisionShape* shape) {
  if (MeshShape::isMeshShape(shape)) return static_cast<const MeshShape*>(shape)->sharedBody();
  // A box: baked once per size (its half extents include Bullet's margin: btBoxShape stores the
  // extents less the margin and adds it back here, so this is the box the user asked for).
  const btVector3 h = static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin();
  const std::array<float, 3> key = {float(h.x()), float(h.y()), float(h.z())};
  auto found = boxBodies.find(key);
  if (found == boxBodies.end()) {
    BakeSettings bs;
    bs.measureFit = false;
    bs.buildContactTree = settings.model == ContactModel::kContactTree;
    bs.sphereTree.depth = 3;  // as scene.h's default for boxes
    bs.sourceName = "btBoxShape";
    auto body = std::make_shared<CollisionBody>(CollisionBody::fromBake(bakeMesh(makeBox(toClod(h)), bs).contents));
    body->setName("btBoxShape " + std::to_string(h.x()) + " x " + std::to_string(h.y()) + " x " + std::to_string(h.z()));
    found = boxBodies.emplace(key, std::move(body)).first;
  }
  return found->second;
}

void PairAlgorithm::processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                                     const btDispatcherInfo& info, btManifoldResult* resultOut) {
  Collider::Core& core = *core_;
  if (!manifold_) {
    manifold_ = m_dispatcher->getNewManifold(w0->getCollisionObject(), w1->getCollisionObject());
    ownManifold_ = true;
  }
  resultOut->setPersistentManifold(manifold_);
  State& st = *state_;
  if (st.modelEpoch != core.modelEpoch) {
    st.cache.clear();
    st.modelEpoch = core.modelEpoch;
  }
  const std::shared_ptr<const CollisionBody> a = core.bodyOf(w0->getCollisionShape());
  const std::shared_ptr<const CollisionBody> b = core.bodyOf(w1->getCollisionShape());
  QuerySettings qs;
  qs.model = core.settings.model;
  qs.maxContacts = core.settings.maxContacts;
  if (core.inBatch) {
    qs.budget = core.nextBudget;
  } else if (core.settings.budgetTests > 0) {
    qs.budget = QueryBudget::tests(core.settings.budgetTests);  // a lone query (compound child, contactPairTest)
  }
  QueryResult& r = core.result;
  queryContacts(*a, Collider::Core::meshPose(w0->getCollisionShape(), w0->getWorldTransform()), *b,
                Collider::Core::meshPose(w1->getCollisionShape(), w1->getWorldTransform()), qs, core.scratch, r, &st.cache);
  core.report.tests += r.tests;
  if (!r.finished) ++core.report.interrupted;
  st.starved = 0;

  // Hand the contacts to Bullet (collider.h, "Conventions" and "Manifolds").
  const std::size_t n = std::min(r.contacts.size(), st.added.size());
  double deepest = 0.0;
  Vec3 deepestNormal = Vec3::UnitZ(), deepestPoint = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Contact& c = r.contacts[i];
    const Vec3 onB = c.point + 0.5 * c.depth * c.normal;
    st.added[i] = toBt(onB);
    resultOut->addContactPoint(toBt(c.normal), st.added[i], btScalar(-c.depth));
    if (i == 0 || c.depth > deepest) {
      deepest = c.depth;
      deepestNormal = c.normal;
      deepestPoint = c.point;
    }
  }
  core.report.contacts += n;
  if (r.finished) {
    // The finished answer replaces the manifold: drop the cached points it did not match (the
    // manifold was made with body0 = w0's object, so no point is swapped).
    for (int k = manifold_->getNumContacts() - 1; k >= 0; --k) {
      const btVector3& onB = manifold_->getContactPoint(k).m_positionWorldOnB;
      bool found = false;
      for (std::size_t i = 0; i < n && !found; ++i) found = st.added[i] == onB;
      if (!found) manifold_->removeContactPoint(k);
    }
  }
  if (manifold_->getNumContacts() > 0) resultOut->refreshContactPoints();

  // Priority for the next substep's ranking: approach speed along the normal + depth / dt.
  double approach = 0.0;
  if (n > 0) {
    auto velocity = [&](const btCollisionObject* o) {
      const btRigidBody* rb = btRigidBody::upcast(o);
      if (!rb) return Vec3(Vec3::Zero());
      return toClod(rb->getVelocityInLocalPoint(toBt(deepestPoint) - rb->getCenterOfMassPosition()));
    };
    approach = std::max(0.0, (velocity(w1->getCollisionObject()) - velocity(w0->getCollisionObject())).dot(deepestNormal));
  }
  const double dt = info.m_timeStep > 0 ? double(info.m_timeStep) : 1.0 / 60.0;
  st.priority = approach + std::max(0.0, deepest) / dt;
}

// ---- MeshShape against btStaticPlaneShape (collider.h, ColliderSettings::collidePlanes) ----

// Its manifold is always (mesh, plane), whatever order the dispatcher passes: the normal Bullet
// wants is then the plane's ("on B"), and btManifoldResult swaps the points when the pair came
// the other way round.
class PlaneAlgorithm : public btActivatingCollisionAlgorithm {
public:
  PlaneAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* w0,
                 const btCollisionObjectWrapper* w1, Collider::Core* core)
      : btActivatingCollisionAlgorithm(ci, w0, w1), core_(core) {}
  ~PlaneAlgorithm() override {
    if (manifold_) m_dispatcher->releaseManifold(manifold_);
  }
  void processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                        const btDispatcherInfo& info, btManifoldResult* resultOut) override;
  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return btScalar(1);
  }
  void getAllContactManifolds(btManifoldArray& manifoldArray) override {
    if (manifold_) manifoldArray.push_back(manifold_);
  }

private:
  Collider::Core* core_;  // outlives the algorithm: uninstall drops every PlaneAlgorithm first
  btPersistentManifold* manifold_ = nullptr;
  std::array<std::uint32_t, 16> used_{};  // vertices of the last answer (maxContacts is capped at 16 here)
  std::uint32_t usedCount_ = 0;
};

btCollisionAlgorithm* Collider::Core::PlaneCreateFunc::CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                                                const btCollisionObjectWrapper* w0,
                                                                                const btCollisionObjectWrapper* w1) {
  const bool m0 = MeshShape::isMeshShape(w0->getCollisionShape()), m1 = MeshShape::isMeshShape(w1->getCollisionShape());
  if (m0 != m1) {
    void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(int(sizeof(PlaneAlgorithm)));
    return new (mem) PlaneAlgorithm(ci, w0, w1, core);
  }
  btCollisionConfiguration* config = core->dispatcher->getCollisionConfiguration();
  return config->getCollisionAlgorithmCreateFunc(w0->getCollisionShape()->getShapeType(),
                                                 w1->getCollisionShape()->getShapeType())
      ->CreateCollisionAlgorithm(ci, w0, w1);
}

void PlaneAlgorithm::processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                                      const btDispatcherInfo&, btManifoldResult* resultOut) {
  const bool meshFirst = MeshShape::isMeshShape(w0->getCollisionShape());
  const btCollisionObjectWrapper* meshW = meshFirst ? w0 : w1;
  const btCollisionObjectWrapper* planeW = meshFirst ? w1 : w0;
  if (!manifold_) manifold_ = m_dispatcher->getNewManifold(meshW->getCollisionObject(), planeW->getCollisionObject());
  resultOut->setPersistentManifold(manifold_);
  const auto* mesh = static_cast<const MeshShape*>(meshW->getCollisionShape());
  const auto* plane = static_cast<const btStaticPlaneShape*>(planeW->getCollisionShape());
  // The plane n . x = d in the world (its local normal and constant, turned and moved).
  const Pose planePose = toPose(planeW->getWorldTransform());
  const Vec3 n = (planePose.rotation * toClod(plane->getPlaneNormal())).normalized();
  const double d = double(plane->getPlaneConstant()) + n.dot(planePose.translation);
  const Pose meshPose = Collider::Core::meshPose(mesh, meshW->getWorldTransform());
  const TriangleMesh& vertices = mesh->body().mesh();
  const double threshold = double(manifold_->getContactBreakingThreshold());
  const Aabb box = vertices.bounds();
  const double reach = 0.5 * (box.max - box.min).norm();
  std::vector<Contact>& contacts = core_->planeContacts;
  contacts.clear();
  // Selection depths are rounded down to steps of 1e-4 x the mesh's diagonal and the vertices
  // used last substep go first, so that a flat ring of vertices at one height (a torus lying on
  // the plane) keeps its contacts from substep to substep: reduceManifold breaks ties by input
  // order, and points that jump around the ring make Bullet's warm-started friction impulses act
  // at the wrong places (measured: a torus spun up to 3 rad/s in 2 s). Contact::level carries
  // the vertex index through the reduction; the true depth goes to Bullet.
  // Candidates lie within a band of 0.5 % of the diagonal above the lowest vertex (and below the
  // threshold): reduceManifold spreads its picks after the deepest one whatever their depth, and
  // points well above the plane (a torus's next ring of vertices) would stand in for the ones
  // it rests on.
  const double step = 1e-4 * mesh->body().diagonal();
  double lowest = std::numeric_limits<double>::infinity();
  const bool near = n.dot(meshPose.apply(0.5 * (box.min + box.max))) - d <= reach + threshold;
  if (near)
    for (const Vec3& v : vertices.vertices) lowest = std::min(lowest, n.dot(meshPose.apply(v)) - d);
  const double cutoff = std::min(threshold, lowest + 5e-3 * mesh->body().diagonal());
  auto candidate = [&](std::uint32_t v) {
    const Vec3 p = meshPose.apply(vertices.vertices[v]);
    const double distance = n.dot(p) - d;
    if (distance >= cutoff) return;
    Contact c;
    c.point = p - 0.5 * distance * n;  // midway between the vertex and the plane
    c.normal = n;                       // from the plane (B) toward the mesh (A)
    c.depth = std::floor(-distance / step) * step;
    c.level = v;
    contacts.push_back(c);
  };
  if (near) {
    for (std::uint32_t i = 0; i < usedCount_; ++i) candidate(used_[i]);
    for (std::uint32_t v = 0; v < vertices.vertexCount(); ++v)
      if (std::find(used_.begin(), used_.begin() + usedCount_, v) == used_.begin() + usedCount_) candidate(v);
  }
  ManifoldSettings ms;
  ms.maxContacts = std::min<std::uint32_t>(core_->settings.maxContacts, std::uint32_t(used_.size()));
  ms.mergeDistanceAbs = 1e-3 * mesh->body().diagonal();
  const std::size_t kept = contacts.empty() ? 0 : reduceManifold(contacts, ms, core_->planeScratch);
  usedCount_ = std::uint32_t(kept);
  std::array<btVector3, 16> added;
  for (std::size_t i = 0; i < kept; ++i) {
    const std::uint32_t v = contacts[i].level;
    used_[i] = v;
    const Vec3 p = meshPose.apply(vertices.vertices[v]);
    const double distance = n.dot(p) - d;
    added[i] = toBt(p - distance * n);  // on the plane
    resultOut->addContactPoint(toBt(n), added[i], btScalar(distance));
  }
  // This answer is complete: drop the cached points it did not give again.
  for (int k = manifold_->getNumContacts() - 1; k >= 0; --k) {
    const btVector3& onB = manifold_->getContactPoint(k).m_positionWorldOnB;
    if (std::find(added.begin(), added.begin() + kept, onB) == added.begin() + kept) manifold_->removeContactPoint(k);
  }
  if (manifold_->getNumContacts() > 0) resultOut->refreshContactPoints();
}

// ---- the budgeted dispatch ----

namespace {

void nearCallback(btBroadphasePair& pair, btCollisionDispatcher& d, const btDispatcherInfo& info) {
  Collider::Core* core = coreOf(&d);
  if (!core) {
    btCollisionDispatcher::defaultNearCallback(pair, d, info);
    return;
  }
  btOverlappingPairCache* cache = core->world->getPairCache();
  const bool first = cache->getNumOverlappingPairs() > 0 && &pair == &cache->getOverlappingPairArray()[0];
  const auto* o0 = static_cast<const btCollisionObject*>(pair.m_pProxy0->m_clientObject);
  const auto* o1 = static_cast<const btCollisionObject*>(pair.m_pProxy1->m_clientObject);
  const bool ours = core->handles(o0->getCollisionShape(), o1->getCollisionShape()) &&
                    d.needsCollision(o0, o1);
  auto* algorithm = ours ? dynamic_cast<PairAlgorithm*>(pair.m_algorithm) : nullptr;
  // The batch runs once per dispatch, when the dispatcher reaches the array's first pair (or,
  // with m_deterministicOverlappingPairs, which visits in another order, a clod pair not yet done).
  if (first || (ours && (!algorithm || algorithm->state().doneSerial != core->serial))) core->runBatch(d, info);
  if (ours) return;  // handled by the batch
  core->previousNearCallback(pair, d, info);  // also skips the handled pairs needsCollision refuses
}

}  // namespace

void Collider::Core::runBatch(btCollisionDispatcher& d, const btDispatcherInfo& info) {
  using Clock = QueryBudget::Clock;
  const auto t0 = Clock::now();
  ++serial;
  report = DispatchReport{};
  batch.clear();
  btBroadphasePairArray& pairs = world->getPairCache()->getOverlappingPairArray();
  for (int i = 0; i < pairs.size(); ++i) {
    btBroadphasePair& pair = pairs[i];
    auto* o0 = static_cast<btCollisionObject*>(pair.m_pProxy0->m_clientObject);
    auto* o1 = static_cast<btCollisionObject*>(pair.m_pProxy1->m_clientObject);
    if (!handles(o0->getCollisionShape(), o1->getCollisionShape()) || !d.needsCollision(o0, o1)) continue;
    if (!pair.m_algorithm) {
      btCollisionObjectWrapper w0(nullptr, o0->getCollisionShape(), o0, o0->getWorldTransform(), -1, -1);
      btCollisionObjectWrapper w1(nullptr, o1->getCollisionShape(), o1, o1->getWorldTransform(), -1, -1);
      pair.m_algorithm = d.findAlgorithm(&w0, &w1, nullptr, BT_CONTACT_POINT_ALGORITHMS);
    }
    auto* algorithm = dynamic_cast<PairAlgorithm*>(pair.m_algorithm);
    if (!algorithm) continue;
    algorithm->state().doneSerial = serial;
    batch.push_back({&pair, algorithm});
  }
  // clod's world's order: starved pairs first, then by priority; ties by the bodies' indices in
  // the world (deterministic).
  std::sort(batch.begin(), batch.end(), [](const Entry& x, const Entry& y) {
    const PairAlgorithm::State &sx = x.algorithm->state(), &sy = y.algorithm->state();
    if (sx.starved != sy.starved) return sx.starved > sy.starved;
    if (sx.priority != sy.priority) return sx.priority > sy.priority;
    auto key = [](const Entry& e) {
      const auto* a = static_cast<const btCollisionObject*>(e.pair->m_pProxy0->m_clientObject);
      const auto* b = static_cast<const btCollisionObject*>(e.pair->m_pProxy1->m_clientObject);
      return std::make_pair(a->getWorldArrayIndex(), b->getWorldArrayIndex());
    };
    return key(x) < key(y);
  });
  report.pairs = std::uint32_t(batch.size());
  const bool limitTests = settings.budgetTests > 0, limitTime = settings.budgetMicros > 0.0;
  const auto end = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::micro>(settings.budgetMicros));
  inBatch = true;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const Entry& e = batch[i];
    auto* o0 = static_cast<btCollisionObject*>(e.pair->m_pProxy0->m_clientObject);
    auto* o1 = static_cast<btCollisionObject*>(e.pair->m_pProxy1->m_clientObject);
    const std::uint64_t pairsLeft = batch.size() - i;
    QueryBudget budget;
    bool skip = false;
    if (limitTests) {
      const std::uint64_t left = settings.budgetTests - std::min(settings.budgetTests, report.tests);
      skip = left == 0;
      budget.maxTests = std::max<std::uint64_t>(1, left / pairsLeft);
    }
    if (limitTime && !skip) {
      // The first pair (the most starved) is always queried, so a budget the dispatch's own
      // overhead uses up still makes progress round robin.
      const auto now = Clock::now();
      skip = i > 0 && now >= end;
      budget.deadline = now + (end - now) / std::int64_t(pairsLeft);
    }
    if (skip) {
      // Keep the last contacts, refreshed by Bullet's rules (collider.h); ranked first next time.
      ++report.skipped;
      ++e.algorithm->state().starved;
      if (btPersistentManifold* m = e.algorithm->manifold(); m && m->getNumContacts() > 0)
        m->refreshContactPoints(m->getBody0()->getWorldTransform(), m->getBody1()->getWorldTransform());
      continue;
    }
    nextBudget = budget;
    btCollisionObjectWrapper w0(nullptr, o0->getCollisionShape(), o0, o0->getWorldTransform(), -1, -1);
    btCollisionObjectWrapper w1(nullptr, o1->getCollisionShape(), o1, o1->getWorldTransform(), -1, -1);
    btManifoldResult manifoldResult(&w0, &w1);
    try {
      e.algorithm->processCollision(&w0, &w1, info, &manifoldResult);
    } catch (...) {
      inBatch = false;
      throw;
    }
    ++report.queried;
  }
  inBatch = false;
  report.narrowSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---- Collider ----

Collider::Collider(const ColliderSettings& settings) : core_(std::make_shared<Core>()) {
  checkSettings(settings);
  core_->settings = settings;
  core_->createFunc.core = core_.get();
  core_->planeCreateFunc.core = core_.get();
  core_->self = core_;
}

Collider::~Collider() { uninstall(); }

bool Collider::installed() const noexcept { return core_->world != nullptr; }
const ColliderSettings& Collider::settings() const noexcept { return core_->settings; }
const DispatchReport& Collider::lastDispatch() const noexcept { return core_->report; }

void Collider::setSettings(const ColliderSettings& settings) {
  checkSettings(settings);
  if (core_->world && (settings.collideBoxes != core_->settings.collideBoxes ||
                       settings.collidePlanes != core_->settings.collidePlanes))
    throw Error(ErrorCode::kInvalidArgument, "clod::bullet::Collider::setSettings: collideBoxes / collidePlanes change what "
                                             "install registered; uninstall first");
  if (settings.model != core_->settings.model) {
    ++core_->modelEpoch;
    if (settings.model == ContactModel::kContactTree) core_->boxBodies.clear();  // rebaked with contact trees
  }
  core_->settings = settings;
}

namespace {

// Drops the algorithms of pairs whose shapes match `which` (their manifolds are released); Bullet
// makes a new one for each at the next dispatch.
template <class Pred>
void cleanPairs(btCollisionWorld& world, btDispatcher* d, Pred which) {
  btOverlappingPairCache* cache = world.getPairCache();
  btBroadphasePairArray& pairs = cache->getOverlappingPairArray();
  for (int i = 0; i < pairs.size(); ++i)
    if (pairs[i].m_algorithm && which(pairs[i])) cache->cleanOverlappingPair(pairs[i], d);
}

constexpr int kBoxType = BOX_SHAPE_PROXYTYPE, kMeshType = CUSTOM_CONCAVE_SHAPE_TYPE, kPlaneType = STATIC_PLANE_PROXYTYPE;

bool isMeshAndPlane(const btBroadphasePair& p) {
  const btCollisionShape* s0 = static_cast<const btCollisionObject*>(p.m_pProxy0->m_clientObject)->getCollisionShape();
  const btCollisionShape* s1 = static_cast<const btCollisionObject*>(p.m_pProxy1->m_clientObject)->getCollisionShape();
  return (MeshShape::isMeshShape(s0) && s1->getShapeType() == kPlaneType) ||
         (MeshShape::isMeshShape(s1) && s0->getShapeType() == kPlaneType);
}

}  // namespace

void Collider::install(btCollisionWorld& world) {
  if (core_->world) throw Error(ErrorCode::kInvalidArgument, "clod::bullet::Collider::install: already installed");
  auto* d = dynamic_cast<btCollisionDispatcher*>(world.getDispatcher());
  if (!d) throw Error(ErrorCode::kInvalidArgument, "clod::bullet::Collider::install: the world's dispatcher is not a btCollisionDispatcher");
  if (coreOf(d)) throw Error(ErrorCode::kInvalidArgument, "clod::bullet::Collider::install: another Collider is installed on this dispatcher");
  btPoolAllocator* pool = d->getCollisionConfiguration()->getCollisionAlgorithmPool();
  if (pool && pool->getElementSize() < int(sizeof(PairAlgorithm)))
    throw Error(ErrorCode::kInvalidArgument,
                "clod::bullet::Collider::install: the collision configuration's algorithm pool elements (" +
                    std::to_string(pool->getElementSize()) + " bytes) are smaller than clod's algorithm (" +
                    std::to_string(sizeof(PairAlgorithm)) + " bytes)");
  core_->world = &world;
  core_->dispatcher = d;
  core_->previousNearCallback = d->getNearCallback();
  {
    std::lock_guard<std::mutex> lock(gRegistryMutex);
    gRegistry.emplace_back(d, core_.get());
  }
  d->registerCollisionCreateFunc(kMeshType, kMeshType, &core_->createFunc);
  if (core_->settings.collideBoxes) {
    d->registerCollisionCreateFunc(kMeshType, kBoxType, &core_->createFunc);
    d->registerCollisionCreateFunc(kBoxType, kMeshType, &core_->createFunc);
  }
  if (core_->settings.collidePlanes) {
    d->registerCollisionCreateFunc(kMeshType, kPlaneType, &core_->planeCreateFunc);
    d->registerCollisionCreateFunc(kPlaneType, kMeshType, &core_->planeCreateFunc);
  }
  d->setNearCallback(&nearCallback);
  Core& core = *core_;
  cleanPairs(world, d, [&](const btBroadphasePair& p) {
    if (core.settings.collidePlanes && isMeshAndPlane(p)) return true;
    return core.handles(static_cast<const btCollisionObject*>(p.m_pProxy0->m_clientObject)->getCollisionShape(),
                        static_cast<const btCollisionObject*>(p.m_pProxy1->m_clientObject)->getCollisionShape());
  });
}

void Collider::uninstall() {
  Core& core = *core_;
  if (!core.world) return;
  btCollisionDispatcher* d = core.dispatcher;
  btCollisionConfiguration* config = d->getCollisionConfiguration();
  for (auto [t0, t1] : {std::pair{kMeshType, kMeshType}, std::pair{kMeshType, kBoxType}, std::pair{kBoxType, kMeshType},
                        std::pair{kMeshType, kPlaneType}, std::pair{kPlaneType, kMeshType}})
    d->registerCollisionCreateFunc(t0, t1, config->getCollisionAlgorithmCreateFunc(t0, t1));
  d->setNearCallback(core.previousNearCallback);
  cleanPairs(*core.world, d, [](const btBroadphasePair& p) {
    return dynamic_cast<PairAlgorithm*>(p.m_algorithm) != nullptr || dynamic_cast<PlaneAlgorithm*>(p.m_algorithm) != nullptr;
  });
  {
    std::lock_guard<std::mutex> lock(gRegistryMutex);
    std::erase_if(gRegistry, [&](const auto& e) { return e.second == &core; });
  }
  core.world = nullptr;
  core.dispatcher = nullptr;
}

}  // namespace clod::bullet
