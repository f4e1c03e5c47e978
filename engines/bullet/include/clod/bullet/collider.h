#pragma once
// clod_bullet: clod's anytime narrow phase as Bullet's mesh-mesh collider (issue 19). Bullet 3.24
// as Debian packages it (libbullet-dev: single precision, btScalar = float). docs/engines.md has
// the installation, the conventions and the limits.
//
// Typical use:
//   auto body = std::make_shared<clod::CollisionBody>(clod::CollisionBody::fromBake(clod::loadBake("part.clod")));
//   clod::bullet::MeshShape shape(body);                 // a btCollisionShape; share it like any other
//   btRigidBody rb(mass, motionState, &shape, inertia);  // shape.calculateLocalInertia(mass, inertia)
//   clod::bullet::Collider collider({.model = clod::ContactModel::kCfm, .budgetTests = 256});
//   collider.install(world);      // every (MeshShape, MeshShape) and (MeshShape, btBoxShape) pair now
//   world.stepSimulation(dt);     // goes through clod, within 256 tests per substep for all of them
//   collider.uninstall();         // Bullet's own algorithms again (also done by ~Collider)
//
// Conventions. A pair (body0, body1) of Bullet's overlapping pair is clod's (A, B): clod's normal
// from B toward A is Bullet's normalOnB (btManifoldPoint::m_normalWorldOnB), clod's depth d > 0
// becomes the distance -d (< 0 in penetration). clod puts a contact point in the middle of the
// overlap; Bullet wants one point on each surface, so the point on B is point + d/2 normal and
// the point on A point - d/2 normal (their distance along the normal is -d, as Bullet computes
// it again in btPersistentManifold::refreshContactPoints). Units are the mesh's (clod has none
// of its own). Friction and restitution are Bullet's (btManifoldResult's combiners).
//
// Budget sharing (the time-critical part), per Bullet substep, i.e. per dispatch of the overlapping
// pairs (btDiscreteDynamicsWorld::internalSingleStepSimulation -> dispatchAllCollisionPairs):
// when the dispatcher reaches the first overlapping pair of the array, the collider takes every pair
// it handles out of Bullet's order and runs them as clod's world does (world.h): ranked first by how
// many substeps a pair has gone without a query (a starved pair moves to the front), then by priority
// = approach speed along its last normal + its last deepest depth / dt; walking down the list each
// pair gets share = tests left / pairs left (at least 1 while any is left), and what it does not use
// rolls over to the pairs after it. A time budget does the same with the microseconds left, as a
// deadline per query (clod::QueryBudget); the first pair is queried even when the dispatch's own
// overhead has used the time up, so the round robin always advances. Pairs reached after the budget is gone are not queried:
// their persistent manifold is refreshed (Bullet's own bookkeeping: points that opened or slid are
// dropped) and kept, and they rank first next substep. Each pair keeps a clod::CoherenceCache, so an
// interrupted query resumes next substep from the frontier it reached. The other pairs go through
// the near callback that was installed before (Bullet's default one), in Bullet's order.
//
// Manifolds. A query that finished (reached the leaves) replaces the pair's manifold: its contacts
// are added through btManifoldResult::addContactPoint, which matches each to a cached point (so
// the cached point keeps its applied impulse for warm starting, and btPersistentManifold keeps at
// most 4 points: the deepest and the largest area of the ColliderSettings::maxContacts given),
// and the cached points not matched are removed. An interrupted query's contacts are merged into
// the manifold the same way but do not remove the points it did not find (those are finer ones from
// earlier queries, which Bullet's refresh drops when they open or slide).
//
// Threads: a Collider and its world are used from one thread (Bullet's btCollisionDispatcher is
// single-threaded); several worlds with one Collider each may run on different threads.

#include <cstdint>
#include <memory>
#include <vector>

#include <BulletCollision/CollisionShapes/btConcaveShape.h>

#include "clod/collision_body.h"
#include "clod/contact.h"
#include "clod/query.h"

class btCollisionWorld;
class btBoxShape;

namespace clod::bullet {

/// A clod body (baked mesh: sphere-tree, closest feature maps, optionally a contact tree) as a
/// Bullet collision shape. Shape type CUSTOM_CONCAVE_SHAPE_TYPE (a concave shape: Bullet's own
/// convex-vs-concave algorithm collides convex shapes other than boxes with its triangles, and ray
/// tests see the triangles too). The shape's local frame is the mesh's coordinates moved by
/// `shapeFromMesh` (default: the same). A dynamic btRigidBody needs its shape's local frame to be
/// the principal frame of inertia with the origin at the centre of mass: principalFrame(mesh) is
/// that pose, so MeshShape(body, principalFrame(body->mesh())) can be simulated as it is, without
/// rebaking. Immutable after construction except for the margin.
class MeshShape : public btConcaveShape {
public:
  /// Throws clod::Error(kInvalidArgument) for a null body or a non-finite pose.
  explicit MeshShape(std::shared_ptr<const CollisionBody> body, const Pose& shapeFromMesh = Pose{});
  ~MeshShape() override;

  const CollisionBody& body() const noexcept { return *body_; }
  const std::shared_ptr<const CollisionBody>& sharedBody() const noexcept { return body_; }
  /// Mesh coordinates -> the shape's local coordinates.
  const Pose& shapeFromMesh() const noexcept { return shapeFromMesh_; }

  /// The pose taking mesh coordinates to the mesh's principal frame of inertia (solid of uniform
  /// density; the bounding box for an open mesh): origin at the centre of mass, axes the principal
  /// axes (right-handed). For a box mesh centred at the origin, the identity.
  static Pose principalFrame(const TriangleMesh& mesh);

  /// The mesh's bounding box in the shape's local coordinates (no margin).
  const btVector3& localAabbMin() const noexcept { return localMin_; }
  const btVector3& localAabbMax() const noexcept { return localMax_; }

  // btCollisionShape / btConcaveShape.
  /// The local bounding box, transformed, grown by the margin (0 unless set). O(1).
  void getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const override;
  /// Every triangle whose bounding box overlaps [aabbMin, aabbMax] (shape coordinates), part id 0,
  /// index = clod's triangle index. O(triangles): this is Bullet's fallback path (convex shapes,
  /// ray tests), not the mesh-mesh one.
  void processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin,
                           const btVector3& aabbMax) const override;
  /// Only (1, 1, 1) is accepted (a bake is in the mesh's units: scale the mesh, then bake);
  /// anything else throws clod::Error(kInvalidArgument).
  void setLocalScaling(const btVector3& scaling) override;
  const btVector3& getLocalScaling() const override { return scaling_; }
  /// Diagonal, in the shape's axes, of the mesh's inertia tensor about its centre of mass for this
  /// mass (solid of uniform density; the bounding box for an open mesh): the principal moments
  /// when shapeFromMesh is principalFrame(mesh) (see the class comment).
  void calculateLocalInertia(btScalar mass, btVector3& inertia) const override;
  const char* getName() const override { return "clod::bullet::MeshShape"; }

  /// True when `shape` is a MeshShape.
  static bool isMeshShape(const btCollisionShape* shape) noexcept;

private:
  std::shared_ptr<const CollisionBody> body_;
  Pose shapeFromMesh_;
  btVector3 localMin_, localMax_;
  btVector3 scaling_{1, 1, 1};
  btVector3 unitInertia_;  // inertia diagonal per unit mass
};

/// How the collider answers.
struct ColliderSettings {
  /// The contact model of every query (contact.h). cfm and average need closest feature maps in
  /// the bodies (a default bake has them), contact-tree a contact tree; a body without them makes
  /// stepSimulation throw clod::Error(kBakeMissingSection) naming it (queryContacts).
  ContactModel model = ContactModel::kCfm;
  /// Sphere/triangle tests per Bullet substep for all clod pairs together; 0 = unlimited.
  std::uint64_t budgetTests = 0;
  /// Narrow-phase wall-clock time per substep for all clod pairs together, microseconds; 0 = no
  /// time limit (finite, >= 0). With both set, each query gets both limits.
  double budgetMicros = 0.0;
  /// clod's manifold size per query (QuerySettings::maxContacts, >= 1). Bullet keeps at most 4,
  /// so 4 lets clod's reduction choose them (the deepest, the largest area) the same way every
  /// substep; given 8, Bullet's choice among them changed from substep to substep and a twisted
  /// stack drifted 21.5 mm in 10 s instead of 9.3 (docs/engines.md, "Manifolds").
  std::uint32_t maxContacts = 4;
  /// Also collide MeshShape with btBoxShape through clod (the box baked once per distinct size,
  /// as a 12-triangle mesh, on first contact: it allocates then). false: Bullet's
  /// convex-vs-concave algorithm against the MeshShape's triangles.
  bool collideBoxes = true;
  /// Also collide MeshShape with btStaticPlaneShape (Bullet has no algorithm for a concave shape
  /// against a plane): every mesh vertex closer to the plane than the manifold's contact
  /// breaking threshold (or below it) is a contact, normal = the plane's normal (on B = the
  /// plane), distance = the vertex's signed distance (exact: a mesh touches a plane at vertices
  /// first), reduced to maxContacts by reduceManifold (deepest first, spread in the plane;
  /// contacts within 1e-3 x the mesh's diagonal merged). Not budgeted (no tests: O(vertices) per
  /// substep, skipped when the mesh's bounding sphere is farther than the threshold).
  bool collidePlanes = true;
};

/// What the collider did in the last dispatch (substep).
struct DispatchReport {
  std::uint32_t pairs = 0;         ///< clod pairs in the dispatch
  std::uint32_t queried = 0;       ///< of those, queried
  std::uint32_t skipped = 0;       ///< not queried for lack of budget (manifold refreshed and kept)
  std::uint32_t interrupted = 0;   ///< queries that stopped before the leaves
  std::uint64_t tests = 0;         ///< tests spent (<= budgetTests when limited)
  std::uint64_t contacts = 0;      ///< contacts clod handed to Bullet (before its 4-point reduction)
  double narrowSeconds = 0.0;      ///< wall time of the clod pairs' dispatch
};

/// Installs clod as the collision algorithm of a Bullet world and shares a budget among its pairs
/// (see the top of this file). One Collider serves one world at a time.
class Collider {
public:
  /// Throws clod::Error(kInvalidArgument) naming the setting when one is out of range.
  explicit Collider(const ColliderSettings& settings = {});
  /// Uninstalls if installed: destroy the Collider (or uninstall) before the world.
  ~Collider();
  Collider(const Collider&) = delete;
  Collider& operator=(const Collider&) = delete;

  /// Registers clod's algorithm on the world's dispatcher for (MeshShape, MeshShape) and, with
  /// collideBoxes, (MeshShape, btBoxShape) both ways (btCollisionDispatcher::
  /// registerCollisionCreateFunc), with collidePlanes (MeshShape, btStaticPlaneShape) both ways
  /// (not budgeted), and its near callback for the budget; pairs that already had an
  /// algorithm between such shapes get clod's from the next dispatch on. Throws
  /// clod::Error(kInvalidArgument) when the world's dispatcher is not a btCollisionDispatcher,
  /// when this Collider or another one is already installed on it, or when the configuration's
  /// algorithm pool is too small for clod's algorithm.
  void install(btCollisionWorld& world);
  /// Restores what the world's collision configuration registers (Bullet's defaults) and the near
  /// callback that was there before, and drops clod's algorithms from the overlapping pairs (their
  /// manifolds are released; Bullet creates its own next dispatch). No-op when not installed.
  void uninstall();
  bool installed() const noexcept;

  const ColliderSettings& settings() const noexcept;
  /// Changes the settings between steps (a model change clears every pair's coherence cache).
  /// Same checks as the constructor; changing collideBoxes or collidePlanes while installed throws
  /// clod::Error(kInvalidArgument) (uninstall, change, install).
  void setSettings(const ColliderSettings& settings);

  /// The last dispatch's figures.
  const DispatchReport& lastDispatch() const noexcept;

  struct Core;

private:
  std::shared_ptr<Core> core_;
};

}  // namespace clod::bullet
