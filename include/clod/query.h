#pragma once
// The anytime narrow phase: contacts between two bodies (collision_body.h) within a budget
// (budget.h), from any of the contact models of contact.h. docs/narrow-phase.md explains the
// design and the measured cost and accuracy.
//
// Typical use (one pair, every frame):
//   clod::QueryScratch scratch;      // reused: no allocation per query in steady state
//   clod::QueryResult result;        // reused likewise
//   clod::CoherenceCache cache;      // optional: next frame starts from this frame's frontier
//   clod::QuerySettings settings;
//   settings.model = clod::ContactModel::kCfm;
//   settings.budget = clod::QueryBudget::tests(256);
//   clod::queryContacts(bodyA, xfWorldFromA, bodyB, xfWorldFromB, settings, scratch, result, &cache);
//   for (const clod::Contact& c : result.contacts) ...   // normal from B toward A, world frame
//
// Traversal (Hubbard-style simultaneous breadth-first, in rounds). The frontier is a list of
// overlapping node pairs (sphere-tree spheres, or contact-tree cells with their bounding
// spheres). It starts as the root pair, if the roots overlap. Each round sorts the frontier by
// priority -- the pair's sphere penetration r_A + r_B - |c_A - c_B|, largest first -- and
// expands every pair once: the node with the larger radius is replaced by its children (if one
// node is a leaf, the other one; pairs of two leaves are final and carried over), every child is
// tested against the other node (one test each), and the overlapping children replace the pair.
// So both trees descend level by level, and an interrupted round has spent its tests on the
// deepest-penetrating pairs first. Contact-tree children whose field proves them outside their
// body (ContactTree::minDistance > 0) are skipped without a test.
//
// Interruption keeps a consistent covering frontier: a pair is either expanded completely or kept
// whole; when the budget runs out in the middle of an expansion, that expansion's partial
// results are discarded (its tests stay counted) and the pair stays as it was. The answer is
// then built from the frontier: one contact per pair for the sphere models (D&O; cfm:
// none for pairs proven apart, patch depth and point where a sphere is a faceted patch), contact sampling
// of every frontier cell pair for the contact tree.
//
// Exact model: after the sphere-tree traversal has reached leaf x leaf pairs, the triangle
// pairs of those leaves (deduplicated: a triangle may belong to several leaves) are tested for
// intersection, one test each, in (triangle of A, triangle of B) order. Each intersecting pair
// gives the end points of its intersection segment (or the corners of the overlap polygon of
// coplanar triangles facing each other) as contacts. The intersecting pairs are grouped into
// connected patches: two pairs are in one patch when their intersection points coincide (within
// 1e-7 x the sum of the bodies' diagonals) and both are coplanar (flush face-on-face) or both
// crossing; so separate touching regions (a box on the ground and against a bump or a wall) are
// separate patches even where they share a large triangle. Every contact carries its patch's
// normal, the gradient of the patch's intersection volume (B's surface inside A minus A's
// surface inside B, area-weighted normals, each intersecting triangle clipped by the other
// body's triangles it meets in that patch), and its patch's depth: where one side is flat, the
// intersection volume over its area projected along that normal, the triangles wholly inside the
// other body counted (a box's bottom sunk into a slab crosses nothing): a flat penetration
// exactly; where both sides are curved, the distance along the normal between the two inside
// surfaces' centroids, half a lens's thickness (docs/narrow-phase.md). A flush coplanar patch
// gets its face normal and depth 0. In a curved patch (on both sides the inside pieces'
// normals spread by more than 1 deg: a thread's helical band, not a box's face) a contact whose
// own triangle pair is
// conformal (faces within 20 deg of facing each other) or one-sided (one inside piece >= 10x the
// other's) takes that pair's own volume gradient as its normal instead, when within 45 deg of
// the patch's (the depth stays the patch's): per-point normals, so a nut on a bolt's flank is pushed along the helix
// (docs/narrow-phase.md). Patch grouping costs O(k log k) for k contact points. Pairs of the frontier that
// did not get that far (interrupted before or during the triangle tests) give cfm contacts when
// both bodies carry closest feature maps (no extra tests; pairs a separating axis proves apart
// give none), else D&O contacts.
//
// Contacts are finally reduced to a manifold (reduceManifold, contact.h).

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "clod/budget.h"
#include "clod/collision_body.h"
#include "clod/contact.h"
#include "clod/contact_sampling.h"
#include "clod/math.h"

namespace clod {

struct QuerySettings {
  ContactModel model = ContactModel::kCfm;
  QueryBudget budget;
  /// Manifold size, >= 1 (the issue asks for 4..8 by default).
  std::uint32_t maxContacts = 8;
  /// Contacts closer than this times the smaller body's bounding-box diagonal are merged
  /// (ManifoldSettings::mergeDistanceAbs), >= 0.
  double mergeDistanceRel = 1e-3;
  /// Contact sampling of the contact-tree model. Its maxDepth is ignored (the traversal decides
  /// how deep to go) and its own per-patch thinning is not applied: the manifold reduction is.
  /// Its marginAbs applies to finished answers only (an interrupted answer's depths are known to
  /// within its coarse cells' bounds); the world sets it to 1e-4 of the smaller diagonal.
  ContactSamplingSettings contactSampling;
  /// Deepest hierarchy level the traversal descends to (0 = the roots): nodes at this level count
  /// as leaves, so the answer is the one "resolved at level maxLevel" (the papers' experiments).
  /// Sphere models: sphere level; contact-tree: cell depth; ignored by the exact model (it needs
  /// the leaves' triangles). Default: no cap.
  std::uint32_t maxLevel = UINT32_MAX;
  /// Contact margin (length units of the bodies, >= 0, finite): speculative contacts for bodies
  /// about to touch, in every model (docs/narrow-phase.md, "Margin"). When no contact of the
  /// model's answer penetrates beyond its errorBound and the two surfaces are at most marginAbs
  /// apart, the result gets one more contact at their exact closest points (World::separation's
  /// descent, separation.h): point midway, normal from B's closest point toward A's, depth =
  /// -distance (< 0), errorBound 0, the two triangles as features (ContactFeature::kTriangle).
  /// It does not set `colliding`.
  /// Not metered by the budget: one exact distance query, which stops as soon as the surfaces
  /// are proven farther apart than the margin, and runs only for answers without penetration.
  /// The contact tree's own samples within contactSampling.marginAbs come in addition. 0: off.
  double marginAbs = 0.0;
};

/// Why a query stopped.
enum class QueryStop : std::uint8_t {
  kFinished = 0,  ///< reached the leaves (and, in the exact model, tested every triangle pair)
  kTestBudget = 1,///< QueryBudget::maxTests used up
  kDeadline = 2,  ///< QueryBudget::deadline passed
};

/// "finished", "test_budget" or "deadline": the name the CLI's JSON and the Python bindings use.
std::string_view queryStopName(QueryStop stop) noexcept;

/// One pair of the frontier the answer was built from (body-local node indices).
struct FrontierPair {
  std::uint32_t nodeA = 0;   ///< sphere index (sphere models) or contact-tree node index
  std::uint32_t nodeB = 0;
  std::uint32_t levelA = 0;  ///< level of the sphere / depth of the cell
  std::uint32_t levelB = 0;
};

/// Result of queryContacts. Reuse one object across queries: its vectors keep their capacity.
struct QueryResult {
  /// dos and average: the frontier is non-empty. cfm: at least one contact (pairs whose patches
  /// a separating axis proves apart give none, docs/narrow-phase.md). Contact tree: at least one
  /// contact. Exact: a triangle pair intersects (or, if interrupted: with closest feature maps on
  /// both bodies at least one contact, as cfm; else some frontier pair was not refuted).
  bool colliding = false;
  /// The manifold, at most QuerySettings::maxContacts contacts, deepest first.
  std::vector<Contact> contacts;
  /// Tests made: sphereTests + triangleTests; never more than QueryBudget::maxTests.
  std::uint64_t tests = 0;
  std::uint64_t sphereTests = 0;
  std::uint64_t triangleTests = 0;
  /// True when nothing was left to refine (stop == kFinished).
  bool finished = false;
  QueryStop stop = QueryStop::kFinished;
  /// The frontier the contacts were built from, and the shallowest and deepest pair level in it
  /// (pair level = max(levelA, levelB)); 0 and 0 when it is empty.
  std::vector<FrontierPair> frontier;
  std::uint32_t minLevel = 0;
  std::uint32_t maxLevel = 0;
  /// Raw contacts before the manifold reduction.
  std::uint64_t rawContacts = 0;
  /// Exact model only: the intersecting (triangle of A, triangle of B) pairs found, sorted,
  /// each once. Empty for the other models.
  std::vector<std::array<std::uint32_t, 2>> intersectingTriangles;
  /// Frontier pairs turned into contacts: all of `frontier`, unless a deadline cut the answer
  /// short (QueryBudget::answerWithinDeadline); then the first ones in traversal order.
  std::uint64_t pairsAnswered = 0;
  /// Exact model only: frontier pairs that did not get their triangle tests (an interrupted
  /// query) and were answered by `fallbackModel` instead (cfm when both bodies carry closest
  /// feature maps, else dos); 0 when every contact is a triangle-level one. At an unlimited
  /// budget it is always 0: the exact model never falls back there.
  std::uint64_t fallbackPairs = 0;
  ContactModel fallbackModel = ContactModel::kExact;
  /// A lower bound on the distance between the two bodies' surfaces, > 0 when the query proved
  /// them apart everywhere: every pair of its traversal ended separated by its bounding spheres
  /// (the surfaces lie inside them), so the smallest gap between two such spheres bounds the
  /// surfaces' distance; no contact, not contained. 0 when some pair was not so separated (a
  /// frontier pair that gave no contact proves nothing about the gap) or the query stopped early.
  /// The world skips a pair while its bodies have moved against each other by less than this
  /// (docs/dynamics.md, "Proven apart").
  double separation = 0.0;
  /// Wall-clock seconds the query took.
  double seconds = 0.0;
};

/// Working memory of queries: frontier lists, candidate lists, raw contacts. Reuse one per
/// thread; after the first few queries of a scene it stops allocating. Not thread-safe.
class QueryScratch {
public:
  QueryScratch();
  ~QueryScratch();
  QueryScratch(QueryScratch&&) noexcept;
  QueryScratch& operator=(QueryScratch&&) noexcept;
  /// Seconds per frontier pair that turning a frontier into contacts takes with `model`: a
  /// deadline query stops its traversal this much per frontier pair before the deadline, so its
  /// answer ends by the deadline too (QueryBudget::answerWithinDeadline). Learned from this
  /// scratch's deadline queries (exponential average over answers of at least 8 pairs); set it to seed or pin the estimate (finite, >= 0; kInvalidArgument otherwise).
  double answerSecondsPerPair(ContactModel model) const noexcept;
  void setAnswerSecondsPerPair(ContactModel model, double seconds);

  struct Impl;
  Impl& impl() noexcept { return *impl_; }

private:
  std::unique_ptr<Impl> impl_;
};

/// Temporal coherence for one pair of bodies: remembers the last query's frontier -- its
/// overlapping pairs and the separated pairs next to them, which together cover every pair of
/// nodes -- so the next query re-tests that front (one test per pair) and refines from there
/// instead of from the roots. When the bodies, the model or the tree kind change, or nothing
/// overlapped last time, the next query starts from the roots. A cache belongs to one pair of
/// bodies in one order; it holds no pointers into them beyond identity checks.
///
/// What it changes: at an unlimited budget the exact model gives exactly the contacts of a cold
/// query (every intersecting triangle pair is below an overlapping front pair). The sphere
/// models may report, in addition, leaf pairs whose spheres overlap although an ancestor pair no
/// longer does (a cold query would have pruned them higher up): those pairs still overlap.
class CoherenceCache {
public:
  CoherenceCache();
  ~CoherenceCache();
  CoherenceCache(CoherenceCache&&) noexcept;
  CoherenceCache& operator=(CoherenceCache&&) noexcept;
  /// Forget the remembered front: the next query starts from the roots.
  void clear() noexcept;
  /// Pairs in the remembered front (overlapping + separated).
  std::size_t frontSize() const noexcept;
  struct Impl;
  Impl& impl() noexcept { return *impl_; }

private:
  std::unique_ptr<Impl> impl_;
};

/// Contacts between body A placed by xfWorldFromA and body B placed by xfWorldFromB (see the
/// top of this file). Overwrites `result`. Thread-safe for distinct scratch/result/cache.
/// Throws clod::Error(kBakeMissingSection) when the model needs data a body lacks (cfm and
/// average: a closest feature map; contact-tree: a contact tree), naming the body and the bake
/// option that adds it, and clod::Error(kInvalidArgument) for settings out of range
/// (maxContacts 0, maxTests 0, a negative or non-finite mergeDistanceRel, a null clock).
/// Cost: O(tests + frontier size * log) plus contact generation per frontier pair; no
/// allocation once scratch, result and cache have grown.
void queryContacts(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b,
                   const Pose& xfWorldFromB, const QuerySettings& settings, QueryScratch& scratch,
                   QueryResult& result, CoherenceCache* cache = nullptr);

/// Convenience: one query with fresh scratch memory (allocates).
QueryResult queryContacts(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b,
                          const Pose& xfWorldFromB, const QuerySettings& settings);

/// A lower bound on the distance between the two bodies' surfaces from their sphere-trees alone,
/// or 0 when it cannot prove them apart within `maxTests` sphere tests: the traversal of
/// queryContacts without contacts, > 0 only when every sphere pair ended separated (the smallest
/// gap between two separated spheres; the spheres hold the surfaces) and neither body lies inside
/// the other (closed bodies; a seed vertex against the other's field, as queryContacts checks
/// containment). Costs at most maxTests sphere tests plus a few field queries; no allocation
/// once the scratch has grown. `testsUsed`, if given, receives the tests made. The world asks
/// it first for a pair without contacts that a time budget would answer from the roots
/// (docs/dynamics.md, "Proven apart").
double proveApart(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b, const Pose& xfWorldFromB,
                  std::uint64_t maxTests, QueryScratch& scratch, std::uint64_t* testsUsed = nullptr);

}  // namespace clod
