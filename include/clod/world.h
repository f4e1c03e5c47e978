#pragma once
// The rigid-body world: impulse-based dynamics (Mirtich & Canny 1995; Mirtich 1996) solved as
// sequential impulses with accumulated clamping and warm starting (Catto, "Iterative dynamics
// with temporal coherence", GDC 2005), with a per-frame collision budget that the world divides
// among the colliding pairs. docs/dynamics.md explains the choices and their reasons.
//
// One step (World::step) of length dt:
//   1. substeps: n = ceil(max speed * dt / (kTravelFraction * smallest body extent)), at most
//      WorldSettings::maxSubsteps, so no body moves more than a fraction of the thinnest body's
//      size per substep (anti-tunnelling by substepping; the narrow phase then sees overlap); the
//      max is over bodies whose box grown by their travel over dt overlaps another body's grown
//      box (a body that cannot meet anything this step needs no substeps, however fast);
//   2. per substep: gravity; broad phase (sweep and prune over world boxes of the root spheres);
//      budget division among the candidate pairs (below); narrow phase (queryContacts) per pair;
//      velocity solve (normal + 2 friction directions per contact, accumulated impulses clamped,
//      friction to the Coulomb cone,
//      warm started from the previous substep's contacts of the same pair, matched one-to-one by
//      proximity and normal; pairs solved in a fixed order of body ids). Contacts persist: each is
//      anchored in both bodies, a matched one keeps its anchors while they have not slid or opened
//      by more than 1 % of the smaller diagonal, and every point's separation is measured from its
//      anchors each substep (per-point depth; open points are speculative: the solve lets them
//      approach by separation / h);
//      then one shock-propagation sweep up the bodies' support layers (contact-graph distance to
//      an immovable body), each layer's pairs solved with the lower body held fixed, so a heavy
//      body cannot push a light one under it into the ground (docs/dynamics.md, "Mass ratios");
//      restitution only above WorldSettings::restitutionThreshold; penetration removed by a
//      separate pseudo-velocity solve (split impulses) that moves positions but never enters the
//      velocities, so correction adds no kinetic energy; integration (semi-implicit Euler for
//      positions along pressing contacts' normals and in free flight, the trapezoid rule along
//      the other directions of a pressed body; angular momentum kept exactly through rotation,
//      see docs/dynamics.md).
//
// Budget division (the time-critical part): WorldSettings::budgetTests is per step (frame). A
// substep may spend ceil(tests the step has left / substeps left), but never run ahead of the
// even schedule ceil(budgetTests (i + 1) / n) by the end of substep i of n, so substeps that
// outnumber the tests get evenly spaced queries. Within a substep the
// candidate pairs are ranked first by how many substeps they have gone without a query (round
// robin: a starved pair moves to the front), then by priority = approach speed along last contact
// normal + last deepest depth / dt. Walking down the list, each pair gets share = remaining /
// pairs left (at least 1 test while any is left), and what a pair does not use rolls over to the
// pairs after it. When the budget is gone, the remaining pairs are not queried: they keep their
// last contacts (graceful fallback) and are reported as skipped. Each pair keeps a
// CoherenceCache, so an interrupted pair resumes from the level it reached next time. Hence a
// step makes at most budgetTests tests. The contact tree, cfm and exact also do work per pair of
// the answer frontier, tested or not (sampling, map lookups); that is charged too
// (WorldSettings::frontierPairCost per frontier pair), and a query is given only as many tests as
// keep its frontier -- at most max(cached front, tests) pairs -- within what it may spend: a pair
// whose cached front costs more than the substep has left waits for the next substep (it is then
// ranked first), and one whose front costs more than a substep's even share restarts from the
// roots. A sphere-model pair (dos, average) whose query the budget interrupted answers along the
// supporting body's box-outward direction (the immovable or the heavier body) instead of the
// spheres' normals (docs/dynamics.md, "Sphere models' interrupted contacts"); finished queries
// keep their model's normals.
//
// Energy: the velocity solve is checked -- if the warm-started solve ends with more kinetic energy
// than it started with, it is redone from zero impulses -- and the restitution impulses are scaled
// so that they return at most e^2 of the energy the compression phase removed (energetic
// restitution, Stronge 1990). So contacts never add kinetic energy, at any iteration count.
//
// Determinism: everything runs on one thread in a fixed order; the same scene and settings give
// bit-identical states on the same build.

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "clod/broadphase.h"
#include "clod/budget.h"
#include "clod/contact.h"
#include "clod/rigid_body.h"
#include "clod/separation.h"

namespace clod {

/// Body index in the order of World::addBody. Id policy: ids are handed out 0, 1, 2, ... and never
/// reused. World::removeBody retires an id for good: the other bodies keep theirs, and a retired id
/// is rejected by every call that takes an id (clod::Error kInvalidArgument, "body 3 was removed").
/// bodyCount() counts every id handed out, removed ones included (World::contains tells them apart).
using BodyId = std::uint32_t;

/// Which bodies may collide (the category / mask rule of Box2D's b2Filter). Bodies a and b are
/// paired only when (a.group & b.mask) != 0 and (b.group & a.mask) != 0; a pair filtered out is
/// dropped after the broad phase, before the narrow phase, so it costs no budget. Default: group 1,
/// mask all ones -- everything collides. group 0 (or mask 0) collides with nothing.
struct CollisionFilter {
  std::uint32_t group = 1;            ///< the bits this body is
  std::uint32_t mask = 0xffffffffu;   ///< the bits of the bodies it collides with
};

/// What the contact callback (World::setContactCallback) sees of one pair in one substep.
struct ContactPairEvent {
  BodyId a = 0, b = 0;                ///< a < b; the contacts' normals point from b toward a
  /// The contacts the solver is about to use (world frame, contact.h): the narrow phase's answer of
  /// this substep as the persistent manifold kept it (docs/dynamics.md: a finer earlier manifold
  /// may stand, earlier points may be carried), or the pair's manifold when the budget skipped it
  /// or manifold reuse spared it the query (PairReport::skipped / reused). The solver's holds at
  /// the bodies' hull boxes (docs/dynamics.md, "Pairs the budget has not reached") are not listed.
  std::span<const Contact> contacts;
  std::uint32_t substep = 0;          ///< 0-based substep of the current World::step
};

/// The contact callback: return false to disable the pair for the rest of this step (its contacts
/// are dropped before the solver, and it is not queried again until the next step, where it starts
/// afresh: no warm start, no kept manifold). Runs on the stepping thread, inside World::step;
/// it must not call World functions that edit the world (add/remove bodies, set state, forces).
using ContactCallback = std::function<bool(const ContactPairEvent& event)>;

/// A copy of `shape` scaled uniformly by `scale` (> 0, finite; else clod::Error kInvalidArgument)
/// about its mesh origin, without baking again: mesh vertices, sphere-tree centres and radii,
/// the contact tree's field values, cell geometry, error bounds and half-space offsets scale by
/// `scale` (distances scale linearly); closest feature maps, normals and the tree's relative error
/// codes are invariant under a uniform scale and are copied unchanged. Float-stored field values
/// are rounded again after the multiplication (relative 6e-8). O(size of the shape).
std::shared_ptr<const CollisionBody> scaleCollisionBody(const CollisionBody& shape, double scale);

struct WorldSettings {
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  ///< may be zero
  ContactModel model = ContactModel::kCfm;
  /// Sphere/triangle tests per step (per World::step, i.e. per frame) for all pairs and all
  /// substeps together; 0 = unlimited. A step never spends more. Each substep gets an equal
  /// share of what the step has left (rounded up), never ahead of an even spread over the
  /// step's substeps; what it does not spend rolls over.
  std::uint64_t budgetTests = 0;
  /// Narrow-phase wall-clock time per step in microseconds, for all pairs and substeps together;
  /// 0 = no time limit (finite, >= 0). Each step converts it to budget units at the narrow
  /// phase's measured time per unit (an exponential average over the previous time-budgeted
  /// steps, StepReport::testsBudget shows the result) and divides those like budgetTests (with
  /// both set, the smaller applies). As a backstop each substep also has an equal share of the
  /// time the step has left: pairs reached after it is gone keep their contacts (skipped, ranked
  /// first next substep), so a step's narrow phase ends within budgetMicros plus the one query
  /// running when it ran out (a query bounded by its test share). Per-query deadlines were
  /// tried first and lost bodies in the 200-body bin: each query's fixed cost is a large part of
  /// a share of a few microseconds, so the pairs late in the order starved (docs/dynamics.md).
  /// Runs with a time budget are not repeatable bit for bit (the division follows measured time).
  double budgetMicros = 0.0;
  /// The clock budgetMicros is measured with (also passed to the queries); replaceable so tests
  /// can count reads instead of timing. Must be non-null.
  QueryBudget::TimePoint (*clock)() = &QueryBudget::Clock::now;
  /// Budget units charged per pair of the answer frontier a query turns into contacts (0..1024),
  /// for the models that do real work per frontier pair besides the tests: the contact tree
  /// samples each cell pair, cfm looks up both closest feature maps and runs a separating-axis
  /// test per sphere pair, exact does that for the pairs an interrupted query did not
  /// triangle-test. Tested this query or kept from the pair's CoherenceCache, every frontier pair
  /// is answered, so without this charge the frame cost grows with the frontier and the substep
  /// count, not with the budget (docs/dynamics.md, "Collision budget per frame", has the
  /// measurement). The budget then counts tests + frontierPairCost x frontier pairs
  /// (StepReport::budgetSpent). 0 = only tests count (the behaviour before). dos and average
  /// (a D&O point per pair: a few flops) are not charged.
  std::uint32_t frontierPairCost = 2;
  /// Manifold size per pair (QuerySettings::maxContacts), >= 1.
  std::uint32_t maxContacts = 8;
  /// Velocity iterations of the sequential-impulse solver per substep (>= 1; see
  /// minSubstepIterations for steps with extra substeps); position iterations likewise.
  std::uint32_t velocityIterations = 20;
  std::uint32_t positionIterations = 4;
  /// Stop iterating early when no impulse changed by more than this (relative to the largest
  /// accumulated impulse); 0 = always run every iteration.
  double convergenceRel = 1e-9;
  /// Normal approach speeds below this get no restitution (m/s), so resting contact stays at rest.
  double restitutionThreshold = 0.5;
  /// Rolling resistance, relative to the smaller body's bounding-box diagonal: the two bodies'
  /// relative turn about axes in their contact plane is resisted by an angular impulse of at most
  /// this length times the pair's normal impulse -- the moment of a contact's pressure shifted
  /// that far ahead of the rolling direction, as real (deforming) bodies shift it. A rigid curved
  /// body rolling without slip loses no energy, so without it a bunny landed on its round back
  /// rocked for 5 s and more with every model (docs/dynamics.md, "Rolling resistance", says why
  /// 0.3 %); a body rolls beyond tan(slope) = this x diagonal / lever. 0 = none; >= 0, finite.
  /// A pair with a ball (RigidBodyDesc::ballRadius) has none: a rigid ball rolls for ever.
  double rollingResistanceRel = 0.003;
  /// Split-impulse penetration correction: fraction of (depth - slop) removed per substep
  /// (Baumgarte-like factor, in (0, 1]) and the allowed penetration, relative to the smaller
  /// body's bounding-box diagonal.
  double correctionFactor = 0.2;
  double slopRel = 0.002;
  /// Manifold reuse: a pair whose last query finished (QueryResult::finished) keeps its manifold
  /// without a new query while its two bodies have moved against each other, since that query,
  /// by less than this fraction of the smaller body's diagonal (translation plus rotation angle
  /// x diagonal); its contacts follow the bodies through their anchors. 0 queries every pair in
  /// every substep (docs/dynamics.md, "Manifold reuse").
  double reuseMotionRel = 0.001;
  /// Memory limits (README, "Limits on hostile input"). A step whose broad phase finds more
  /// overlapping body pairs than maxPairs throws Error(kResourceLimit) before it allocates their
  /// state (n bodies piled at one point make n(n-1)/2 pairs: 10,000 ended in std::bad_alloc).
  std::uint64_t maxPairs = std::uint64_t{1} << 20;
  /// The pairs' coherence caches (each query's front, carried to the next) hold at most this
  /// many node pairs together (16 bytes each): a pair keeps its cache while it holds at most
  /// an even share, maxCachedNodePairs / pairs; a larger one is dropped and the pair's next
  /// query starts from the roots. Coincident meshes keep thousands of leaf pairs per pair.
  std::uint64_t maxCachedNodePairs = std::uint64_t{1} << 23;
  /// Narrow-phase level cap for every pair (QuerySettings::maxLevel); default: no cap.
  std::uint32_t maxLevel = UINT32_MAX;
  /// At most this many substeps per step (>= 1).
  std::uint32_t maxSubsteps = 128;
  /// Velocity iterations per substep when a step needs more than minSubsteps substeps (fast
  /// bodies): the step's velocityIterations x minSubsteps iterations are spread over its n
  /// substeps, ceil(velocityIterations x minSubsteps / n) each but at least this many (and at
  /// most velocityIterations). Smaller steps converge better than more iterations at equal cost
  /// (Macklin et al., SCA 2019, see minSubsteps), and it keeps a fast-moving frame's solver cost
  /// near a resting frame's instead of n times it (docs/dynamics.md). The pairs of an impact (a
  /// contact approaching by more than the slop within the substep) get the rest of
  /// velocityIterations in sweeps over them alone (docs/dynamics.md, "One step"). 0 =
  /// velocityIterations in every substep (the behaviour before).
  std::uint32_t minSubstepIterations = 4;
  /// At least this many substeps per step, in [1, maxSubsteps]. A stack gets more on its own: a
  /// substep per body of its tallest support chain, up to 8, each with velocityIterations --
  /// projected Gauss-Seidel passes support down a stack of n bodies only about one body per
  /// iteration, and smaller steps converge far better than more iterations at equal cost
  /// (Macklin et al., "Small steps in physics simulation", SCA 2019; docs/dynamics.md, "One
  /// step"). Each substep queries the narrow phase again, so collision cost grows with it (the
  /// budget stays per step).
  std::uint32_t minSubsteps = 1;
  /// Bodies whose centre of mass leaves this box are reported in StepReport::leftBounds
  /// (once, when they leave) and then frozen (made static) so they cannot run off to infinity.
  Aabb bounds = Aabb{Vec3::Constant(-1e3), Vec3::Constant(1e3)};
};

/// Per-pair part of a step's report (last substep's query of the pair).
struct PairReport {
  BodyId a = 0, b = 0;
  std::uint64_t tests = 0;     ///< tests spent on this pair in this step (all substeps)
  std::uint32_t level = 0;     ///< deepest level reached (QueryResult::maxLevel), last query
  bool finished = false;       ///< the last query reached the leaves
  bool skipped = false;        ///< budget gone before its turn in the last substep: old contacts used
  /// Not queried in the last substep: its last query finished and the two bodies have since moved
  /// against each other by less than WorldSettings::reuseMotionRel, so its manifold stands
  /// (docs/dynamics.md, "Manifold reuse").
  bool reused = false;
  /// Not queried in the last substep: its last query proved the surfaces apart by a gap
  /// (QueryResult::separation) that the bodies have not moved against each other since.
  bool provenApart = false;
  /// Frontier pairs of the last query answered by the cfm (or dos) fallback: exact's pairs left
  /// without triangle tests (QueryResult::fallbackPairs), and the contact tree's pairs answered
  /// past a time budget's substep time (docs/dynamics.md); 0 at an unlimited budget.
  std::uint64_t fallbackPairs = 0;
  /// The last query was interrupted and its answer coarser than the pair's manifold, which still
  /// held, so the finer manifold was kept (a finished answer always replaces it;
  /// docs/dynamics.md, "Graceful degradation").
  bool keptFiner = false;
  std::uint32_t contacts = 0;  ///< contacts the solver used in the last substep (not its holds, docs/dynamics.md)
};

/// What one World::step did.
struct StepReport {
  std::uint32_t substeps = 0;
  std::uint64_t candidatePairs = 0;  ///< broad-phase pairs, summed over substeps
  std::uint64_t testsSpent = 0;      ///< narrow-phase tests, all pairs and substeps
  /// WorldSettings::budgetTests, or what budgetMicros converted to (the smaller when both are
  /// set; 0 = unlimited); budgetSpent <= it.
  std::uint64_t testsBudget = 0;
  /// What the budget counted: testsSpent + WorldSettings::frontierPairCost x the frontier pairs of
  /// the charged models' queries (= testsSpent for dos and average); <= testsBudget when limited.
  std::uint64_t budgetSpent = 0;
  /// The same count for all the work the queries did, charged or not: >= budgetSpent when a
  /// query got more than its substep had left (the roots' answer to a pair that may be arriving,
  /// under a time budget, or to any pair when not even that was left). A time budget converts to
  /// units at timeSpentMicros / unitsWorked (exponential average over the steps).
  std::uint64_t unitsWorked = 0;
  double timeBudgetMicros = 0.0;     ///< WorldSettings::budgetMicros (0 = no time limit)
  /// Narrow-phase time the time budget counted (WorldSettings::clock, µs, all substeps); 0 when
  /// there is no time limit.
  double timeSpentMicros = 0.0;
  std::uint64_t pairsSkipped = 0;    ///< pair queries skipped for lack of budget, summed
  std::uint64_t pairsReused = 0;     ///< pair queries saved by manifold reuse (PairReport::reused), summed
  std::uint64_t pairsProvenApart = 0;  ///< pair queries saved by a proven gap (PairReport::provenApart), summed
  std::uint64_t pairsInterrupted = 0;///< queries that stopped before the leaves, summed
  /// Frontier pairs answered by the cfm / dos fallback, summed over pairs and substeps
  /// (PairReport::fallbackPairs): exact's and the contact tree's past a time budget; 0 for the
  /// other models and at an unlimited budget.
  std::uint64_t fallbackPairs = 0;
  std::uint32_t solverIterations = 0;///< velocity iterations used, summed over substeps
  /// Substeps whose warm-started velocity solve gained kinetic energy and was redone from zero
  /// impulses (see world.h top; a sign of an unconverged solve).
  std::uint32_t coldRestarts = 0;
  double narrowPhaseSeconds = 0.0;
  double solverSeconds = 0.0;
  /// Where the rest of the step's time went (wall seconds, summed over substeps): broad phase
  /// (boxes, sweep and prune, pair bookkeeping and the budget's sort), constraint preparation
  /// (persistent-contact matching, effective masses), integration with the bounds check.
  double broadPhaseSeconds = 0.0;
  double prepareSeconds = 0.0;
  double integrateSeconds = 0.0;
  /// Work the test budget does not count, summed over substeps: frontier pairs the queries
  /// answered from (QueryResult::frontier), raw contacts before the manifold reduction
  /// (QueryResult::rawContacts), and contacts in the velocity solve.
  std::uint64_t frontierPairs = 0;
  std::uint64_t rawContacts = 0;
  std::uint64_t solverContacts = 0;
  std::vector<PairReport> pairs;     ///< pairs with contacts or queries this step, sorted (a, b)
  std::vector<BodyId> leftBounds;    ///< bodies that left WorldSettings::bounds in this step
  std::vector<Contact> contacts;     ///< last substep's contacts (world frame; not its holds) ...
  std::vector<std::array<BodyId, 2>> contactBodies;  ///< ... and the pair (a, b) of each
  /// ... and the two points of each that the solver holds apart, anchored in the bodies (world
  /// frame): [0] on A, [1] on B. A contact's separation is (point on A - point on B) . normal,
  /// negative when penetrating (= -depth when the contact was found this substep).
  std::vector<std::array<Vec3, 2>> contactPoints;
};

class World {
public:
  /// Throws clod::Error(kInvalidArgument) naming the setting when one is out of range.
  explicit World(const WorldSettings& settings = {});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  /// Adds a body; returns its id (0, 1, ...). Throws clod::Error(kInvalidArgument) naming the
  /// body for a null shape, a non-positive or non-finite mass, a non-positive-definite inertia
  /// of a dynamic body, restitution outside [0, 1], negative friction, non-finite state, or a
  /// ball (ballRadius > 0) whose mesh does not enclose it or whose centre of mass is off its origin.
  BodyId addBody(const RigidBodyDesc& desc);
  /// Adds a body whose shape is desc.shape scaled uniformly by `scale` (scaleCollisionBody; > 0
  /// and finite). Everything else in `desc` describes the scaled body: centerOfMass and ballRadius in the scaled
  /// mesh coordinates, mass and inertia of the scaled body (for a uniform density they grow as
  /// scale^3 and scale^5; mass_properties.h computes them from the scaled mesh). Bodies added with
  /// the same shape and scale share one scaled copy. desc(id).shape is the scaled shape.
  BodyId addBody(const RigidBodyDesc& desc, double scale);

  /// Removes a body: it no longer moves, collides or counts in the momenta and energies, and its
  /// pairs' contacts and caches are dropped. Its id is retired, never reused (see BodyId); every
  /// other id stays valid. The world keeps a small record per retired id (and the shape pointer).
  /// Throws kInvalidArgument for an unknown or removed id.
  void removeBody(BodyId id);
  /// True when `id` was handed out by addBody and not removed.
  bool contains(BodyId id) const noexcept;

  /// Sets a body's pose and velocities (RigidBodyState frames: position of the mesh origin,
  /// centre-of-mass velocity, world angular velocity), e.g. to teleport or reset it. Validated:
  /// every component finite, and the orientation a unit quaternion to within 1e-3 (it is then
  /// normalised); otherwise clod::Error(kInvalidArgument) naming the body and the component. A
  /// static body takes the pose but its velocities must be zero. The body's pairs forget their
  /// contacts and caches (a teleport invalidates them), so the next step queries them afresh.
  void setState(BodyId id, const RigidBodyState& state);

  /// Force and torque (world frame, N and N m for SI scenes) acting on a dynamic body during the
  /// next World::step, added to what earlier calls since the last step applied; applyForce with a
  /// point (world frame) also adds the torque (point - centre of mass) x force. Like gravity they
  /// enter each substep's velocities before the contact solve, so a free body gains v = F dt / m.
  /// Cleared at the end of the step. Ignored for static and kinematic bodies (infinite mass).
  /// Non-finite values throw kInvalidArgument.
  void applyForce(BodyId id, const Vec3& force);
  void applyForce(BodyId id, const Vec3& force, const Vec3& pointWorld);
  void applyTorque(BodyId id, const Vec3& torque);
  /// An impulse (N s) at a point (world frame), applied to the velocities at once: v += J / m,
  /// w += I^-1 ((point - centre of mass) x J). Ignored for static and kinematic bodies.
  void applyImpulse(BodyId id, const Vec3& impulse, const Vec3& pointWorld);

  /// Collision filter of a body (default: collides with everything). Takes effect at the next
  /// step; a pair that becomes filtered out drops its contacts and caches.
  void setFilter(BodyId id, const CollisionFilter& filter);
  CollisionFilter filter(BodyId id) const;

  /// Called for every pair with contacts in every substep, after the narrow phase and before the
  /// solver (ContactCallback says what it may do). An empty function removes it.
  void setContactCallback(ContactCallback callback);

  /// Exact closest distance between bodies a and b as placed now (Separation), independent of the
  /// contact model and budget; their collision filter does not matter. The descent stops once the
  /// distance is known to exceed maxDistance (>= 0, or infinity; kInvalidArgument otherwise).
  /// The first query on a shape builds a box hierarchy over its triangles (O(T log T), kept while
  /// a body uses the shape). A query's cost grows with the number of triangle pairs about as near
  /// as the closest one: small for bodies near contact, large for curved bodies apart by their own
  /// size (O(Ta Tb) at worst). Measured on two bunny-1500 at 200 random poses 0.4-1.2 diagonals
  /// apart (a loaded 2-core machine): median 1 ms, 90th percentile 20 ms, slowest 41 ms; give
  /// maxDistance (a contact margin) to stop the far ones early. Not thread-safe with step() or
  /// itself.
  Separation separation(BodyId a, BodyId b,
                        double maxDistance = std::numeric_limits<double>::infinity()) const;

  /// Advances by dt (> 0, finite; else kInvalidArgument). Throws clod::Error(kSimulationDiverged)
  /// naming the body when a state becomes NaN or infinite (the state is then that of the failed
  /// substep). Cost: broad phase O(n log n + pairs) + narrow phase (bounded by the budget, see
  /// the top of this file) + solver O(iterations * contacts) per substep. No allocation once the
  /// contact and pair counts have stopped growing.
  const StepReport& step(double dt);

  /// Ids handed out so far, removed ones included (see BodyId).
  std::size_t bodyCount() const noexcept;
  /// Accessors by id. An id >= bodyCount() throws clod::Error(kInvalidArgument) naming the id
  /// and the body count, in every build type (not an assert: ids often come from outside); so
  /// does a removed body's id.
  RigidBodyState state(BodyId id) const;
  const RigidBodyDesc& desc(BodyId id) const;  ///< as added (initial state)
  BodyType type(BodyId id) const;  ///< current type (a body that left the bounds is kStatic)
  double mass(BodyId id) const;    ///< 0 for static/kinematic
  /// Total linear momentum, angular momentum about the world origin, and kinetic energy of the
  /// dynamic bodies; potential energy -m g.x summed likewise.
  Vec3 linearMomentum() const;
  Vec3 angularMomentum() const;
  double kineticEnergy() const;
  double potentialEnergy() const;
  const WorldSettings& settings() const noexcept;
  /// Changes the budget / model between steps (caches are cleared on a model change).
  void setBudgetTests(std::uint64_t tests);
  void setModel(ContactModel model);
  /// 64-bit hash of every body's state bits (for determinism checks).
  std::uint64_t stateHash() const;

  struct Impl;

private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace clod
