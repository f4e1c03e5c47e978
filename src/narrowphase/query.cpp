// The anytime narrow phase: breadth-first traversal of two hierarchies under a budget, then
// contacts from the frontier (see include/clod/query.h for the contract).
#include "clod/query.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <limits>
#include <span>
#include <cmath>
#include <string>

#include "clod/contact_normal.h"
#include "clod/contact_rim.h"
#include "clod/error.h"
#include "containment.h"
#include "face_overlap.h"
#include "ray_cast.h"
#include "separation.h"
#include "triangle_intersection.h"

namespace clod {
namespace {

// ---------------------------------------------------------------------------------------------
// Budget meter: counts tests, reads the clock once per batch (budget.h).

class Meter {
public:
  // reservePerPair: seconds to set aside per frontier pair for turning the frontier into
  // contacts, so that the answer, too, ends by the deadline (0: stop at the deadline itself).
  Meter(const QueryBudget& budget, double reservePerPair)
      : limit_(budget.maxTests), deadline_(budget.deadline), now_(budget.now),
        timed_(budget.deadline != QueryBudget::TimePoint::max()), reservePerPair_(reservePerPair) {
    if (timed_ && reservePerPair_ > 0.0) start_ = now_();
  }

  // The traversal's current frontier size (pairs the answer will have to turn into contacts).
  void setFrontier(std::size_t pairs) { frontier_ = pairs; }
  // Exact model: triangle tests left until the query finishes, when finishing makes the answer
  // unnecessary (0: unknown). The reserve is then the cheaper of answering the frontier and
  // finishing at this query's average time per test so far.
  void setRemainingTests(std::uint64_t tests) { remainingTests_ = tests; }
  // Does the deadline check use the frontier and remaining tests (else they need no updates)?
  bool reserving() const { return timed_ && reservePerPair_ > 0.0; }

  bool take() {
    if (stopped_) return false;
    if (used_ >= limit_) {
      stop_ = QueryStop::kTestBudget;
      stopped_ = true;
      return false;
    }
    if (timed_) {
      if (batchLeft_ == 0) {
        const QueryBudget::TimePoint now = now_();
        if (now + reserve(now) >= deadline_) {
          stop_ = QueryStop::kDeadline;
          stopped_ = true;
          return false;
        }
        batchLeft_ = kDeadlineBatch;
      }
      --batchLeft_;
    }
    ++used_;
    return true;
  }
  // Counts `n` tests of work that is done whatever the budget (the containment answer), as far
  // as the limit allows: `used` never exceeds maxTests, and nothing stops.
  void count(std::uint64_t n) { used_ += std::min(n, limit_ > used_ ? limit_ - used_ : 0); }
  bool stopped() const { return stopped_; }
  // Neither a test limit nor a deadline: the traversal will finish whatever its order.
  bool unlimited() const { return !timed_ && limit_ == kUnlimitedTests; }
  QueryStop stop() const { return stop_; }
  std::uint64_t used() const { return used_; }

private:
  QueryBudget::Clock::duration reserve(QueryBudget::TimePoint now) const {
    if (reservePerPair_ <= 0.0) return QueryBudget::Clock::duration::zero();
    double seconds = reservePerPair_ * static_cast<double>(frontier_);
    if (remainingTests_ > 0 && used_ > 0) {
      const double perTest = std::chrono::duration<double>(now - start_).count() / static_cast<double>(used_);
      seconds = std::min(seconds, perTest * static_cast<double>(remainingTests_));
    }
    // Capped at an hour so the arithmetic on time points cannot overflow.
    return std::chrono::duration_cast<QueryBudget::Clock::duration>(
        std::chrono::duration<double>(std::clamp(seconds, 0.0, 3600.0)));
  }

  std::uint64_t limit_;
  QueryBudget::TimePoint deadline_;
  QueryBudget::TimePoint (*now_)();
  bool timed_;
  double reservePerPair_;
  QueryBudget::TimePoint start_{};
  std::size_t frontier_ = 0;
  std::uint64_t remainingTests_ = 0;
  // The first batch starts without a clock read (budget.h).
  std::uint32_t batchLeft_ = kDeadlineBatch;
  std::uint64_t used_ = 0;
  bool stopped_ = false;
  QueryStop stop_ = QueryStop::kFinished;
};

// Sphere pairs answered between two clock reads of AnswerClock.
inline constexpr std::uint32_t kAnswerBatch = 8;

// Deadline while the frontier is turned into contacts (QueryBudget::answerWithinDeadline): the
// first batch of pairs is always answered, then the clock is read once per batch; past the
// deadline the rest of the frontier -- its lowest-priority end: the traversal leaves the deepest
// pairs' children first -- gets no contacts (unless none was found yet: next()). Also times the
// answer, to learn its cost per pair.
class AnswerClock {
public:
  // batch: pairs between clock reads, about a microsecond of work each -- kAnswerBatch sphere
  // pairs (tens of ns to a few hundred each), or 1 contact-tree cell pair (each samples two
  // cells' fields: microseconds). A clock read costs ~20-30 ns.
  AnswerClock(const QueryBudget& budget, std::uint32_t batch)
      : deadline_(budget.deadline), now_(budget.now),
        timed_(budget.deadline != QueryBudget::TimePoint::max() && budget.answerWithinDeadline), batch_(batch),
        batchLeft_(batch) {
    if (timed_) start_ = now_();
  }

  bool timed() const { return timed_; }
  // May the next pair be answered? Past the deadline only while the answer has no contact yet
  // (`haveContact`), for at most kDeadlineBatch more pairs: a deep overlap whose first answered
  // pairs happen to give nothing (contact-tree samples all outside) still reports a contact.
  bool next(bool haveContact) {
    if (cut_ && (haveContact || extra_ >= kDeadlineBatch)) return false;
    if (cut_) {
      ++extra_;
    } else if (timed_) {
      if (batchLeft_ == 0) {
        if (now_() >= deadline_) {
          cut_ = true;
          return next(haveContact);
        }
        batchLeft_ = batch_;
      }
      --batchLeft_;
    }
    ++answered_;
    return true;
  }
  std::uint64_t answered() const { return answered_; }
  double secondsSinceStart() const { return std::chrono::duration<double>(now_() - start_).count(); }

private:
  QueryBudget::TimePoint deadline_;
  QueryBudget::TimePoint (*now_)();
  bool timed_;
  std::uint32_t batch_;
  std::uint32_t batchLeft_;
  QueryBudget::TimePoint start_{};
  std::uint64_t answered_ = 0;
  std::uint32_t extra_ = 0;
  bool cut_ = false;
};

// ---------------------------------------------------------------------------------------------
// Hierarchy adapters: the traversal sees a tree as nodes with a bounding sphere and children.

struct SphereSide {
  const SphereTree& tree;
  const CollisionBody& body;
  using Node = std::uint32_t;
  Node root() const { return 0; }
  Vec3 center(Node n) const { return {tree.centerX[n], tree.centerY[n], tree.centerZ[n]}; }
  double radius(Node n) const { return tree.radius[n]; }
  bool isLeaf(Node n) const {
    return tree.childCount[n] == 0 || body.sphereLevel(n) >= maxLevel || (wholeBodyIsLeaf && body.patchIsWholeConvexBody(n));
  }
  std::uint32_t childCount(Node n) const { return tree.childCount[n]; }
  Node child(Node n, std::uint32_t k) const { return tree.firstChild[n] + k; }
  bool usable(Node) const { return true; }
  std::uint32_t level(Node n) const { return body.sphereLevel(n); }
  static std::uint32_t index(Node n) { return n; }
  std::uint64_t triangleCount(Node n) const { return tree.triangleOffsets[n + 1] - tree.triangleOffsets[n]; }
  std::uint32_t maxLevel = UINT32_MAX;  // QuerySettings::maxLevel
  // cfm without a level cap: a sphere whose patch is the whole convex body is final -- its
  // children's patches are parts of it, and its contacts are exact already (error bound 0), so
  // refining it could not change the answer, only its cost (a 10-box pyramid at an unlimited
  // budget took 68 M tests for 10 s, 1.9x slower than real time).
  bool wholeBodyIsLeaf = false;
  // Spheres have no planes: a final sphere never prunes the other side's children, and no
  // sphere pair is final before its leaves for being flat.
  static bool outsidePlane(Node, const Vec3&, double) { return false; }
  static bool isFlat(Node) { return false; }
  static bool isResolved(Node) { return false; }
};

struct CellSide {
  const ContactTree& tree;
  using Node = ContactCell;
  Node root() const { return tree.rootCell(); }
  Vec3 center(const Node& c) const { return tree.cellCenter(c); }
  double radius(const Node& c) const { return tree.cellRadius(c.depth); }
  // A cell whose surface is one plane within the field's error (a face away from its edges) is
  // final like a leaf: its children's samples would lie on the same plane, and the field
  // queries of sampling go to the other tree's leaves anyway. So a box on a box refines only
  // along the edges, and stops at the faces' largest flat cells (docs/narrow-phase.md).
  bool isLeaf(const Node& c) const { return tree.isLeaf(c.node) || c.depth >= maxLevel || isFlat(c); }
  bool isFlat(const Node& c) const { return tree.isFlatSurface(c.node); }
  // A cell at most 1/8 of its body's diagonal is resolved: a pair of resolved (or flat) cells is
  // final. Sampling reads the other body's field at its leaves and moves this side's samples
  // onto its own surface (contact_sampling.cpp), so descending further only adds samples, which
  // are already spaced at most 1/32 of the diagonal. Edges and corners, where the field is
  // refined to the tree's depth, otherwise made every leaf along a box's edges a pair of its own
  // (a box on a slab: 3,668 pairs, 10 ms; a box on an equal box, edges flush: 4,352 leaf pairs,
  // 34 ms; docs/narrow-phase.md).
  bool isResolved(const Node& c) const { return tree.cellSize(c.depth) * 8.0 <= tree.meshDiagonal; }
  // Paper B's half-space test, for a final cell (a leaf or a flat cell): true when the sphere
  // (centre in this tree's frame) lies on the outer side of the cell's plane, farther than the
  // plane's distance from the surface in the cell (a leaf's fit error; errorAbs for a flat cell,
  // whose stored fit error also measured lattice points deep inside the body). Within the cell
  // the body is below that, so no sample of the pair can be a contact. Without it a large flat
  // cell's bounding sphere reaches far beyond its face, and the other tree descended to every
  // leaf inside that sphere (a box on a slab: twice the tests of full refinement).
  bool outsidePlane(const Node& c, const Vec3& centre, double radius) const {
    const ContactHalfSpace* hs = tree.halfSpace(c.node);
    if (!hs) return false;
    const Vec3 n(hs->normal[0], hs->normal[1], hs->normal[2]);
    const double surface = tree.isFlatSurface(c.node) ? tree.errorAbs : double(hs->fitError);
    const double above = n.dot(centre - tree.cellCenter(c)) - double(hs->offset);
    return above > radius + surface + 1e-6 * tree.cellSize(c.depth);
  }
  std::uint32_t childCount(const Node&) const { return 8; }
  Node child(const Node& c, std::uint32_t k) const { return tree.childCell(c, k); }
  // A cell the field proves to be wholly outside its body holds neither surface nor interior:
  // nothing of it can touch the other body. This is a property of the cell alone, not a test.
  bool usable(const Node& c) const { return tree.minDistance(c) <= 0.0; }
  std::uint32_t level(const Node& c) const { return c.depth; }
  static std::uint32_t index(const Node& c) { return c.node; }
  // Cells have no triangle lists: never final before the leaves.
  static std::uint64_t triangleCount(const Node&) { return std::numeric_limits<std::uint32_t>::max(); }
  std::uint32_t maxLevel = UINT32_MAX;  // QuerySettings::maxLevel
};

template <class NA, class NB>
struct NodePair {
  NA a;
  NB b;
  double priority;  // sphere penetration r_A + r_B - |c_A - c_B|
};

using SpherePair = NodePair<std::uint32_t, std::uint32_t>;
using CellPair = NodePair<ContactCell, ContactCell>;

}  // namespace

// ---------------------------------------------------------------------------------------------

// A vertex tested against a closed non-convex body in one answer (cornersInsideContacts), and
// whether it was inside.
struct ProbedCorner {
  std::uint32_t vertex;
  bool inside;
  Vec3 point = Vec3::Zero();  // A frame
  Contact contact{};          // inside: the vertex's contact
  Vec3 exit = Vec3::Zero();   // inside: the direction the vertex's body leaves along (A frame)
};

struct QueryScratch::Impl {
  std::vector<SpherePair> sphereFront, sphereNext, sphereSeparated;
  std::vector<CellPair> cellFront, cellNext, cellSeparated;
  struct TrianglePairRef {
    std::uint32_t ta, tb, pair;
  };
  std::vector<TrianglePairRef> trianglePairs;
  struct KeyedContact {
    std::uint64_t key;
    std::uint32_t pair;  // index into volumePairs (insertion order)
    Contact contact;
  };
  std::vector<KeyedContact> exactContacts;
  std::vector<std::uint8_t> pairDone;
  std::vector<std::uint64_t> pairSet;  // open-addressing set of triangle-pair keys
  // Intersecting triangle pairs of the exact model: triangles, patch (after grouping).
  struct VolumePair {
    std::uint32_t ta, tb, patch, index;  // index: insertion order, kept through the sorts
  };
  std::vector<VolumePair> volumePairs;
  std::vector<std::uint8_t> pairCoplanar;  // per volume pair (insertion order)
  std::vector<Vec3> pairNormalA;           // A's face normal per volume pair, A's frame
  std::vector<Vec3> pairNormalB;           // B's face normal per volume pair, A's frame
  std::vector<std::uint32_t> pairLevel;    // the sphere-tree level it was found at, per volume pair
  // Per volume pair (insertion order): the inside pieces of its A and of its B triangle (each
  // triangle clipped by the other body's triangles it meets in the patch), A's frame.
  struct Piece {
    Vec3 areaVector, weightedCentroid;  // area x outward normal; area x centroid
    double area;
  };
  std::vector<Piece> pieceA, pieceB;
  std::vector<std::uint8_t> patchCurved;  // per patch: both sides' pieces spread (local normals)
  std::vector<std::uint32_t> patchParent;  // union-find over volume pairs
  struct CellPoint {
    std::array<std::int64_t, 3> cell;
    std::uint32_t contact;
  };
  std::vector<CellPoint> cellPoints;
  std::vector<Vec3> patchNormal;
  std::vector<double> patchDepth;
  struct PatchSums {
    Vec3 centroidA, centroidB, fallbackNormal;
    double areaA, areaB;
    bool seen;
    Vec3 vectorA, vectorB;      // sums of the pieces' area vectors, per side
    double absoluteA, absoluteB;  // sums of their lengths
    double moment;              // sum of centroid . area vector over both sides (the volume, x3)
    // The triangles wholly inside the other body (addWhollyInsideTriangles), for the depth only:
    // their area vectors per side and their share of `moment`.
    Vec3 insideVectorA, insideVectorB;
    double insideMoment;
    Vec3 largestA = Vec3::Zero(), largestB = Vec3::Zero();  // each side's largest piece's area vector
  };
  std::vector<PatchSums> patchSums;
  // Triangles wholly inside the other body (addWhollyInsideTriangles): per triangle of the side
  // being filled, its state (kUnseen, kCrossing, kOutside or the patch it was reached from), and
  // the triangles touched, to reset them afterwards; the flood's queue.
  std::vector<std::uint32_t> triangleState, touchedTriangles, floodQueue;
  // Vertex contacts of the exact model (vertexContacts): per vertex of each body whether it was
  // tried, the vertices tried (to reset), the contacts found and the patches that have any.
  std::array<std::vector<std::uint8_t>, 2> vertexTried;
  std::array<std::vector<std::uint32_t>, 2> triedVertices;
  std::vector<Contact> vertexContacts;
  std::vector<std::uint8_t> patchHasVertices;
  std::vector<double> patchVertexDepth;  // the deepest vertex contact per patch
  // Vertices already probed against a closed non-convex body's exact field in this answer
  // (cornersInsideContacts), per body (A, B).
  std::array<std::vector<ProbedCorner>, 2> probedCorners;
  // Separating-axis contacts of such pairs without a vertex inside, kept only if no pair has one.
  std::vector<Contact> edgeContacts;
  std::vector<std::uint32_t> clippers;
  std::vector<Vec3> poly, polyTmp;
  std::vector<Contact> raw;
  std::vector<ContactPoint> sampled;
  std::vector<double> manifold;
  detail::ContainmentScratch containment;
  detail::SeparationHeap separationHeap;
  // Seconds per frontier pair of turning a frontier into contacts, per model (index =
  // ContactModel), learned from this scratch's deadline queries (QueryBudget::answerWithinDeadline).
  // Starting values: medians measured on the deep benchmark poses (bench_narrowphase
  // BM_NarrowPhase_Deadline, 2-core x86-64, 2026): they only matter until the first deadline query.
  std::array<double, 5> answerSecondsPerPair{0.02e-6, 0.1e-6, 0.3e-6, 2.0e-6, 0.3e-6};
};

QueryScratch::QueryScratch() : impl_(std::make_unique<Impl>()) {}
QueryScratch::~QueryScratch() = default;
QueryScratch::QueryScratch(QueryScratch&&) noexcept = default;
QueryScratch& QueryScratch::operator=(QueryScratch&&) noexcept = default;
double QueryScratch::answerSecondsPerPair(ContactModel model) const noexcept {
  return impl_->answerSecondsPerPair[static_cast<std::size_t>(model)];
}
void QueryScratch::setAnswerSecondsPerPair(ContactModel model, double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds)) {
    throw Error(ErrorCode::kInvalidArgument, "answer seconds per pair must be finite and >= 0, got " + std::to_string(seconds));
  }
  impl_->answerSecondsPerPair[static_cast<std::size_t>(model)] = seconds;
}

struct CoherenceCache::Impl {
  const CollisionBody* a = nullptr;
  const CollisionBody* b = nullptr;
  bool cells = false;  // which lists below are in use
  bool valid = false;
  std::vector<SpherePair> sphereOverlapping, sphereSeparated;
  std::vector<CellPair> cellOverlapping, cellSeparated;
};

CoherenceCache::CoherenceCache() : impl_(std::make_unique<Impl>()) {}
CoherenceCache::~CoherenceCache() = default;
CoherenceCache::CoherenceCache(CoherenceCache&&) noexcept = default;
CoherenceCache& CoherenceCache::operator=(CoherenceCache&&) noexcept = default;
void CoherenceCache::clear() noexcept {
  impl_->valid = false;
  impl_->sphereOverlapping.clear();
  impl_->sphereSeparated.clear();
  impl_->cellOverlapping.clear();
  impl_->cellSeparated.clear();
}
std::size_t CoherenceCache::frontSize() const noexcept {
  if (!impl_->valid) return 0;
  return impl_->cells ? impl_->cellOverlapping.size() + impl_->cellSeparated.size()
                      : impl_->sphereOverlapping.size() + impl_->sphereSeparated.size();
}

namespace {

// Exact model: a sphere pair whose triangle lists make at most this many triangle pairs is not
// descended further; its triangle pairs are tested directly. Below that, descending costs up to
// 8 sphere tests per level and finds the same large triangles again in many small spheres (a
// box's 12 triangles fill every sphere of a 4-level tree), while a triangle test costs only a few
// sphere tests and the pairs are deduplicated. Measured (CPU time, deep / shallow poses): 16 ->
// bunny 416 / 47 us, fandisk 1716 / 430 us; 32 -> 448 / 37, 1038 / 237; 64 -> 650 / 56,
// 1330 / 248 (docs/benchmarks/narrowphase.md).
constexpr std::uint64_t kExactDirectPairs = 32;

// cos 60 deg: the cone within which the manifold pools the normals of cfm contacts (below).
constexpr double kPoolNormalsCos = 0.5;

// Exact model, per-point normals (localNormal): a patch side whose pieces' area vectors
// sum to less than cos 1 deg of their lengths' sum is curved (a flat face, however tessellated,
// sums to its area: rounding only); a triangle pair is conformal when its faces are within 20 deg
// of facing each other (a thread's flank facets meet within 8 deg; its flank crosses the other
// part's crest at 60, a box's side face crosses a top face at 90).
constexpr double kFlatSpreadCos = 0.99984769515639;  // cos 1 deg
constexpr double kConformalCos = 0.93969262078591;   // cos 20 deg
// ... and one-sided when the faces cross at 45 deg or more and one inside piece has 10 x the
// other's area: a thread facet sunk 10 um past the other part's crest (crossing at 60 deg) has
// ~100 x the area of the crest strip inside it. Below 45 deg a sliver is tessellation luck: two
// unit icospheres 0.1 deep cross at 36 deg, and their slivers tilted the resultant 6.3 deg off
// the centre line (NarrowPhaseSpheres.EveryModelGivesTheCentreLine allows 6).
constexpr double kDominantPiece = 10.0;
constexpr double kOneSidedCrossingCos = 0.70710678118655;  // cos 45 deg
// A local normal refines its patch's (c.normal on entry), which is the mean of the pieces' normals:
// one more than 45 deg from it comes from an edge, not a surface (a face that an edge of the other
// part cuts at a corner, whose inside piece is overestimated by clipping with the few triangles
// that edge meets: the nut's end step, normal along the helix, met by the bolt's crest edge).
constexpr double kLocalConeCos = 0.70710678118655;  // cos 45 deg

// A Pose as a rotation matrix: moving a point costs 9 multiply-adds instead of the quaternion's
// two cross products. The traversal moves a centre per sphere test and the exact model three
// corners per triangle test (the quaternion product was ~20 % of a deep bunny exact query, perf).
struct MatrixPose {
  Mat3 rotation;
  Vec3 translation;
  explicit MatrixPose(const Pose& p) : rotation(p.rotation.toRotationMatrix()), translation(p.translation) {}
  Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
};

// ---------------------------------------------------------------------------------------------
// The traversal. All geometry is in A's frame: B's centres are moved once per test.

enum class TestOutcome : std::uint8_t { kOverlap, kSeparated, kOutOfBudget };

template <class SideA, class SideB>
class Traversal {
public:
  using NA = typename SideA::Node;
  using NB = typename SideB::Node;
  using Pair = NodePair<NA, NB>;

  // directPairs > 0: a pair whose triangle lists give at most that many triangle pairs is final
  // (the exact model tests its triangles instead of descending further).
  Traversal(const SideA& a, const SideB& b, const Pose& xfAFromB, Meter& meter, std::uint64_t directPairs)
      : a_(a), b_(b), xfAFromB_(xfAFromB), xfBFromA_(xfAFromB.inverse()), meter_(meter), directPairs_(directPairs) {}

  // `penetration` is the spheres' overlap, negative for separated spheres: minus their gap, which
  // a separated pair keeps as its priority (QueryResult::separation).
  // A separated pair's gap is computed only where it is kept (`keepGap`: the separated list is
  // tracked) or may be the smallest so far; otherwise `penetration` is -infinity, which
  // noteSeparated ignores (the square root was a fifth of the traversal's time).
  TestOutcome test(const Vec3& centerA, double radiusA, const Vec3& centerBinA, double radiusB, bool keepGap,
                   double& penetration) {
    if (!meter_.take()) return TestOutcome::kOutOfBudget;
    const double d2 = (centerA - centerBinA).squaredNorm();
    const double rr = radiusA + radiusB;
    const bool separated = d2 > rr * rr;
    penetration = separated && !keepGap && !mayBeSmallestGap(d2, rr) ? -std::numeric_limits<double>::infinity()
                                                                      : rr - std::sqrt(d2);
    return separated ? TestOutcome::kSeparated : TestOutcome::kOverlap;
  }

  // Could the gap sqrt(d2) - rr be below the smallest so far? Conservative by 1e-9 relative,
  // far above the rounding of either side, so the smallest gap is the one computing every gap gives.
  bool mayBeSmallestGap(double d2, double rr) const {
    if (smallestGap_ == std::numeric_limits<double>::infinity()) return true;
    const double reach = smallestGap_ + rr;
    return d2 <= reach * reach * (1.0 + 1e-9);
  }

  Vec3 centerB(const NB& n) const { return xfAFromB_.apply(b_.center(n)); }

  // The smallest gap between the bounding spheres of the pairs found separated so far (infinity
  // before any; 0 once a cell's plane, not the spheres, separated a pair: QueryResult::separation).
  double smallestGap() const { return smallestGap_; }
  void noteSeparated(double penetration) { smallestGap_ = std::min(smallestGap_, std::max(0.0, -penetration)); }

  // A final cell's plane proves the pair apart (CellSide::outsidePlane); never for spheres.
  bool planeSeparates(const NA& a, const NB& b) const {
    return (a_.isLeaf(a) && a_.outsidePlane(a, centerB(b), b_.radius(b))) ||
           (b_.isLeaf(b) && b_.outsidePlane(b, xfBFromA_.apply(a_.center(a)), a_.radius(a)));
  }

  // Re-tests a list of pairs (the roots, or a cached front): overlapping ones go to `front`,
  // separated ones to `separated` (if tracked). When the budget runs out, the untested pairs keep
  // the status they came with (`assumeOverlap`).
  void retest(const std::vector<Pair>& pairs, bool assumeOverlap, std::vector<Pair>& front,
              std::vector<Pair>* separated) {
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const Pair& p = pairs[i];
      meter_.setFrontier(front.size() + (pairs.size() - i));
      double pen = 0.0;
      TestOutcome o = test(a_.center(p.a), a_.radius(p.a), centerB(p.b), b_.radius(p.b), separated != nullptr, pen);
      if (o == TestOutcome::kOverlap && planeSeparates(p.a, p.b)) o = TestOutcome::kSeparated;
      if (o == TestOutcome::kOverlap) {
        front.push_back({p.a, p.b, pen});
      } else if (o == TestOutcome::kSeparated) {
        noteSeparated(pen);
        if (separated) separated->push_back({p.a, p.b, pen});
      } else if (assumeOverlap) {
        front.push_back(p);
      } else if (separated) {
        separated->push_back(p);
      }
    }
  }

  // Deepest pairs first, ties by index: the order a budget cuts the rounds in, and the answer's.
  static void sortByPriority(std::vector<Pair>& pairs) {
    std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) {
      if (x.priority != y.priority) return x.priority > y.priority;
      if (SideA::index(x.a) != SideA::index(y.a)) return SideA::index(x.a) < SideA::index(y.a);
      return SideB::index(x.b) < SideB::index(y.b);
    });
  }

  // Rounds of expansion until every pair is final or the budget is out. Returns true when
  // finished. `front` holds the answer frontier afterwards.
  bool refine(std::vector<Pair>& front, std::vector<Pair>& next, std::vector<Pair>* separated) {
    // Without a budget every round expands every pair whatever the order, so only the final
    // front is sorted (the same pairs in the same order; the sort per round was ~8 % of cfm's
    // unlimited bunny-1500 query).
    const bool sortEachRound = !meter_.unlimited();
    for (;;) {
      if (sortEachRound) sortByPriority(front);
      if (directPairs_ > 0 && meter_.reserving()) {
        // Exact model: tests left to finish, at most the frontier pairs' triangle pairs and at
        // most all triangle pairs of the two meshes (the deduplicated total) -- a small mesh
        // pair finishes sooner than its frontier can be answered from the spheres (Meter).
        const std::uint64_t all = a_.triangleCount(a_.root()) * b_.triangleCount(b_.root());
        std::uint64_t left = 0;
        for (std::size_t i = 0; i < front.size() && left < all; ++i) {
          left += a_.triangleCount(front[i].a) * b_.triangleCount(front[i].b);
        }
        meter_.setRemainingTests(std::min(left, all));
      }
      next.clear();
      bool expanded = false;
      for (std::size_t i = 0; i < front.size(); ++i) {
        const Pair& p = front[i];
        meter_.setFrontier(next.size() + (front.size() - i));
        const bool leafA = a_.isLeaf(p.a);
        const bool leafB = b_.isLeaf(p.b);
        if ((leafA && leafB) || a_.triangleCount(p.a) * b_.triangleCount(p.b) <= directPairs_ ||
            ((a_.isFlat(p.a) || a_.isResolved(p.a)) && (b_.isFlat(p.b) || b_.isResolved(p.b)))) {
          next.push_back(p);
          continue;
        }
        const double rA = a_.radius(p.a);
        const double rB = b_.radius(p.b);
        const bool descendA = !leafA && (leafB || rA >= rB);
        const std::size_t mark = next.size();
        const std::size_t sepMark = separated ? separated->size() : 0;
        bool out = false;
        if (descendA) {
          const Vec3 cB = centerB(p.b);
          for (std::uint32_t k = 0, n = a_.childCount(p.a); k < n; ++k) {
            const NA c = a_.child(p.a, k);
            if (!a_.usable(c)) continue;
            double pen = 0.0;
            TestOutcome o = test(a_.center(c), a_.radius(c), cB, rB, separated != nullptr, pen);
            if (o == TestOutcome::kOutOfBudget) {
              out = true;
              break;
            }
            if (o == TestOutcome::kOverlap && planeSeparates(c, p.b)) o = TestOutcome::kSeparated;
            if (o == TestOutcome::kOverlap) {
              next.push_back({c, p.b, pen});
            } else {
              noteSeparated(pen);
              if (separated) separated->push_back({c, p.b, pen});
            }
          }
        } else {
          const Vec3 cA = a_.center(p.a);
          for (std::uint32_t k = 0, n = b_.childCount(p.b); k < n; ++k) {
            const NB c = b_.child(p.b, k);
            if (!b_.usable(c)) continue;
            double pen = 0.0;
            TestOutcome o = test(cA, rA, centerB(c), b_.radius(c), separated != nullptr, pen);
            if (o == TestOutcome::kOutOfBudget) {
              out = true;
              break;
            }
            if (o == TestOutcome::kOverlap && planeSeparates(p.a, c)) o = TestOutcome::kSeparated;
            if (o == TestOutcome::kOverlap) {
              next.push_back({p.a, c, pen});
            } else {
              noteSeparated(pen);
              if (separated) separated->push_back({p.a, c, pen});
            }
          }
        }
        if (out) {
          // Keep the pair whole: drop this expansion's partial results, keep the rest as is.
          next.resize(mark);
          if (separated) separated->resize(sepMark);
          next.insert(next.end(), front.begin() + static_cast<std::ptrdiff_t>(i), front.end());
          front.swap(next);
          return false;
        }
        expanded = true;
      }
      front.swap(next);
      if (!expanded) {
        if (!sortEachRound) sortByPriority(front);
        return true;
      }
    }
  }

private:
  const SideA& a_;
  const SideB& b_;
  MatrixPose xfAFromB_;
  MatrixPose xfBFromA_;
  Meter& meter_;
  std::uint64_t directPairs_;
  double smallestGap_ = std::numeric_limits<double>::infinity();
};

// ---------------------------------------------------------------------------------------------
// Contacts from sphere pairs.

// Dingliana & O'Sullivan's point: where the plane of the two spheres' intersection circle cuts
// the centre line. With d = |c_A - c_B| and u = (c_A - c_B)/d, that plane is at distance
// x = (d^2 + r_B^2 - r_A^2) / (2d) from c_B along u (the radical plane). When one sphere holds
// the other the plane leaves the segment; x is clamped to B's sphere so the point stays in both.
struct DosContact {
  Vec3 point;   // A frame
  Vec3 normal;  // A frame, B -> A
  double depth;
};

DosContact dosContact(const Vec3& cA, double rA, const Vec3& cB, double rB) {
  const Vec3 delta = cA - cB;
  const double d = delta.norm();
  DosContact c;
  c.depth = rA + rB - d;
  if (d <= 1e-300) {
    // Concentric: any direction is as good as any other; +z of A's frame, point at the centre.
    c.normal = Vec3::UnitZ();
    c.point = cB;
    return c;
  }
  c.normal = delta / d;
  const double x = std::clamp((d * d + rB * rB - rA * rA) / (2.0 * d), std::max(0.0, d - rA), std::min(d, rB));
  c.point = cB + x * c.normal;
  return c;
}

// How the two spheres' normals are combined (docs/narrow-phase.md). u is the D&O normal (B's
// centre toward A's); A's outward normal should face B (n_A . u < 0), B's should face A.
//  1. if they agree (n_B and -n_A within 10 deg), n = normalize(n_B - n_A): both surfaces'
//     normals; for face-on-face n_A = -n_B so n = n_B, on smooth bodies their average;
//  2. if at least one sphere is a faceted patch (CollisionBody::spherePatchVertices), the
//     separating-axis choice of leastOverlapNormal below: the candidate (the faceted patches'
//     face normals; edge-edge cross products when both are faceted; both map normals when one
//     side is a curved patch bounded by its sphere -- between two faceted patches map
//     pseudonormals are no SAT axes and were measured to undercut the face normal where an edge
//     of A lies along an edge of B) along which the two sides overlap least; an axis along
//     which they do not overlap proves the pair apart, and it gives no contact;
//  rules 3-5 decide between two curved patches:
//  3. if exactly one of them faces the other sphere, it wins: the other sphere's lookup found
//     a feature that turns away from the contact (a loose sphere whose nearest surface is a side
//     face, not the one touching);
//  4. if exactly one of them is a face normal of its sphere's triangles
//     (CollisionBody::sphereFaceNormals; an edge or vertex pseudonormal is not), it wins: an edge
//     or corner meeting a face is pushed along the face normal;
//  5. otherwise the one that faces the other sphere more (larger n_B . u or -n_A . u): of two
//     faces of a box meeting another box, the one turned toward the contact.
// (A vanishing rule-1 normal, n_A = n_B, gives the D&O normal.)
// Where a side is faceted, depth and point then come from the patches too (patchDepthAndPoint).
constexpr double kAgreeCos = 0.984807753012208;   // cos 10 deg
constexpr double kFaceMatchCos = 0.99939082701909; // cos 2 deg: above the 16-bit codec's ~0.95 deg

bool isFaceNormal(const Vec3& nLocal, std::span<const Vec3f> faces) {
  for (const Vec3f& f : faces) {
    if (f.cast<double>().dot(nLocal) > kFaceMatchCos) return true;
  }
  return false;
}

enum class PatchAxis : std::uint8_t { kNotFaceted, kChosen, kApart };

// [min, max] of n . v over a side's vertices, in one pass: the separating-axis test needs both
// ends of every projection. A faceted patch's vertices are those of whole triangles, not of their
// part inside the sphere: where a sphere cuts a face just at the other body's edge, the cut would
// look like a real boundary and make the side face the least-overlap axis.
struct Extent {
  double lo, hi;
};

// A side's patch or support vertices in A's frame, as three flat arrays: the separating-axis
// choice projects the same vertices onto up to 52 axes: gathered once per sphere pair, they are
// not re-read through the index list and each axis is not rotated into the body per projection
// (cfm's unlimited bunny-1500 query: ~980 -> ~930 us). Sides with more vertices than fit (a large
// curved patch's hull: up to 1,024) are projected in place.
struct GatheredVertices {
  GatheredVertices() {}  // filled on first use; the arrays are not zeroed per sphere pair
  static constexpr std::uint32_t kNotGathered = ~0u;
  static constexpr std::uint32_t kTooMany = kNotGathered - 1;
  static constexpr std::uint32_t kCapacity = 64;
  static_assert(CollisionBody::kMaxSpherePatchVertices <= kCapacity, "a faceted patch always fits");
  double x[kCapacity], y[kCapacity], z[kCapacity];
  std::uint32_t count = kNotGathered;

  // [min, max] of n . v over the gathered vertices.
  Extent extent(const Vec3& n) const {
    // Four independent running minima and maxima: one pair of them is a chain of dependent,
    // latency-bound min/max instructions.
    const double nx = n.x(), ny = n.y(), nz = n.z();
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo[4] = {kInf, kInf, kInf, kInf}, hi[4] = {-kInf, -kInf, -kInf, -kInf};
    std::uint32_t i = 0;
    for (; i + 4 <= count; i += 4) {
      for (std::uint32_t k = 0; k < 4; ++k) {
        const double d = nx * x[i + k] + ny * y[i + k] + nz * z[i + k];
        lo[k] = std::min(lo[k], d);
        hi[k] = std::max(hi[k], d);
      }
    }
    for (; i < count; ++i) {
      const double d = nx * x[i] + ny * y[i] + nz * z[i];
      lo[0] = std::min(lo[0], d);
      hi[0] = std::max(hi[0], d);
    }
    return {std::min(std::min(lo[0], lo[1]), std::min(lo[2], lo[3])),
            std::max(std::max(hi[0], hi[1]), std::max(hi[2], hi[3]))};
  }

  // The largest |coordinate| of the gathered vertices: the scale of their projections' rounding.
  double largestCoordinate() const {
    double m = 0.0;
    for (std::uint32_t i = 0; i < count; ++i) m = std::max({m, std::abs(x[i]), std::abs(y[i]), std::abs(z[i])});
    return m;
  }
};

// One side of a sphere pair as a support function in A's frame: the faceted patch of the sphere
// (its vertices, CollisionBody::spherePatchVertices) when it has one, else the sphere itself,
// which bounds whatever surface the sphere is responsible for. Both are conservative: they
// contain that surface, so an axis along which two sides do not overlap proves that the two
// spheres' triangles do not meet.
// A curved patch is bounded twice: by its sphere, and by its support vertices
// (CollisionBody::sphereSupportVertices) plus their slack; the smaller of the two supports holds.
struct PatchSide {
  const CollisionBody& body;
  std::uint32_t sphere;
  bool faceted;
  Vec3 centre;                    // sphere centre, A frame
  double radius;
  const Eigen::Matrix3d* rotToA;  // body frame -> A frame (null: body A itself)
  Vec3 shift;                     // translation body frame -> A frame
  mutable GatheredVertices gathered{};

  Vec3 toA(const Vec3& local) const { return rotToA ? Vec3(*rotToA * local + shift) : local; }

  // The same body's faceted patch of another sphere (its root: a whole convex body), same frame.
  PatchSide facetedAt(std::uint32_t other) const { return {body, other, true, centre, radius, rotToA, shift}; }

  // Its face planes in A's frame as half-spaces n . x <= support, the patch's extent along n.
  using HalfSpaces = std::array<std::pair<Vec3, double>, CollisionBody::kMaxSphereFaceNormals>;
  std::span<const std::pair<Vec3, double>> halfSpaces(HalfSpaces& out) const {
    const std::span<const Vec3f> faces = body.sphereFaceNormals(sphere);
    for (std::size_t k = 0; k < faces.size(); ++k) {
      const Vec3 f = rotToA ? Vec3(*rotToA * faces[k].cast<double>()) : Vec3(faces[k].cast<double>());
      out[k] = {f, extent(f).hi};
    }
    return {out.data(), faces.size()};
  }

  // The vertices that bound the side: the faceted patch's, else a curved patch's support vertices.
  std::span<const std::uint32_t> boundingVertices() const {
    return faceted ? body.spherePatchVertices(sphere) : body.sphereSupportVertices(sphere);
  }

  void gather() const {
    const std::span<const std::uint32_t> ids = boundingVertices();
    if (ids.size() > GatheredVertices::kCapacity) {
      gathered.count = GatheredVertices::kTooMany;
      return;
    }
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const Vec3 x = toA(body.mesh().vertices[ids[i]]);
      gathered.x[i] = x.x(), gathered.y[i] = x.y(), gathered.z[i] = x.z();
    }
    gathered.count = static_cast<std::uint32_t>(ids.size());
  }

  // The bounding vertices in A's frame; a faceted patch's (at most kMaxSpherePatchVertices) always fit.
  const GatheredVertices& gatheredVertices() const {
    if (gathered.count == GatheredVertices::kNotGathered) gather();
    return gathered;
  }

  // [min, max] of n . x over the bounding vertices (n in A's frame).
  Extent vertexExtent(const Vec3& n) const {
    if (gathered.count == GatheredVertices::kNotGathered) gather();
    Extent e{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    if (gathered.count == GatheredVertices::kTooMany) {
      const Vec3 nLocal = rotToA ? Vec3(rotToA->transpose() * n) : n;
      for (std::uint32_t i : boundingVertices()) {
        const double d = nLocal.dot(body.mesh().vertices[i]);
        e.lo = std::min(e.lo, d);
        e.hi = std::max(e.hi, d);
      }
      const double along = n.dot(shift);
      return {e.lo + along, e.hi + along};
    }
    return gathered.extent(n);
  }

  // [min, max] over the side of n . x, n in A's frame: its support along -n (negated) and n.
  Extent extent(const Vec3& n) const {
    if (faceted) return vertexExtent(n);
    const double c = n.dot(centre);
    if (body.sphereSupportVertices(sphere).empty()) return {c - radius, c + radius};
    const Extent e = vertexExtent(n);
    const double slack = body.sphereSupportSlack(sphere);
    return {std::max(c - radius, e.lo - slack), std::min(c + radius, e.hi + slack)};
  }
};

// Candidate axes of two faceted sides (A's frame) and both sides' projections on them, in the
// order leastOverlapNormal judges them: B's face normals, A's, then (a second set) the edge-edge
// cross products (A's edge direction outer, B's inner). Projected a vertex at a
// time across all axes, which the compiler vectorises: per axis and side, a faceted patch has
// only a few vertices (bunny-1500's leaves: ~4), too few for the per-axis loop of
// PatchSide::vertexExtent to pay for its set-up. min and max are exact, so the extents are the
// per-axis loop's bit for bit.
struct SatAxes {
  static constexpr std::uint32_t kMax = 2 * CollisionBody::kMaxSphereFaceNormals +
                                        CollisionBody::kMaxSphereEdgeDirections * CollisionBody::kMaxSphereEdgeDirections;
  double x[kMax], y[kMax], z[kMax];
  double loA[kMax], hiA[kMax], loB[kMax], hiB[kMax];
  double squaredLength[kMax];  // edge-edge axes, which are not unit vectors
  std::uint32_t count = 0;

  void add(const Vec3& n) { x[count] = n.x(), y[count] = n.y(), z[count] = n.z(), ++count; }

  void gatherFaceNormals(const PatchSide& sideA, const PatchSide& sideB, const Eigen::Matrix3d& rotAFromB) {
    for (const Vec3f& f : sideB.body.sphereFaceNormals(sideB.sphere)) add(rotAFromB * f.cast<double>());
    for (const Vec3f& f : sideA.body.sphereFaceNormals(sideA.sphere)) add(f.cast<double>());
  }

  // The edge-edge cross products as they are, not normalised, with their squared lengths.
  void gatherEdgeCrossProducts(const PatchSide& sideA, const PatchSide& sideB, const Eigen::Matrix3d& rotAFromB) {
    std::array<Vec3, CollisionBody::kMaxSphereEdgeDirections> edgesB;
    const std::span<const Vec3f> edgeDirsB = sideB.body.sphereEdgeDirections(sideB.sphere);
    for (std::size_t k = 0; k < edgeDirsB.size(); ++k) edgesB[k] = rotAFromB * edgeDirsB[k].cast<double>();
    for (const Vec3f& ea : sideA.body.sphereEdgeDirections(sideA.sphere)) {
      for (std::size_t k = 0; k < edgeDirsB.size(); ++k) {
        const Vec3 axis = ea.cast<double>().cross(edgesB[k]);
        squaredLength[count] = axis.squaredNorm();
        add(axis);
      }
    }
  }

  // [lo, hi] of n . v over the vertices, for every axis n.
  void project(const GatheredVertices& v, double* lo, double* hi) const {
    for (std::uint32_t k = 0; k < count; ++k) {
      lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (std::uint32_t i = 0; i < v.count; ++i) {
      const double vx = v.x[i], vy = v.y[i], vz = v.z[i];
      for (std::uint32_t k = 0; k < count; ++k) {
        const double d = x[k] * vx + y[k] * vy + z[k] * vz;
        lo[k] = std::min(lo[k], d);
        hi[k] = std::max(hi[k], d);
      }
    }
  }
};

// Separating-axis choice between two sphere patches of which at least one is faceted. Candidate
// axes: the face normals of the faceted patches (B's, and A's, tried both ways), the cross
// products of their body-edge directions when both are faceted (edge-edge axes), and, when one
// side is not faceted (a curved patch bounded by its sphere), the closest-feature-map normals of
// both spheres (nA, nB, B -> A): a sphere at a box edge is pushed along the edge's rounding, not
// along one of the faces. These are the candidate axes of the separating-axis test for convex
// polyhedra (Gottschalk et al. 1996 use the same test for OBBs). The chosen axis is the one
// along which the two sides overlap least, overlap(n) = support_B(n) - (-support_A(-n)): for a
// face resting on a face it is the face normal, whatever the spheres' centre line; where an
// edge of A crosses an edge of B both maps may return side faces, but along a side face the
// other patch overlaps by about its sphere's radius, along the resting face only by the
// penetration; a small body's sphere inside a large flat body's root sphere (a box on a floor)
// is pushed along the floor's top face, where the centre line is nearly horizontal. Axes with a
// negative overlap prove the sides apart (kApart): the sphere pair's overlap is looseness.
PatchAxis leastOverlapNormal(const PatchSide& sideA, const PatchSide& sideB, const Eigen::Matrix3d& rotAFromB,
                             const Vec3& nA, const Vec3& nB, Vec3& best) {
  if (!sideA.faceted && !sideB.faceted) return PatchAxis::kNotFaceted;
  double bestOverlap = std::numeric_limits<double>::infinity();
  bool apart = false;
  // Two faceted pieces of convex bodies' surfaces (not whole bodies): a normal n (B -> A) is a
  // way out only if A's piece has a face turned against n and B's piece a face turned along it.
  // Pieces are open, so their vertex sets also overlap little along directions that push A
  // through itself: a leaf patch on an icosphere's underside, over another icosphere, got its
  // own outward normal (pointing down, into the lower body) as the least-overlap axis, and the
  // line along that contact's normal crossed both bodies whole (issue 18's error-bound promise:
  // 58 % of cfm's contacts on two icospheres). Those directions are chosen only when no other is.
  const bool piecesOfConvexBodies = sideA.faceted && sideB.faceted && sideA.body.isConvexPolyhedron() &&
                                    sideB.body.isConvexPolyhedron() &&
                                    !(sideA.body.patchIsWholeConvexBody(sideA.sphere) &&
                                      sideB.body.patchIsWholeConvexBody(sideB.sphere));
  auto facesTheOtherPiece = [&](const Vec3& n) {
    if (!piecesOfConvexBodies) return true;
    const auto facesA = sideA.body.sphereFaceNormals(sideA.sphere);
    const auto facesB = sideB.body.sphereFaceNormals(sideB.sphere);
    return std::any_of(facesA.begin(), facesA.end(), [&](const Vec3f& f) { return f.cast<double>().dot(n) < 0.0; }) &&
           std::any_of(facesB.begin(), facesB.end(),
                       [&](const Vec3f& f) { return (rotAFromB * f.cast<double>()).dot(n) > 0.0; });
  };
  double fallbackOverlap = std::numeric_limits<double>::infinity();
  Vec3 fallback = Vec3::Zero();
  auto keep = [&](double overlap, const Vec3& n) {
    if (facesTheOtherPiece(n)) {
      if (overlap < bestOverlap) bestOverlap = overlap, best = n;
    } else if (overlap < fallbackOverlap) {
      fallbackOverlap = overlap, fallback = n;
    }
  };
  auto consider = [&](const Vec3& n) {  // n in A's frame; both n and -n are tried
    if (apart) return;  // one separating axis settles it
    const Extent a = sideA.extent(n), b = sideB.extent(n);
    const double alongN = b.hi - a.lo;   // push A along +n by this much to separate
    const double againstN = a.hi - b.lo; // or along -n by this much
    if (alongN < 0.0 || againstN < 0.0) {
      apart = true;  // the projections do not overlap: a separating axis
      return;
    }
    keep(alongN, n);
    keep(againstN, -n);
  };
  // The best axis, or the best of those that push a convex piece through itself if no other
  // was found.
  auto chosen = [&] {
    if (bestOverlap == std::numeric_limits<double>::infinity() && fallbackOverlap < bestOverlap) best = fallback;
    return PatchAxis::kChosen;
  };
  if (sideA.faceted && sideB.faceted) {
    // Both sides are vertex sets: the candidate axes are gathered, then projected in one pass
    // (SatAxes) and judged in the order above. The face axes first: a pair they prove apart
    // needs no edge-edge axes.
    const GatheredVertices& vertsA = sideA.gatheredVertices();
    const GatheredVertices& vertsB = sideB.gatheredVertices();
    SatAxes axes;
    axes.gatherFaceNormals(sideA, sideB, rotAFromB);
    axes.project(vertsA, axes.loA, axes.hiA);
    axes.project(vertsB, axes.loB, axes.hiB);
    for (std::uint32_t k = 0; k < axes.count; ++k) {
      const double alongN = axes.hiB[k] - axes.loA[k], againstN = axes.hiA[k] - axes.loB[k];
      if (alongN < 0.0 || againstN < 0.0) return PatchAxis::kApart;
      const Vec3 n(axes.x[k], axes.y[k], axes.z[k]);
      keep(alongN, n);
      keep(againstN, -n);
    }
    // The edge-edge axes are first projected as they are. An axis whose overlaps, divided by its
    // length, both exceed the best so far by more than rounding (kRoundingRel of the vertices'
    // largest coordinate) can neither separate nor win, and is passed over; the others are
    // normalised and judged exactly as the face axes. Choices are those of judging every axis
    // normalised; the square root and three divisions per axis, then a third of this function's
    // time, are left to the few that may matter.
    axes.count = 0;
    axes.gatherEdgeCrossProducts(sideA, sideB, rotAFromB);
    if (axes.count == 0) return chosen();
    axes.project(vertsA, axes.loA, axes.hiA);
    axes.project(vertsB, axes.loB, axes.hiB);
    constexpr double kRoundingRel = 1e-12;
    const double slack = kRoundingRel * std::max(vertsA.largestCoordinate(), vertsB.largestCoordinate());
    for (std::uint32_t k = 0; k < axes.count; ++k) {
      if (!piecesOfConvexBodies) {
        const double rawOverlap = std::min(axes.hiB[k] - axes.loA[k], axes.hiA[k] - axes.loB[k]);
        const double beaten = bestOverlap + slack;  // infinite before any axis: never passed over
        if (rawOverlap >= 0.0 && rawOverlap * rawOverlap >= beaten * beaten * axes.squaredLength[k]) continue;
      }
      const Vec3 axis(axes.x[k], axes.y[k], axes.z[k]);
      const double length = std::sqrt(axes.squaredLength[k]);  // Eigen's norm()
      if (length < 1e-6) continue;  // parallel edges: their axes are face normals already
      const Vec3 n = axis / length;
      const Extent a = vertsA.extent(n), b = vertsB.extent(n);
      const double alongN = b.hi - a.lo, againstN = a.hi - b.lo;
      if (alongN < 0.0 || againstN < 0.0) return PatchAxis::kApart;
      keep(alongN, n);
      keep(againstN, -n);
    }
    return chosen();
  }
  if (sideB.faceted) {
    for (const Vec3f& f : sideB.body.sphereFaceNormals(sideB.sphere)) consider(rotAFromB * f.cast<double>());
  }
  if (sideA.faceted) {
    for (const Vec3f& f : sideA.body.sphereFaceNormals(sideA.sphere)) consider(f.cast<double>());
  }
  consider(nB);  // one side curved: the maps' normals
  consider(nA);
  return apart ? PatchAxis::kApart : chosen();
}

// The vertex among `ids` of a side's mesh that reaches farthest along `dir` (A frame), in A's frame.
Vec3 extremeVertex(const PatchSide& side, std::span<const std::uint32_t> ids, const Vec3& dir) {
  Vec3 best = Vec3::Zero();
  double farthest = -std::numeric_limits<double>::infinity();
  for (std::uint32_t v : ids) {
    const Vec3 x = side.toA(side.body.mesh().vertices[v]);
    if (dir.dot(x) > farthest) farthest = dir.dot(x), best = x;
  }
  return best;
}

// Depth and point of a contact along a chosen normal n (A frame, B -> A) between two sides of
// which at least one is faceted: the sides overlap along n over [min_A(n), max_B(n)]; depth =
// max_B(n) - min_A(n), capped by the spheres' D&O depth (both bound the same thing from above;
// a sphere side overestimates its surface); the point is the D&O point moved along n onto the
// middle of that overlap (from a curved side's centre instead, see below) and, across n, clamped
// into the common extent of the two sides along
// two tangents (so it lies where both patches are, not beside the smaller one). For a box
// resting on a box or a floor this is the true penetration and a point in the contact face at
// every level, where the D&O point lies up to a sphere radius inside the upper box and its depth
// is the spheres' overlap. Returns false when the sides are apart along n.
bool patchDepthAndPoint(const PatchSide& sideA, const PatchSide& sideB, const Vec3& n, Contact& c) {
  const double maxB = sideB.extent(n).hi;
  const double minA = sideA.extent(n).lo;
  const double overlap = maxB - minA;
  if (overlap < 0.0) return false;
  c.depth = std::min(c.depth, overlap);
  // A curved side is its sphere here, whose support along the normal lies straight through its
  // centre: start there (the D&O point of a small sphere inside a floor's huge root sphere lies
  // on the nearly horizontal centre line, off to the side). Two curved patches with support
  // vertices start between their witnesses instead -- A's vertex reaching farthest toward B along
  // n and B's farthest toward A, where the two hulls overlap: from a sphere's centre the point
  // of two icospheres 2 % into each other landed up to 0.24 radii outside their lens (0.3 radii
  // off the centre line in the median), a contact where the bodies do not touch, and its lever
  // turned the zero-g bunnies of `clod experiment fidelity` the wrong way (docs/plausibility.md).
  Vec3 start = !sideA.faceted ? sideA.centre : !sideB.faceted ? sideB.centre : c.point;
  if (!sideA.faceted && !sideB.faceted) {
    const std::span<const std::uint32_t> idsA = sideA.body.sphereSupportVertices(sideA.sphere);
    const std::span<const std::uint32_t> idsB = sideB.body.sphereSupportVertices(sideB.sphere);
    if (!idsA.empty() && !idsB.empty()) start = 0.5 * (extremeVertex(sideA, idsA, -n) + extremeVertex(sideB, idsB, n));
  }
  Vec3 p = start + (0.5 * (maxB + minA) - n.dot(start)) * n;
  const Vec3 t1 = n.unitOrthogonal();
  const Vec3 t2 = n.cross(t1);
  for (const Vec3& t : {t1, t2}) {
    const Extent a = sideA.extent(t), b = sideB.extent(t);
    const double lo = std::max(a.lo, b.lo);
    const double hi = std::min(a.hi, b.hi);
    if (lo > hi) continue;  // no common extent along t (the sides overlap only along n)
    const double s = t.dot(p);
    p += (std::clamp(s, lo, hi) - s) * t;
  }
  c.point = p;
  return true;
}

// False when the support functions of two sides (patches or spheres) do not overlap along
// `axis`: a separating axis, the sides cannot touch.
bool curvedPatchesMayTouch(const PatchSide& sideA, const PatchSide& sideB, const Vec3& axis) {
  const Extent a = sideA.extent(axis), b = sideB.extent(axis);
  return b.hi - a.lo >= 0.0 && a.hi - b.lo >= 0.0;
}

// A rule-1 normal within 2 degrees of a face normal of a side becomes that face normal:
// the maps' normals carry the codec's error (up to ~0.95 deg for oct16), and the patch depth
// along a normal tilted by e grows by e times the patch's width (a box on a 4 m slab: 0.16 deg
// doubled the depth of a 0.01 m contact).
void snapToFaceNormal(const PatchSide& sideA, const PatchSide& sideB, const Eigen::Matrix3d& rotAFromB, Vec3& n) {
  // sphereFaceNormals: also for patches with too many vertices to be faceted (a finely
  // tessellated flat floor), empty for curved ones.
  for (const Vec3f& f : sideB.body.sphereFaceNormals(sideB.sphere)) {
    const Vec3 fA = rotAFromB * f.cast<double>();  // B's outward normal points toward A
    if (fA.dot(n) > kFaceMatchCos) {
      n = fA;
      return;
    }
  }
  for (const Vec3f& f : sideA.body.sphereFaceNormals(sideA.sphere)) {
    const Vec3 fA = -f.cast<double>();  // A's outward normal points toward B
    if (fA.dot(n) > kFaceMatchCos) {
      n = fA;
      return;
    }
  }
}

// The face of a faceted side that faces direction `toward` (A frame) most, if within 45 degrees:
// its plane (the patch's outermost one with that normal) and its corners (the patch vertices on
// that plane), in A's frame. False when no face of the patch turns that way (an edge or a corner
// leads).
bool facingFace(const PatchSide& side, const Vec3& toward, detail::FacePlane& plane, std::array<Vec3, 32>& corners,
                std::size_t& cornerCount) {
  constexpr double kMinFacingCos = 0.70710678118654752;  // cos 45 deg
  double best = kMinFacingCos;
  bool found = false;
  for (const Vec3f& f : side.body.sphereFaceNormals(side.sphere)) {
    const Vec3 fA = side.rotToA ? Vec3(*side.rotToA * f.cast<double>()) : Vec3(f.cast<double>());
    if (fA.dot(toward) > best) {
      best = fA.dot(toward);
      plane.normal = fA;
      found = true;
    }
  }
  if (!found) return false;
  std::span<const std::uint32_t> ids = side.body.spherePatchVertices(side.sphere);
  const TriangleMesh& mesh = side.body.mesh();
  cornerCount = 0;
  std::array<Vec3, 32> placed;
  plane.offset = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ids.size() && i < placed.size(); ++i) {
    placed[i] = side.rotToA ? Vec3(*side.rotToA * mesh.vertices[ids[i]] + side.shift) : mesh.vertices[ids[i]];
    plane.offset = std::max(plane.offset, plane.normal.dot(placed[i]));
  }
  // Vertices of one face agree to rounding; 1e-7 diagonals also takes a tessellated face whose
  // triangles' normals differ by the 1e-6 rad that CollisionBody counts as one normal.
  const double tolerance = 1e-7 * side.body.diagonal();
  for (std::size_t i = 0; i < ids.size() && i < placed.size(); ++i) {
    if (plane.normal.dot(placed[i]) >= plane.offset - tolerance) corners[cornerCount++] = placed[i];
  }
  return true;
}

// The supporting edge of a whole convex body along `toward` (A frame), for a side with no face
// turned that way (an edge on a face, two parallel edges): the body's vertices at its support
// height (within 1e-7 diagonals, as facingFace), as a "face" seen edge-on whose plane is
// perpendicular to `toward` through them. Only for a patch that is the whole convex body: there
// the vertices at the support height span the body's own supporting feature, so the segment
// lies on its surface and every point of it has that height (a sub-patch's extreme vertices may
// span a chord through the inside). False unless that feature has two or more vertices.
bool supportingEdge(const PatchSide& side, const Vec3& toward, detail::FacePlane& plane, std::array<Vec3, 32>& corners,
                    std::size_t& cornerCount) {
  if (!side.body.patchIsWholeConvexBody(side.sphere)) return false;
  std::span<const std::uint32_t> ids = side.body.spherePatchVertices(side.sphere);
  const TriangleMesh& mesh = side.body.mesh();
  std::array<Vec3, 32> placed;
  plane.normal = toward;
  plane.offset = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ids.size() && i < placed.size(); ++i) {
    placed[i] = side.toA(mesh.vertices[ids[i]]);
    plane.offset = std::max(plane.offset, toward.dot(placed[i]));
  }
  const double tolerance = 1e-7 * side.body.diagonal();
  cornerCount = 0;
  for (std::size_t i = 0; i < ids.size() && i < placed.size(); ++i) {
    if (toward.dot(placed[i]) >= plane.offset - tolerance) corners[cornerCount++] = placed[i];
  }
  return cornerCount >= 2;
}

// The single contact of two faceted patches whose facing features do not overlap in an area (a
// corner in a face, two crossing edges): where those features touch, on the plane midway between
// the two sides' supports along the normal. A side's feature is its vertices within a rounding
// tolerance of its support along n: one vertex (a corner) is the point; two edges (two vertices
// each) cross at the points of their lines nearest each other across the normal. patchDepthAndPoint
// places the point from the bounding spheres' centre line, clamped to the sides' common extent: a
// cube standing on a corner 0.2 off another cube's centre had its contact 0.1 off, under the
// middle of the line to the corner, so the lever of the one force holding it was half the true
// one; and the line along the normal through the point of two crossing edges missed one body
// (issue 18's error-bound promise: 94 % of the box pair's contacts). False (the point is kept)
// where either feature is larger, or the edges are parallel (facedPatchContacts answers those).
// Only for sides that are whole convex bodies: a sub-patch's extreme vertex along n may be a
// vertex of its rim, not where the bodies touch (on two icospheres' leaf patches the promise
// then held for 32 % of cfm's contacts instead of 58 %).
bool touchingFeaturesPoint(const PatchSide& sideA, const PatchSide& sideB, const Vec3& n, Vec3& point) {
  const double maxB = sideB.extent(n).hi;
  const double minA = sideA.extent(n).lo;
  auto feature = [&](const PatchSide& side, double support, double sign, std::array<Vec3, 2>& ends) {
    const double tolerance = 1e-7 * side.body.diagonal();
    std::size_t count = 0;
    for (std::uint32_t id : side.body.spherePatchVertices(side.sphere)) {
      const Vec3 v = side.toA(side.body.mesh().vertices[id]);
      if (sign * (n.dot(v) - support) < -tolerance) continue;
      if (count == 2) return std::size_t{3};
      ends[count++] = v;
    }
    return count;
  };
  std::array<Vec3, 2> a, b;
  const std::size_t countB = feature(sideB, maxB, 1.0, b);
  const std::size_t countA = feature(sideA, minA, -1.0, a);
  Vec3 q;
  if (countB == 1) {
    q = b[0];
  } else if (countA == 1) {
    q = a[0];
  } else if (countA == 2 && countB == 2) {
    // Across the normal: a(s) - b(t) perpendicular to both edges within the plane of n.
    auto across = [&](const Vec3& v) { return Vec3(v - n.dot(v) * n); };
    const Vec3 da = across(a[1] - a[0]), db = across(b[1] - b[0]), r = across(a[0] - b[0]);
    const double aa = da.dot(da), bb = db.dot(db), ab = da.dot(db);
    const double det = aa * bb - ab * ab;
    if (!(det > 1e-12 * aa * bb)) return false;
    const double sA = std::clamp((ab * db.dot(r) - bb * da.dot(r)) / det, 0.0, 1.0);
    const double sB = std::clamp((aa * db.dot(r) - ab * da.dot(r)) / det, 0.0, 1.0);
    q = 0.5 * (a[0] + sA * (a[1] - a[0]) + b[0] + sB * (b[1] - b[0]));
  } else {
    return false;
  }
  point = q + (0.5 * (maxB + minA) - n.dot(q)) * n;
  return true;
}

// Contacts of two faceted patches along the chosen normal c.normal (A frame): where a face of
// B faces A and a face of A faces B, the corners of the faces' overlap (detail::faceOverlapPoints),
// each with its own depth (capped, like the single contact's, by the spheres' D&O depth) and
// the pair's error bound -- a support area instead of one point at its centre, so that friction
// and tilt have a lever arm at every level (a box sliding on a root-level contact at its face
// centre tipped over). Where a side is a whole convex body that turns an edge toward the other
// (supportingEdge), the edge stands in for its face: an edge on a face gets the two ends of its
// part over the face, two parallel edges the ends of their common part (one contact in the
// middle of a box's edge let the box spin about the normal and roll along the edge). Crossing
// edges and corners keep the single contact. Returns false when it added nothing.
bool facedPatchContacts(const PatchSide& sideA, const PatchSide& sideB, const Contact& c, std::vector<Contact>& out) {
  detail::FacePlane planeA, planeB;
  std::array<Vec3, 32> cornersA, cornersB;
  std::size_t countA = 0, countB = 0;
  const bool faceB = facingFace(sideB, c.normal, planeB, cornersB, countB);
  const bool faceA = facingFace(sideA, -c.normal, planeA, cornersA, countA);
  if (!faceB && !supportingEdge(sideB, c.normal, planeB, cornersB, countB)) return false;
  if (!faceA && !supportingEdge(sideA, -c.normal, planeA, cornersA, countA)) return false;
  std::array<detail::FacePoint, detail::kMaxFaceOverlapPoints> points;
  const std::size_t count = detail::faceOverlapPoints(c.normal, planeB, std::span<const Vec3>(cornersB.data(), countB),
                                                      planeA, std::span<const Vec3>(cornersA.data(), countA), points);
  if (count < 2) return false;
  for (std::size_t i = 0; i < count; ++i) {
    Contact ci = c;
    ci.point = points[i].point;
    ci.depth = std::min(points[i].depth, c.depth);
    out.push_back(ci);
  }
  return true;
}

// Contacts of a curved patch on a face of a convex body's faceted patch (a mesh dropped on a box,
// at any level): every support vertex of the curved patch (CollisionBody::sphereSupportVertices),
// and every inner vertex of a non-convex one (sphereInnerVertices), that lies behind all of the
// faceted patch's face planes is
// inside it, and gives a contact at its depth below the face that faces it along the chosen
// normal -- the points the body really rests on, with their own depths, where the single contact
// of the pair stood at its sphere's centre with the sphere's depth (a bunny resting on one
// root-level contact rolled over and sank 20 % of its diagonal). Error bound 0: each contact's
// depth is its vertex's exact depth below that face; a curved patch's support slack says only
// that a vertex left out of the set may lie deeper, which a finer level finds (as the solver
// corrected the depth only beyond that slack, a bunny rested 1.35 % of its diagonal deep at 16
// tests per frame). Only against convex bodies, for the reason facedPatchContacts gives.
// Returns false when it added nothing.
bool vertexOnFaceContacts(const PatchSide& patch, const PatchSide& faceted, const Vec3& toward, const Contact& c,
                          std::vector<Contact>& out) {
  // A curved patch's vertex inside a convex body is pushed out through the nearest face its own
  // surface normal faces (within 60 degrees: an edge's or a corner's vertex of a tessellated box
  // faces two or three). The face the
  // pair's axis faces can be a side face: a slab's patch holding flat ground and the foot of a
  // bump, seen from a box sliding toward the bump, overlaps the box least along the box's front
  // face, and its vertices pushed the box back through that face (it then jumped the bump, 767 mm
  // rms off the exact track). Inside: behind every face of the whole body (the root's patch; the
  // leaf's faces if the root has too many).
  constexpr double kMinFacingCos = 0.5;  // cos 60 deg
  constexpr double kMaxDetourRel = 0.02;
  const std::uint32_t root = 0;
  const bool whole = !faceted.body.sphereFaceNormals(root).empty();
  const PatchSide body = faceted.facetedAt(whole ? root : faceted.sphere);
  const std::span<const Vec3f> faces = faceted.body.sphereFaceNormals(body.sphere);
  PatchSide::HalfSpaces halfSpaceStore;
  const std::span<const std::pair<Vec3, double>> halfSpaces = body.halfSpaces(halfSpaceStore);
  const double tolerance = 1e-9 * (patch.body.diagonal() + faceted.body.diagonal());
  const bool facetedIsB = toward.dot(c.normal) > 0.0;
  const std::size_t before = out.size();
  // For the edge-on-surface rule below: the depth-weighted sum of the pressed vertices' outward
  // normals, the face the deepest one leaves through, and per face how far behind its plane the
  // patch's vertices outside the body reach.
  Vec3 normalSum = Vec3::Zero();
  double deepest = 0.0;
  std::size_t deepestFace = 0;
  std::array<double, CollisionBody::kMaxSphereFaceNormals> outsideBehind;
  outsideBehind.fill(-std::numeric_limits<double>::infinity());
  // A faceted patch's own vertices (few; its support set is empty), else the curved patch's
  // support set and its inner vertices (CollisionBody::sphereInnerVertices, only a non-convex
  // patch has them): the flank of a bump can be inside the convex body while the hull's vertices
  // (the bump's top and the patch's rim) are not. With the hull alone a box sliding onto a bump
  // met no contact until the bump's top was inside it, 4 cm deep (`clod experiment
  // flat-contact`: 239 -> 56 mm rms from the exact track).
  const std::span<const std::uint32_t> lists[2] = {
      patch.faceted ? patch.body.spherePatchVertices(patch.sphere) : patch.body.sphereSupportVertices(patch.sphere),
      patch.faceted ? std::span<const std::uint32_t>() : patch.body.sphereInnerVertices(patch.sphere)};
  for (const std::span<const std::uint32_t> candidates : lists) {
    for (std::uint32_t id : candidates) {
      const Vec3 v = patch.toA(patch.body.mesh().vertices[id]);
      // Behind a leaf's few face planes is a cone, not the body: only a vertex within the leaf's
      // sphere can be inside its piece (an L's far corners, 2.5 m away, lay behind the faces of an
      // icosphere's leaf and pushed the ball 0.4-0.9 m "deep" along them; it rolled 60 cm off a
      // wall it rested against, cfm at 1,024 tests and unlimited).
      if (!whole && (v - faceted.centre).squaredNorm() > faceted.radius * faceted.radius) continue;
      const Vec3 normal = patch.rotToA ? Vec3(*patch.rotToA * patch.body.vertexNormal(id)) : patch.body.vertexNormal(id);
      bool inside = true;
      std::size_t pressed = faces.size(), nearest = 0;
      double depth = std::numeric_limits<double>::infinity(), nearestDepth = depth;
      std::array<double, CollisionBody::kMaxSphereFaceNormals> behind;
      for (std::size_t k = 0; k < faces.size(); ++k) {
        const double d = halfSpaces[k].second - halfSpaces[k].first.dot(v);
        behind[k] = d;
        inside = inside && d > tolerance;
        if (-halfSpaces[k].first.dot(normal) >= kMinFacingCos && d < depth) depth = d, pressed = k;
        if (d < nearestDepth) nearestDepth = d, nearest = k;
      }
      if (!inside) {
        // Only where the surface rises toward the body: beyond a face it faces (a bump's near
        // flank in front of a box), not falling away from it (the far flank past the bump's top).
        bool rising = false;
        for (std::size_t k = 0; k < faces.size(); ++k) rising = rising || (behind[k] < 0.0 && halfSpaces[k].first.dot(normal) < 0.0);
        if (rising)
          for (std::size_t k = 0; k < faces.size(); ++k) outsideBehind[k] = std::max(outsideBehind[k], behind[k]);
        continue;
      }
      // No face it faces, or one much deeper than the nearest face: the nearest face. A vertex
      // arrives at most a fraction of a percent of the smaller diagonal deep per substep (the
      // world's arrival rule), so an exit kMaxDetourRel deeper than the nearest one is not where it
      // came in: an open bunny's rim vertex, whose normal lies along the floor, faced the box's side
      // face 0.3-2 m away, and the bunny was pushed sideways into the box (a drop ended 16 % of its
      // diagonal inside).
      const double detour = kMaxDetourRel * std::min(patch.body.diagonal(), faceted.body.diagonal());
      if (pressed == faces.size() || depth > nearestDepth + detour) pressed = nearest, depth = nearestDepth;
      const Vec3& exit = halfSpaces[pressed].first;
      Contact ci = c;
      ci.normal = facetedIsB ? exit : Vec3(-exit);
      ci.point = v + 0.5 * depth * exit;
      ci.depth = depth;
      normalSum += depth * normal;
      if (depth > deepest) deepest = depth, deepestFace = pressed;
      // Exact only against the whole body's faces: "behind every face plane of a leaf's patch" is
      // no proof of being inside (an icosphere's leaf holds a few of its 320 faces; a vertex
      // behind them may lie outside the body), so there the pair's bound stays (measured:
      // tests/narrowphase/error_bound_test.cpp, docs/narrow-phase.md "Error bounds").
      ci.errorBound = whole ? 0.0 : c.errorBound;
      out.push_back(ci);
    }
  }
  // Edge on surface. Where the patch also reaches behind the deepest vertex's exit plane outside
  // the body, its surface passes under an edge of the body (a box's front edge on a bump's flank,
  // 4-15 mm deep, the bump rising in front of the box): pushing each vertex out through the
  // face lifted the box straight up where the exact model pushes it back along the flank, and
  // it crossed the bump without turning (flat-contact: 7 deg heading error). Then the vertices leave
  // along the patch's own surface direction instead -- the depth-weighted mean of their outward
  // normals, a one-sided estimate of the intersection volume's gradient (the exact model's
  // normal) -- each at the depth it needs along it. A patch meeting one face only (a bunny on a
  // floor, whose rim vertices' normals lie along the floor) keeps the faces. Where the mean
  // turns more than 60 deg from a vertex's face, that vertex keeps its face.
  const bool underAnEdge = out.size() > before && outsideBehind[deepestFace] > tolerance;
  const double sumLength = normalSum.norm();
  if (underAnEdge && sumLength > 0.0) {
    const Vec3 axis = -normalSum / sumLength;  // the direction the patch's vertices leave along
    for (std::size_t i = before; i < out.size(); ++i) {
      Contact& ci = out[i];
      const Vec3 exit = facetedIsB ? ci.normal : Vec3(-ci.normal);
      if (axis.dot(exit) < kMinFacingCos) continue;
      const Vec3 v = ci.point - 0.5 * ci.depth * exit;
      double along = std::numeric_limits<double>::infinity();  // travel along axis to leave the body
      for (std::size_t k = 0; k < faces.size(); ++k) {
        const double rate = halfSpaces[k].first.dot(axis);
        if (rate > 1e-9) along = std::min(along, (halfSpaces[k].second - halfSpaces[k].first.dot(v)) / rate);
      }
      if (!std::isfinite(along)) continue;
      ci.normal = facetedIsB ? axis : Vec3(-axis);
      ci.depth = along;
      ci.point = v + 0.5 * along * axis;
    }
  }
  return out.size() > before;
}

// The parameter interval [lo, hi] of the segment from `from` to `to`, projected along n, over
// triangle t (three half-lines); empty when hi < lo.
std::pair<double, double> segmentOverTriangle(const TriangleMesh& mesh, std::uint32_t t, const Vec3& n,
                                              const Vec3& from, const Vec3& to) {
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = mesh.corner(t, k), b = mesh.corner(t, (k + 1) % 3);
    const double g0 = n.dot((b - a).cross(from - a)), g1 = n.dot((b - a).cross(to - a));
    // g(s) = g0 + s (g1 - g0) >= 0 on the triangle's side of edge ab.
    if (g1 == g0) {
      if (g0 < 0.0) hi = -1.0;
    } else if (g1 > g0) {
      lo = std::max(lo, -g0 / (g1 - g0));
    } else {
      hi = std::min(hi, -g0 / (g1 - g0));
    }
  }
  return {lo, hi};
}

// Along the segment from `from` to `to` projected along n onto the plane (normal n, offset
// n . x = offset) of `triangles` (`from` over one of them), the parameter in [0, 1] where it
// first leaves the body's flat surface there: 1 when it never does. The surface is the union of
// `triangles` and the triangles connected to them across edges in the same plane that the
// segment passes over -- a floor's pieces are the sphere-tree's leaves, and the rim a box
// overhangs may lie in another leaf than the corner over the floor: stopping at the leaf's own
// border put the crossing inside the floor, where it holds nothing up. At most kMaxWalk
// triangles are followed; beyond them the crossing comes early (still a point of the overlap).
double leavesFlatSurfaceAt(const CollisionBody& body, std::span<const std::uint32_t> triangles, const Vec3& n,
                           double offset, double tolerance, const Vec3& from, const Vec3& to) {
  constexpr std::size_t kMaxWalk = 256;
  struct Over {
    std::uint32_t triangle;
    double lo, hi;
  };
  thread_local std::vector<Over> over;  // scratch: no allocation per query once warm
  over.clear();
  const TriangleMesh& mesh = body.mesh();
  auto visit = [&](std::uint32_t t) {
    if (over.size() >= kMaxWalk) return;
    for (const Over& o : over)
      if (o.triangle == t) return;
    const auto [lo, hi] = segmentOverTriangle(mesh, t, n, from, to);
    // Touching (a segment through a shared vertex) counts: the walk goes on through it.
    if (hi >= lo - 1e-12) over.push_back({t, lo, hi});
  };
  for (std::uint32_t t : triangles) visit(t);
  auto inPlane = [&](std::uint32_t t) {
    return mesh.triangleNormal(t).dot(n) > 1.0 - 1e-9 && std::abs(n.dot(mesh.corner(t, 0)) - offset) <= tolerance;
  };
  for (std::size_t i = 0; i < over.size(); ++i)  // breadth first over the surface the segment crosses
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t next = body.triangleNeighbour(over[i].triangle, k);
      if (next != CollisionBody::kNoNeighbour && inPlane(next)) visit(next);
    }
  std::sort(over.begin(), over.end(), [](const Over& x, const Over& y) { return x.lo < y.lo; });
  double reach = 0.0;
  for (const Over& o : over) {
    if (o.lo > reach + 1e-12) break;
    reach = std::max(reach, o.hi);
  }
  return std::min(reach, 1.0);
}

// A patch's bounding vertices (a faceted patch's corners, a curved patch's support vertices: its
// hull, which holds its deepest points along any direction) behind a flat patch (all its
// triangles in one plane) of an open non-convex body, each over one of that patch's triangles:
// the plane is the surface there, so a vertex's depth below it is its exact penetration, along
// the plane's normal (error bound 0). A flat piece
// of a floor with more vertices than a faceted patch keeps counted as a curved patch, bounded by
// its sphere: a box resting on one bottom edge, 1 mm into the floor, got contacts along the
// floor's normal at the floor sphere's centre and across the box's underside, 0.2-0.3 m from the
// edge, with the spheres' error bound; their friction turned the box the wrong way over the
// flat-contact bump (docs/narrow-phase.md, "Flat patches"). Returns false when it added nothing.
bool cornersOverFlatPatchContacts(const PatchSide& flat, const PatchSide& other, bool flatIsB, const Contact& c,
                                  std::vector<Contact>& out) {
  const Vec3 nLocal = flat.body.sphereFaceNormals(flat.sphere)[0].cast<double>();
  const Vec3 n = flat.rotToA ? Vec3(*flat.rotToA * nLocal) : nLocal;  // outward, A frame
  const TriangleMesh& mesh = flat.body.mesh();
  const std::span<const std::uint32_t> triangles = flat.body.sphereTree().triangles(flat.sphere);
  if (triangles.empty()) return false;
  const double offsetLocal = nLocal.dot(mesh.corner(triangles[0], 0));
  const double tolerance = 1e-9 * (flat.body.diagonal() + other.body.diagonal());
  const double planeTolerance = 1e-7 * flat.body.diagonal();  // a floor's pieces written to 9 digits are one plane
  const std::size_t before = out.size();
  auto addContact = [&](const Vec3& v, double depth) {
    Contact ci = c;
    ci.normal = flatIsB ? n : Vec3(-n);
    ci.point = v + 0.5 * depth * n;
    ci.depth = depth;
    ci.errorBound = 0.0;
    out.push_back(ci);
  };
  // The vertices behind the plane: A frame, the flat body's frame, depth, over a triangle.
  struct Behind {
    Vec3 v, local;
    double depth;
    bool over;
  };
  std::array<Behind, CollisionBody::kMaxSpherePatchVertices> behind;
  std::size_t count = 0;
  for (std::uint32_t id : other.boundingVertices()) {
    const Vec3 v = other.toA(other.body.mesh().vertices[id]);
    const Vec3 vLocal = flat.rotToA ? Vec3(flat.rotToA->transpose() * (v - flat.shift)) : v;  // flat body's frame
    const double depth = offsetLocal - nLocal.dot(vLocal);
    if (!(depth > tolerance)) continue;
    const Vec3 onPlane = vLocal + depth * nLocal;  // the corner's foot on the plane
    bool over = false;
    for (std::size_t k = 0; k < triangles.size() && !over; ++k) {
      const Vec3 a = mesh.corner(triangles[k], 0), b = mesh.corner(triangles[k], 1), d = mesh.corner(triangles[k], 2);
      over = nLocal.dot((b - a).cross(onPlane - a)) >= 0.0 && nLocal.dot((d - b).cross(onPlane - b)) >= 0.0 &&
             nLocal.dot((a - d).cross(onPlane - d)) >= 0.0;
    }
    if (other.faceted && count < behind.size()) behind[count++] = {v, vLocal, depth, over};
    if (over) addContact(v, depth);
  }
  // Where the patch reaches past the piece's rim (a box overhanging a table's edge), the corners
  // over it are one side of the overlap only: the other side lies where the box's underside
  // crosses the rim. With the inner corners alone the box turned about them and fell off the
  // table, at every budget (cfm, exact's fallback). So between a corner over the piece and one
  // behind the plane but past its rim, the point where the segment's foot leaves the piece's
  // triangles is a contact too; the segment lies in the convex patch, so its depth there (linear
  // along it) is the patch's penetration at that point or less. Faceted patches only (at most
  // kMaxSpherePatchVertices corners); a curved patch's support vertices stand for its hull.
  for (std::size_t i = 0; i < count; ++i) {
    if (!behind[i].over) continue;
    for (std::size_t j = 0; j < count; ++j) {
      if (behind[j].over) continue;
      const double leaves = leavesFlatSurfaceAt(flat.body, triangles, nLocal, offsetLocal, planeTolerance,
                                                behind[i].local, behind[j].local);
      if (!(leaves < 1.0)) continue;
      addContact(behind[i].v + leaves * (behind[j].v - behind[i].v),
                 (1.0 - leaves) * behind[i].depth + leaves * behind[j].depth);
    }
  }
  return out.size() > before;
}

// A face of N that a vertex of the other patch lies on (or within flushReach of), facing the way
// the patch's own surface faces there: the vertex is the patch's farthest point along the face's
// normal, so the patch lies behind the face's plane as N does. The face is not where the two
// bodies press (detail::FlushFaces); the surface past it is.
struct FlushContext {
  const PatchSide& nonConvex;
  const PatchSide& wholeBody;  // the convex body's root patch: a leaf's extent is not the body's
  Vec3 vertex;                 // A frame
  double tolerance;
};

bool isFlushFace(const void* context, std::uint32_t triangle) {
  const FlushContext& f = *static_cast<const FlushContext*>(context);
  const Vec3 nLocal = f.nonConvex.body.mesh().triangleNormal(triangle);
  const Vec3 n = f.nonConvex.rotToA ? Vec3(*f.nonConvex.rotToA * nLocal) : nLocal;
  return f.wholeBody.vertexExtent(n).hi <= n.dot(f.vertex) + f.tolerance;
}

// Vertices of a patch (a convex body's, faceted or curved, or a second closed non-convex body's)
// that lie inside a closed non-convex body N, by N's exact signed distance
// (detail::exactBodyFieldWithin: nearest triangle, signed by the angle-weighted pseudonormal).
// Each is a contact at its own depth, along the field's gradient (out through the nearest
// surface), error bound 0. The separating-axis choice treats N's patch as its convex hull, and a
// box standing in the hull's pocket (on the floor of an L-shaped body, beside its wall) overlaps
// that hull least downward, through the floor: its contact pushed the box into the floor, 0.999
// deep, and at 16-64 tests per frame it fell through (cfm and exact alike). Each vertex is probed
// once per answer (`probed`: the patch body's vertices tested so far, with the answer), by the
// pairs whose N sphere holds it; its contact is added once. Returns whether a vertex in this
// pair's sphere is inside.
bool cornersInsideContacts(const PatchSide& nonConvex, const PatchSide& convex, bool convexIsB, const Contact& c,
                           detail::ContainmentScratch& scratch, std::vector<ProbedCorner>& probed,
                           std::vector<Contact>& out) {
  const TriangleMesh& mesh = convex.body.mesh();
  const double tolerance = 1e-9 * (nonConvex.body.diagonal() + convex.body.diagonal());
  // A vertex deeper in N than its patch's sphere is large is found by a coarser pair, or is the
  // containment rule's case; searching only that far keeps a vertex far from N's surface at a
  // few box tests (with the whole body's radius, the 200-body bin's p99 frame doubled).
  const double reach = convex.radius;
  // Flush, or set in from the face by up to 1e-3 of the smaller diagonal (a resting body's drift):
  // the face's field there is the distance back to flush, not a penetration.
  const double flushReach = 1e-3 * std::min(nonConvex.body.diagonal(), convex.body.diagonal());
  // Only a convex polyhedron's whole extent says which side of a face its material lies on (a
  // box's bottom-face leaf lies behind the floor's plane too, and the floor was skipped).
  const bool flushFaces = convex.body.isConvexPolyhedron() && !convex.body.spherePatchVertices(0).empty();
  const PatchSide wholeBody = convex.facetedAt(0);
  bool anyInside = false;
  // A faceted patch's vertices; a curved patch's support vertices and, on a non-convex body, its
  // inner vertices (the flank of a bump lies between the hull's).
  const std::span<const std::uint32_t> lists[2] = {
      convex.boundingVertices(),
      convex.faceted ? std::span<const std::uint32_t>() : convex.body.sphereInnerVertices(convex.sphere)};
  for (const std::span<const std::uint32_t> candidates : lists)
  for (std::uint32_t id : candidates) {
    const Vec3 v = convex.toA(mesh.vertices[id]);
    if ((v - nonConvex.centre).squaredNorm() > nonConvex.radius * nonConvex.radius) continue;
    const auto seen = std::find_if(probed.begin(), probed.end(), [id](const ProbedCorner& p) { return p.vertex == id; });
    if (seen != probed.end()) {
      anyInside = anyInside || seen->inside;
      continue;
    }
    const Vec3 local = nonConvex.rotToA ? Vec3(nonConvex.rotToA->transpose() * (v - nonConvex.shift)) : v;
    const FlushContext context{nonConvex, wholeBody, v, tolerance};
    const detail::FlushFaces flush{flushReach, &context, &isFlushFace};
    detail::FieldValue f;
    const bool inside = detail::exactBodyFieldWithin(nonConvex.body, local, reach, scratch, f, flushFaces ? &flush : nullptr) &&
                        f.distance < -tolerance;
    probed.push_back({id, inside, v});
    if (!inside) continue;
    anyInside = true;
    const Vec3 exit = nonConvex.rotToA ? Vec3(*nonConvex.rotToA * f.gradient) : f.gradient;  // A frame
    Contact ci = c;
    ci.depth = -f.distance;
    ci.normal = convexIsB ? Vec3(-exit) : exit;  // the convex body leaves along exit
    ci.point = v + 0.5 * ci.depth * exit;
    ci.errorBound = 0.0;
    out.push_back(ci);
    probed.back().contact = ci;
    probed.back().exit = exit;
  }
  return anyInside;
}

// Where a convex body's edge leaves a closed non-convex body N between a corner inside N and one
// outside, the overlap has a corner too: a box standing over the edge of an L-shaped body's floor
// (or of a shelf, a step) had contacts at its inner corners only, turned about them and fell off,
// with cfm and exact at every budget. For each such pair of probed corners whose outer corner lies
// behind the inner corner's exit plane (so the segment runs under N's surface there, not up
// through it), the first crossing of N's surface along the segment (a ray cast on N's triangles)
// is a contact with the inner corner's normal, at the depth of that plane over it, where N's
// surface is that plane out to the crossing. The segment
// lies in the convex body, so that depth is the body's penetration there or less. Once per answer,
// after every pair has probed its corners (`probed`: the convex body's). Returns whether it added any.
bool edgeExitContacts(const CollisionBody& nonConvex, const Pose& xfNFromA, const CollisionBody& convex,
                      const Pose& xfAFromConvex, const std::vector<ProbedCorner>& probed, double tolerance,
                      detail::ContainmentScratch& scratch, std::vector<Contact>& out) {
  const std::size_t before = out.size();
  const double surfaceTolerance = 1e-6 * (nonConvex.diagonal() + convex.diagonal());  // rounding of a ray hit
  // The outer corner may lie beyond every sphere of N that probed corners (a leaf at the rim).
  const std::span<const std::uint32_t> corners = convex.spherePatchVertices(0);
  for (const ProbedCorner& in : probed) {
    if (!in.inside) continue;
    for (const std::uint32_t id : corners) {
      const auto seen = std::find_if(probed.begin(), probed.end(), [id](const ProbedCorner& p) { return p.vertex == id; });
      if (seen != probed.end() && seen->inside) continue;
      const Vec3 run = xfAFromConvex.apply(convex.mesh().vertices[id]) - in.point;
      if (!(in.exit.dot(run) < in.contact.depth - tolerance)) continue;  // it rises out of N first
      const Vec3 from = xfNFromA.apply(in.point);
      const detail::RayHit hit = detail::firstHit(nonConvex, from, xfNFromA.rotation * run, 0.0, 1.0);
      if (!hit.hit || !hit.leaving) continue;
      const Vec3 crossing = in.point + hit.t * run;
      const double depth = in.contact.depth - in.exit.dot(crossing - in.point);
      if (!(depth > tolerance)) continue;
      // Only where N's surface is that plane out to the crossing (the foot lies on N): on a
      // curved body the plane's depth there is not the penetration (box on spot: the error-bound
      // rate fell 1.2-2.4 points).
      detail::FieldValue foot;
      if (!detail::exactBodyFieldWithin(nonConvex, xfNFromA.apply(crossing + depth * in.exit), surfaceTolerance, scratch, foot) ||
          std::abs(foot.distance) > surfaceTolerance)
        continue;
      Contact c = in.contact;
      c.depth = depth;
      c.point = crossing + 0.5 * depth * in.exit;
      out.push_back(c);
    }
  }
  return out.size() > before;
}

// Where the edges of a faceted patch of N pass through a convex polyhedron O with none of their
// vertices inside it (a box tipped over the edge of a step rests on that edge): each edge's part
// inside O (the segment clipped by O's face planes) ends on O's surface, and those ends are the
// contact, each at the depth O must travel along the pair's axis for the end to leave it, with
// the pair's error bound (the axis is still the patches' hulls' choice: two faces touching at
// depth 0 can pick a side face's axis, 0.3 m deep). The pair's separating-axis contact stood at
// the spheres' D&O point instead, up to a sphere away from the edge -- under the step's top,
// where it held the tipping box up (cfm at 256 tests and unlimited: a box 2-5 cm past the edge
// stuck, tilted). O must be a whole convex polyhedron (its root's face planes are its
// half-spaces). `convexIsB`: O is body B. Returns whether it added any.
bool edgesThroughConvexContacts(const PatchSide& faceted, const PatchSide& convex, bool convexIsB, const Contact& c,
                                std::vector<Contact>& out) {
  PatchSide::HalfSpaces halfSpaceStore;
  const std::span<const std::pair<Vec3, double>> halfSpaces = convex.facetedAt(0).halfSpaces(halfSpaceStore);
  if (halfSpaces.empty()) return false;
  const Vec3 leave = convexIsB ? Vec3(-c.normal) : c.normal;  // O's way out
  const double tolerance = 1e-9 * (faceted.body.diagonal() + convex.body.diagonal());
  // How far O travels along `leave` before q (fixed) leaves it through a face that faces q's way
  // out (within 60 deg): an end lies on the side face that clipped it, which a tilt of 1e-3 rad
  // would otherwise make its exit at depth 0.
  constexpr double kMinFacingCos = 0.5;
  auto travel = [&](const Vec3& q) {
    double along = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < halfSpaces.size(); ++k) {
      const double rate = -halfSpaces[k].first.dot(leave);
      if (rate >= kMinFacingCos) along = std::min(along, (halfSpaces[k].second - halfSpaces[k].first.dot(q)) / rate);
    }
    return along;
  };
  const TriangleMesh& mesh = faceted.body.mesh();
  const std::size_t before = out.size();
  for (std::uint32_t t : faceted.body.sphereTree().triangles(faceted.sphere)) {
    for (int k = 0; k < 3; ++k) {
      // (An edge of two triangles of the patch comes twice; the manifold merges its ends.)
      const std::uint32_t i = mesh.triangles[t][k], j = mesh.triangles[t][(k + 1) % 3];
      const Vec3 p0 = faceted.toA(mesh.vertices[i]), p1 = faceted.toA(mesh.vertices[j]);
      double t0 = 0.0, t1 = 1.0;
      for (std::size_t h = 0; h < halfSpaces.size() && t0 < t1; ++h) {
        const double g0 = halfSpaces[h].second - halfSpaces[h].first.dot(p0);
        const double g1 = halfSpaces[h].second - halfSpaces[h].first.dot(p1);
        if (g0 < 0.0 && g1 < 0.0) t1 = -1.0;
        else if (g0 < 0.0) t0 = std::max(t0, g0 / (g0 - g1));
        else if (g1 < 0.0) t1 = std::min(t1, g0 / (g0 - g1));
      }
      if (!(t1 - t0 > 1e-9)) continue;
      for (const double at : {t0, t1}) {
        if (at <= 0.0 || at >= 1.0) continue;  // the edge's own vertex: vertexOnFaceContacts' case
        const Vec3 q = p0 + at * (p1 - p0);
        const double depth = travel(q);
        if (!(depth > tolerance) || !std::isfinite(depth)) continue;
        Contact ci = c;  // its error bound too: the axis is the patches' hulls' choice
        ci.depth = depth;
        ci.point = q - 0.5 * depth * leave;
        out.push_back(ci);
      }
    }
  }
  return out.size() > before;
}

// Whether a faceted patch is convex: every one of its vertices on or behind the plane of every one
// of its triangles. A piece of a non-convex body can be (a step's edge), and then its hull is its
// body there; one that holds a concave corner (an L-shaped body's floor and wall) is not.
bool facetedPatchIsConvex(const CollisionBody& body, std::uint32_t sphere) {
  const TriangleMesh& mesh = body.mesh();
  const double tolerance = 1e-9 * body.diagonal();
  const std::span<const std::uint32_t> vertices = body.spherePatchVertices(sphere);
  for (std::uint32_t t : body.sphereTree().triangles(sphere)) {
    const Vec3 n = mesh.triangleNormal(t);
    const double offset = n.dot(mesh.corner(t, 0));
    for (std::uint32_t v : vertices)
      if (n.dot(mesh.vertices[v]) > offset + tolerance) return false;
  }
  return true;
}

// Whether a patch is not its own hull: a faceted one that is not convex, a curved one with inner
// vertices (vertices inside its hull, which only a non-convex patch has).
bool hasPocket(const PatchSide& side) {
  return side.faceted ? !facetedPatchIsConvex(side.body, side.sphere) : !side.body.sphereInnerVertices(side.sphere).empty();
}

// Two faceted patches whose least-overlap axis shows zero depth, and that have no faces facing
// each other along it, only graze: coplanar side faces lying flush (a box resting on an equal
// box, shifted along one axis), or a side face standing on the rim of a top face. Such a contact
// would push sideways along a face that nothing presses on, so it is dropped; the pair's real
// contact, if any, comes from the pairs holding the faces that do face each other. Zero: within
// 1e-9 of the bodies' diagonals (rounding).
bool grazesAtZeroDepth(const PatchSide& sideA, const PatchSide& sideB, const Contact& c) {
  return c.depth <= 1e-9 * (sideA.body.diagonal() + sideB.body.diagonal());
}

Vec3 differenceNormal(const Vec3& nA, const Vec3& nB, const Vec3& dosNormal) {
  const Vec3 sum = nB - nA;
  const double len = sum.norm();
  if (len < 1e-9) return dosNormal;
  return sum / len;
}

// Contacts of the sphere models, one per frontier pair. Pairs proven apart (cfm: a separating
// axis between their patches) give none.
void sphereContacts(ContactModel model, const CollisionBody& bodyA, const CollisionBody& bodyB, const Pose& xfAFromB,
                    const std::vector<SpherePair>& front, AnswerClock& clock, QueryScratch::Impl& s,
                    std::vector<Contact>& out) {
  s.probedCorners[0].clear();
  s.probedCorners[1].clear();
  s.edgeContacts.clear();
  bool vertexInside = false;  // a vertex of a closed non-convex body or of a convex patch inside the other
  const SphereTree& ta = bodyA.sphereTree();
  const SphereTree& tb = bodyB.sphereTree();
  const Eigen::Matrix3d rotAFromB = xfAFromB.rotation.toRotationMatrix();
  for (const SpherePair& p : front) {
    if (!clock.next(!out.empty() || !s.edgeContacts.empty())) break;
    const Vec3 cA = ta.center(p.a);
    const Vec3 cB = xfAFromB.apply(tb.center(p.b));
    const double rA = ta.radius[p.a];
    const double rB = tb.radius[p.b];
    const DosContact dos = dosContact(cA, rA, cB, rB);
    Contact c;
    c.point = dos.point;
    c.depth = dos.depth;
    c.errorBound = rA + rB;
    c.level = std::max(bodyA.sphereLevel(p.a), bodyB.sphereLevel(p.b));
    c.featureA = p.a;  // every contact below is a copy of c: the pair's spheres
    c.featureB = p.b;
    c.featureKind = ContactFeature::kSphere;
    if (model == ContactModel::kDos) {
      c.normal = dos.normal;
      out.push_back(c);
      continue;
    }
    const ContactNormalModel m =
        model == ContactModel::kCfm ? ContactNormalModel::kClosestFeatureMap : ContactNormalModel::kAverage;
    const PatchSide sideA{bodyA, p.a, !bodyA.spherePatchVertices(p.a).empty(), cA, rA, nullptr, Vec3::Zero()};
    const PatchSide sideB{bodyB, p.b, !bodyB.spherePatchVertices(p.b).empty(), cB, rB, &rotAFromB, xfAFromB.translation};
    // Between two faceted patches the separating-axis choice below decides the normal from their
    // faces and edges alone; the maps' normals are looked up only where a side is curved (or
    // for the average model).
    const bool bothFaceted = model == ContactModel::kCfm && sideA.faceted && sideB.faceted;
    Vec3 nA = Vec3::Zero(), nB = Vec3::Zero(), nBlocal = Vec3::Zero();
    if (!bothFaceted) {
      // Each sphere is looked up at its surface point facing the other sphere: the sample
      // nearest the D&O point whenever that point lies between the centres, and still the
      // side facing the contact when a large sphere's radical plane lies beyond the small
      // sphere's centre (then the D&O point would look up the small sphere's far side).
      nA = contactNormal(m, ta, bodyA.closestFeatureMap(), p.a, cA - rA * dos.normal);
      const Vec3 pointB = xfAFromB.applyInverse(cB + rB * dos.normal);
      nBlocal = contactNormal(m, tb, bodyB.closestFeatureMap(), p.b, pointB);
      nB = xfAFromB.rotation * nBlocal;
      c.normal = differenceNormal(nA, nB, dos.normal);
    }
    if (model != ContactModel::kCfm) {
      // The average model is the paper's straw man and stays plain.
      out.push_back(c);
      continue;
    }
    // Rule 2 applies wherever a side is faceted, also where the maps agree: a small body's
    // sphere and a floor's huge root sphere agree on a nearly horizontal normal (the floor's
    // side face, the body's side facing the floor's centre), and the facets of a polyhedral ball
    // are tilted against the floor it rests on. Between two curved patches, rule 1 and 3-5.
    const bool agree = !bothFaceted && nB.dot(-nA) >= kAgreeCos;
    const PatchAxis axis = leastOverlapNormal(sideA, sideB, rotAFromB, nA, nB, c.normal);
    if (axis == PatchAxis::kNotFaceted && agree) snapToFaceNormal(sideA, sideB, rotAFromB, c.normal);
    if (axis == PatchAxis::kApart) continue;  // the patches cannot touch: no contact
    if (axis == PatchAxis::kNotFaceted && !agree) {
      const bool facingA = nA.dot(dos.normal) < 0.0;
      const bool facingB = nB.dot(dos.normal) > 0.0;
      if (facingA != facingB) {
        c.normal = facingB ? nB : Vec3(-nA);
      } else {
        const bool faceA = isFaceNormal(nA, bodyA.sphereFaceNormals(p.a));
        const bool faceB = isFaceNormal(nBlocal, bodyB.sphereFaceNormals(p.b));
        if (faceA != faceB) {
          c.normal = faceB ? nB : Vec3(-nA);
        } else if (facingA) {
          // Two curved surfaces crossing, both facing the contact: the intersection volume's
          // gradient (the exact model's normal) is the area-weighted difference of the two
          // sides' normals; the maps' two normals are its two-sample estimate. Picking one of
          // them was half the crossing angle off (300 poses: fandisk at 16 tests 28.1 -> 24.3
          // deg, bunny at 64 tests 16.0 -> 14.6 deg median against the exact model).
          c.normal = differenceNormal(nA, nB, dos.normal);
        } else {
          c.normal = nB.dot(dos.normal) >= -nA.dot(dos.normal) ? nB : Vec3(-nA);
        }
      }
    }
    // Two curved patches are bounded by their support vertices (their convex hulls) more
    // tightly than by their spheres: an axis along which the hulls do not overlap proves the
    // patches apart, and along the normal their overlap bounds the depth. Zero-g bunny-1500 pairs
    // at levels 1-2 responded while only the spheres met, where the surfaces were still apart
    // (`clod experiment fidelity`'s gap component: cfm 0.20 / 0.13).
    if (!sideA.faceted && !sideB.faceted && !curvedPatchesMayTouch(sideA, sideB, dos.normal)) continue;
    if (!patchDepthAndPoint(sideA, sideB, c.normal, c)) continue;
    // A curved patch, or a faceted patch of a non-convex body (a bunny's leaf), against a faceted
    // patch of a convex body: the vertices it rests on. B's faces face A along +n, A's face B
    // along -n. (Two convex bodies' faceted patches clip their faces below instead.) The leaves'
    // single patch contact held the Figure 6 bunny 95 deg from the exact run's pose; with their
    // vertices, 13 deg (`clod experiment landing`).
    const bool convexA = bodyA.isConvexPolyhedron(), convexB = bodyB.isConvexPolyhedron();
    // A closed non-convex body against a convex body's patch or a second closed non-convex body:
    // the vertices of each inside the other, each at its exact depth, are the contact.
    // Where a patch of the pair has a pocket, or the other side is a faceted patch (at most 32
    // vertices: cheap to probe, and its corners, not a separating-axis contact at the spheres' D&O
    // point, are where it touches -- a box landing on one corner on a convex piece of a bin's floor
    // stood balanced on such contacts). A convex piece against a curved patch (an icosphere's, a
    // fandisk's: up to 1,024 support vertices) is its own hull, and the separating axis answers it
    // as before (probing those pairs too cost the 200-body bin 45 % more CPU per frame and doubled
    // its p99 frame; it did screw cfm's nut down its bolt, which now jams).
    // An open body (a scanned bunny with holes) has no inside, but its vertices can be inside N:
    // against N it is answered as a convex body is, one way only. Dropped on a closed floor with
    // a wall (a room's, a stair's mesh), bunny-1500 got the hulls' answer, which pushed it down
    // through the floor into the hull's pocket: 2-6 diagonals deep at 16-64 tests per frame, cfm
    // and exact alike; and on a flat piece of N a curved patch's hull overlap let it sink 3-9 % at
    // 256. (A flat piece of an open body is a floor: the rule below holds N on it.)
    auto openCurved = [](const CollisionBody& b, bool convex, std::uint32_t sphere) {
      return !convex && !b.isClosed() && b.sphereFaceNormals(sphere).size() != 1;
    };
    const bool openA = openCurved(bodyA, convexA, p.a), openB = openCurved(bodyB, convexB, p.b);
    const bool closedNonConvexA = !convexA && bodyA.isClosed(), closedNonConvexB = !convexB && bodyB.isClosed();
    const bool pocketA = closedNonConvexA && hasPocket(sideA), pocketB = closedNonConvexB && hasPocket(sideB);
    const bool closedA = closedNonConvexA && ((closedNonConvexB && (pocketA || pocketB || sideA.faceted || sideB.faceted)) ||
                                              (convexB && (pocketA || sideB.faceted)) || openB);
    const bool closedB = !closedA && closedNonConvexB && ((convexA && (pocketB || sideA.faceted)) || openA);
    if (closedA || closedB) {
      const PatchSide& body = closedA ? sideA : sideB;
      const bool bodyPocket = closedA ? pocketA : pocketB;
      const PatchSide& convex = closedA ? sideB : sideA;  // (or a second closed non-convex body: B)
      bool any = cornersInsideContacts(body, convex, closedA, c, s.containment, s.probedCorners[closedA ? 1 : 0], out);
      if (!convex.body.isClosed()) {
        // (An open body has no inside for N's vertices.)
      } else if (!convex.body.isConvexPolyhedron()) {
        // Two closed non-convex bodies (spot dropped into a bin): each one's vertices in the other.
        any = cornersInsideContacts(convex, body, false, c, s.containment, s.probedCorners[0], out) || any;
      } else if (convex.faceted) {
        // (A curved patch of a convex body, an icosphere's, has no few face planes to test the
        // body's vertices against; its own vertices in the body hold it.)
        any = vertexOnFaceContacts(body, convex, closedA ? c.normal : Vec3(-c.normal), c, out) || any;
      }
      if (any) {
        vertexInside = true;
        continue;
      }
      // Neither body has a vertex in the other here: they are apart, or edges cross, which the
      // separating-axis contact stands for only where the body's side is its hull there: not on a
      // flat piece (the convex body's underside does not reach into it; an edge lying across it
      // is held by the corners over the neighbouring pieces), nor on a faceted piece that is not
      // convex, nor where the overlap along the axis exceeds the convex patch's own extent along
      // it (the patch lies wholly inside the other side's hull: in its pocket). And only where no
      // vertex of either lies inside the other anywhere (edges crossing alone): otherwise the
      // vertex contacts are the bodies' deepest points, and a separating-axis contact stands at
      // its pair's D&O point, up to a sphere away from where the bodies meet (a box balanced on
      // one corner on a bin's floor got three such contacts around it at an unlimited budget and
      // stood on them).
      if (body.body.sphereFaceNormals(body.sphere).size() == 1 || (body.faceted && bodyPocket)) continue;
      const Extent e = convex.vertexExtent(c.normal);
      if (c.depth > e.hi - e.lo) continue;
      if (sideA.faceted && sideB.faceted && grazesAtZeroDepth(sideA, sideB, c)) continue;
      if (body.faceted && convex.faceted && convex.body.isConvexPolyhedron() &&
          edgesThroughConvexContacts(body, convex, closedA, c, s.edgeContacts))
        continue;
      s.edgeContacts.push_back(c);
      continue;
    } else {
      // A flat patch of an open body (a ground quad) against any patch: the other patch's
      // bounding vertices over it (its hull's, which hold its deepest points) and, for a convex
      // faceted patch, the flat patch's own vertices inside the convex body are the whole contact;
      // none of either means the other side's underside does not reach into this piece (an edge
      // lying across it is held by the corners over the neighbouring pieces). A closed spot on a
      // two-triangle floor got one contact at the roots' spheres (16-64 tests per frame) and
      // rocked about it, 18 % of its size into the floor; at full depth its leaves' cfm normals
      // below the plane pointed down, through it.
      const bool flatA = !convexA && !bodyA.isClosed() && bodyA.sphereFaceNormals(p.a).size() == 1;
      const bool flatB = !flatA && !convexB && !bodyB.isClosed() && bodyB.sphereFaceNormals(p.b).size() == 1;
      if (flatA) {
        cornersOverFlatPatchContacts(sideA, sideB, false, c, out);
        if (sideB.faceted && convexB) vertexOnFaceContacts(sideA, sideB, c.normal, c, out);
        continue;
      }
      if (flatB) {
        cornersOverFlatPatchContacts(sideB, sideA, true, c, out);
        if (sideA.faceted && convexA) vertexOnFaceContacts(sideB, sideA, -c.normal, c, out);
        continue;
      }
      if ((!sideA.faceted || !convexA) && sideB.faceted && convexB && vertexOnFaceContacts(sideA, sideB, c.normal, c, out))
        continue;
      if ((!sideB.faceted || !convexB) && sideA.faceted && convexA && vertexOnFaceContacts(sideB, sideA, -c.normal, c, out))
        continue;
    }
    if (sideA.faceted && sideB.faceted) {
      // Face-on-face corners between two convex polyhedra are exact (their faces are the bodies'
      // faces); so is everything when both patches are the whole bodies (the separating-axis
      // theorem). Elsewhere a patch stands for a sphere's part of the surface: r_A + r_B.
      // Only between convex bodies: on a non-convex patch the outermost face along a normal
      // need not be the one in contact (a bump's top above the ground plane: clipped against it,
      // a box sliding on flat ground got the bump's height as depth and jumped 57 mm).
      const bool convex = bodyA.isConvexPolyhedron() && bodyB.isConvexPolyhedron();
      Contact faces = c;
      faces.errorBound = 0.0;
      if (convex && facedPatchContacts(sideA, sideB, faces, out)) continue;
      if (grazesAtZeroDepth(sideA, sideB, c)) continue;
      if (bodyA.patchIsWholeConvexBody(p.a) && bodyB.patchIsWholeConvexBody(p.b)) {
        c.errorBound = 0.0;
        touchingFeaturesPoint(sideA, sideB, c.normal, c.point);
      }
    }
    out.push_back(c);
  }
  // Where the convex body's edges leave N between its probed corners (edgeExitContacts).
  const double tolerance = 1e-9 * (bodyA.diagonal() + bodyB.diagonal());
  if (bodyA.isConvexPolyhedron() && bodyB.isClosed() && !bodyB.isConvexPolyhedron())
    edgeExitContacts(bodyB, xfAFromB.inverse(), bodyA, Pose{}, s.probedCorners[0], tolerance, s.containment, out);
  if (bodyB.isConvexPolyhedron() && bodyA.isClosed() && !bodyA.isConvexPolyhedron())
    edgeExitContacts(bodyA, Pose{}, bodyB, xfAFromB, s.probedCorners[1], tolerance, s.containment, out);
  if (!vertexInside) out.insert(out.end(), s.edgeContacts.begin(), s.edgeContacts.end());
}

// The exact model between two closed convex polyhedra whose root patches are the whole bodies
// (CollisionBody::patchIsWholeConvexBody): the least-overlap axis over both bodies' face normals
// and edge-edge cross products is the minimum translation that separates them (the
// separating-axis theorem for convex polyhedra), so depth and normal are exact, and the
// overlap of the two faces facing along it is the exact contact polygon (edge contacts: one
// point). No contact when an axis separates them. Error bound 0.
void convexPolyhedraContacts(const CollisionBody& bodyA, const CollisionBody& bodyB, const Pose& xfAFromB,
                             std::vector<Contact>& out) {
  const Eigen::Matrix3d rotAFromB = xfAFromB.rotation.toRotationMatrix();
  const SphereTree& ta = bodyA.sphereTree();
  const SphereTree& tb = bodyB.sphereTree();
  const Vec3 cA = ta.center(0);
  const Vec3 cB = xfAFromB.apply(tb.center(0));
  const PatchSide sideA{bodyA, 0, true, cA, ta.radius[0], nullptr, Vec3::Zero()};
  const PatchSide sideB{bodyB, 0, true, cB, tb.radius[0], &rotAFromB, xfAFromB.translation};
  const DosContact dos = dosContact(cA, ta.radius[0], cB, tb.radius[0]);
  Contact c;
  c.point = dos.point;
  c.depth = std::numeric_limits<double>::infinity();
  c.errorBound = 0.0;
  c.level = 0;
  c.featureA = c.featureB = 0;  // the root spheres: the whole bodies
  c.featureKind = ContactFeature::kSphere;
  if (leastOverlapNormal(sideA, sideB, rotAFromB, Vec3::Zero(), Vec3::Zero(), c.normal) != PatchAxis::kChosen) return;
  if (!patchDepthAndPoint(sideA, sideB, c.normal, c)) return;
  if (facedPatchContacts(sideA, sideB, c, out)) return;
  touchingFeaturesPoint(sideA, sideB, c.normal, c.point);
  out.push_back(c);
}

Contact toWorld(const Contact& local, const Pose& xfWorldFromA) {
  Contact c = local;
  c.point = xfWorldFromA.apply(local.point);
  c.normal = xfWorldFromA.rotation * local.normal;
  return c;
}

// ---------------------------------------------------------------------------------------------
// Exact model: triangle pairs of the leaf x leaf frontier pairs.

// The exact model's normal: the gradient of the intersection volume V of the two bodies. Moving
// A by dx changes V by -dx . (integral of n_A over A's surface inside B), so the direction that
// shrinks V fastest is N = integral over B's surface inside A of n_B dA - integral over A's
// surface inside B of n_A dA (the two agree for closed meshes, by the divergence theorem; using
// both halves the discretisation error). The part of a triangle inside the other body is taken
// as the triangle clipped by the inner half-spaces of the other body's triangles it intersects:
// exact where the other surface is locally convex, an approximation where it is concave, and
// triangles lying wholly inside the other body (no intersection) are not counted. Depth
// (patchDepth): where one side is flat, the intersection volume over its projected area along
// N, with the wholly inside triangles (addWhollyInsideTriangles) -- the penetration of a flat
// contact; where both are curved, the distance along N between the area centroids of the two
// inside surfaces -- the mean depth (half the lens thickness) for two spheres. An extent along N
// (max - min) would grow with N's tilt times the patch width.
// For a box resting on a box this gives the face normal (tilted by ~depth/width from the thin
// side strips) and the penetration; for two spheres, the centre line and the lens thickness.
void clipByHalfSpaces(const Vec3& p0, const Vec3& p1, const Vec3& p2, const TriangleMesh& other,
                      const MatrixPose& xfSelfFromOther, std::span<const std::uint32_t> clippers, std::vector<Vec3>& poly,
                      std::vector<Vec3>& tmp) {
  poly.assign({p0, p1, p2});
  for (std::uint32_t t : clippers) {
    const Vec3 o0 = xfSelfFromOther.apply(other.corner(t, 0));
    const Vec3 n = xfSelfFromOther.rotation * other.triangleNormal(t);
    tmp.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec3& p = poly[i];
      const Vec3& q = poly[(i + 1) % poly.size()];
      const double dp = n.dot(p - o0);
      const double dq = n.dot(q - o0);
      if (dp <= 0.0) tmp.push_back(p);
      if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) tmp.push_back(p + (dp / (dp - dq)) * (q - p));
    }
    poly.swap(tmp);
    if (poly.empty()) return;
  }
}

// Adds the area-weighted centroid (moved by xf) and the area of a convex polygon.
void accumulateCentroid(const std::vector<Vec3>& poly, const MatrixPose& xf, Vec3& weighted, double& area) {
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
    const double a = 0.5 * (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]).norm();
    weighted += a * xf.apply((poly[0] + poly[i] + poly[i + 1]) / 3.0);
    area += a;
  }
}

Vec3 polygonAreaVector(const std::vector<Vec3>& poly) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) sum += (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]);
  return 0.5 * sum;
}

// Adds a piece (area vector, area x centroid, area; A's frame) to one side of a patch's sums.
void addToSide(QueryScratch::Impl::PatchSums& q, Vec3& patchNormal, bool sideA, const Vec3& areaVector,
               const Vec3& weightedCentroid, double area) {
  if (area > 0.0) q.moment += (weightedCentroid / area).dot(areaVector);
  if (sideA) {
    patchNormal -= areaVector;
    q.centroidA += weightedCentroid;
    q.areaA += area;
    q.vectorA += areaVector;
    q.absoluteA += areaVector.norm();
    if (areaVector.squaredNorm() > q.largestA.squaredNorm()) q.largestA = areaVector;
  } else {
    patchNormal += areaVector;
    q.centroidB += weightedCentroid;
    q.areaB += area;
    q.vectorB += areaVector;
    q.absoluteB += areaVector.norm();
    if (areaVector.squaredNorm() > q.largestB.squaredNorm()) q.largestB = areaVector;
  }
}

// A patch's depth. Where one side is flat (a face, however tessellated: not `curved`), the
// intersection volume over its area projected along the normal: the penetration of a flat
// contact (a box, or a pillar, pressed into a floor), the mean depth under a curved body resting
// on a face. The volume comes from the divergence theorem over both inside surfaces (their
// outward normals are the intersection's), taken about A's inside centroid so that a boundary
// left open (an open mesh, a concave clip) errs little; the projected area is half the length of
// the summed area vectors (B's minus A's: equal halves on a closed boundary); both include the
// triangles wholly inside the other body. Where both sides are curved the projected area is no
// measure of the contact -- a nut's helical band wraps around the axis and its area vectors
// nearly cancel -- and, as where the volume is not positive (a boundary far from closed), the
// depth is the distance along N between the two inside surfaces' centroids: half the lens's
// thickness for two spheres, as the volume would give.
double patchDepth(const QueryScratch::Impl::PatchSums& q, const Vec3& normal, bool curved) {
  const Vec3 origin = q.centroidA / q.areaA;
  const Vec3 vectorA = q.vectorA + q.insideVectorA, vectorB = q.vectorB + q.insideVectorB;
  const double volume = (q.moment + q.insideMoment - origin.dot(vectorA + vectorB)) / 3.0;
  const double projectedArea = 0.5 * (vectorB - vectorA).norm();
  if (!curved && volume > 0.0 && projectedArea > 0.0) return volume / projectedArea;
  return std::max(0.0, normal.dot(q.centroidB / q.areaB - origin));
}

constexpr std::uint32_t kUnseen = 0xffffffffu, kCrossing = 0xfffffffeu, kOutside = 0xfffffffdu;

// The triangles of `self` lying wholly inside `other` next to a patch, for the patch's volume
// (patchDepth): they cross nothing, so no triangle pair finds them, yet they bound the
// intersection (a box pressed flat into a floor: its bottom face). Without them a flat
// penetration's inside surface was its side strips alone, and the depth half the penetration
// (docs/narrow-phase.md). The normal keeps the crossing pieces alone: with these added too, the
// nut of tests/scene/nut_bolt_scene_test.cpp turned 0.89 instead of 1.18 turns in its 2 s.
// From the crossing triangles of flat patches (curved ones do not use them) the flood goes
// across edges: a triangle that crosses nothing is either wholly inside `other` or wholly
// outside, and its centroid against the other body's exact field decides, inside only when
// deeper than `tolerance` -- a triangle lying on the other surface (flush, or touching without
// crossing) is not inside, and the flood does not leak past it. Only for a finished query (every
// crossing pair known) against a closed `other`. Each inside triangle joins the patch it was
// reached from. Cost: one field query per triangle reached.
void addWhollyInsideTriangles(const CollisionBody& self, const CollisionBody& other, bool selfIsA,
                              const MatrixPose& otherFromSelf, const MatrixPose& aFromSelf, double tolerance,
                              QueryScratch::Impl& s) {
  if (!other.isClosed()) return;
  const TriangleMesh& mesh = self.mesh();
  if (s.triangleState.size() < mesh.triangleCount()) s.triangleState.resize(mesh.triangleCount(), kUnseen);
  s.touchedTriangles.clear();
  auto mark = [&](std::uint32_t t, std::uint32_t state) {
    if (s.triangleState[t] == kUnseen) s.touchedTriangles.push_back(t);
    s.triangleState[t] = state;
  };
  for (const auto& p : s.volumePairs) mark(selfIsA ? p.ta : p.tb, kCrossing);
  auto addTriangle = [&](std::uint32_t t, std::uint32_t patch) {
    const Vec3 p0 = aFromSelf.apply(mesh.corner(t, 0)), p1 = aFromSelf.apply(mesh.corner(t, 1)),
               p2 = aFromSelf.apply(mesh.corner(t, 2));
    const Vec3 areaVector = 0.5 * (p1 - p0).cross(p2 - p0);
    auto& q = s.patchSums[patch];
    q.insideMoment += ((p0 + p1 + p2) / 3.0).dot(areaVector);
    (selfIsA ? q.insideVectorA : q.insideVectorB) += areaVector;
  };
  s.floodQueue.clear();
  auto visitNeighbours = [&](std::uint32_t t, std::uint32_t patch) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = self.triangleNeighbour(t, k);
      if (u == CollisionBody::kNoNeighbour || s.triangleState[u] != kUnseen) continue;
      const Vec3 centroid = (mesh.corner(u, 0) + mesh.corner(u, 1) + mesh.corner(u, 2)) / 3.0;
      const bool inside =
          detail::exactBodyField(other, otherFromSelf.apply(centroid), s.containment).distance < -tolerance;
      mark(u, inside ? patch : kOutside);
      if (inside) s.floodQueue.push_back(u);
    }
  };
  for (const auto& p : s.volumePairs)
    if (s.patchCurved[p.patch] == 0) visitNeighbours(selfIsA ? p.ta : p.tb, p.patch);
  for (std::size_t i = 0; i < s.floodQueue.size(); ++i) {
    const std::uint32_t u = s.floodQueue[i];
    addTriangle(u, s.triangleState[u]);
    visitNeighbours(u, s.triangleState[u]);
  }
  for (std::uint32_t t : s.touchedTriangles) s.triangleState[t] = kUnseen;
}

// A patch's normal where one side of it is a single plane (its pieces' area vectors all point one
// way: a box's face, a tessellated floor): that plane's normal. The overlap of a body with a
// half-space separates along the plane's normal by its deepest point's depth and along any other
// direction u only by more (depth / (u . n)), and the divergence theorem gives the same normal
// from the two sides' sum when the overlap's boundary is complete -- but a finely tessellated
// body's triangles wholly inside the other cross nothing and are missing from the sum, which then
// leans toward that body's faces (a fandisk landing on one edge on a box: 6 deg). Where both sides
// are planes and not parallel (two triangles crossing at an edge), or neither is, the sum
// (`summed`, unnormalised) stays.
Vec3 planeSideNormal(const QueryScratch::Impl::PatchSums& q, const Vec3& summed) {
  constexpr double kCoplanarCos = 0.99999998476913;  // cos 0.01 deg: rounding, not a bend
  const bool planeA = q.absoluteA > 0.0 && q.vectorA.norm() >= kCoplanarCos * q.absoluteA;
  const bool planeB = q.absoluteB > 0.0 && q.vectorB.norm() >= kCoplanarCos * q.absoluteB;
  const Vec3 fromA = planeA ? Vec3(-q.vectorA.normalized()) : Vec3::Zero();
  const Vec3 fromB = planeB ? Vec3(q.vectorB.normalized()) : Vec3::Zero();
  if (planeA && planeB) return fromA.dot(fromB) >= kCoplanarCos ? fromA : summed;
  if (planeA) return fromA;
  if (planeB) return fromB;
  // Two faces pressed together whose overlap reaches an edge of one of them (a box standing over
  // the edge of a step or a shelf): each side is its face plus slivers of the side faces as tall
  // as the penetration, whose area vectors tilt the sum off the faces' normal by the depth over
  // the overlap's size (0.3 deg at 1.7 mm on a 0.3 m overlap) -- a steady push over the edge, and
  // the box slid off. Where the largest pieces of the two sides face each other exactly and carry
  // all but kSliverShare of each side's area along their normal, the normal is theirs.
  constexpr double kSliverShare = 0.05;
  if (q.largestA.squaredNorm() > 0.0 && q.largestB.squaredNorm() > 0.0) {
    const Vec3 faceA = -q.largestA.normalized(), faceB = q.largestB.normalized();
    const bool faceOnFace = faceA.dot(faceB) >= kCoplanarCos;
    if (faceOnFace && -q.vectorA.dot(faceA) >= (1.0 - kSliverShare) * q.absoluteA &&
        q.vectorB.dot(faceB) >= (1.0 - kSliverShare) * q.absoluteB)
      return faceA;
  }
  return summed;
}

// Normal and depth of every patch (s.patchNormal, s.patchDepth), each from its own pairs only:
// a triangle is clipped by the half-spaces of the other body's triangles it meets in that patch.
// A patch whose area vectors cancel keeps B's face normal of its first pair (B toward A).
// Also keeps each pair's two pieces (s.pieceA, s.pieceB) and marks the curved patches
// (s.patchCurved: on both sides the pieces' normals spread by more than kFlatSpreadCos), for the
// per-point normals of exactContacts.
void penetrationVolumeNormals(const CollisionBody& bodyA, const CollisionBody& bodyB, const Pose& xfAFromB,
                              std::uint32_t patchCount, bool complete, QueryScratch::Impl& s) {
  const TriangleMesh& ma = bodyA.mesh();
  const TriangleMesh& mb = bodyB.mesh();
  auto& pairs = s.volumePairs;
  s.patchNormal.assign(patchCount, Vec3::Zero());
  s.patchDepth.assign(patchCount, 0.0);
  s.patchCurved.assign(patchCount, 0);
  s.pieceA.resize(pairs.size());
  s.pieceB.resize(pairs.size());
  if (pairs.empty()) return;
  // patchNormal accumulates the area-vector sums.
  auto& sums = s.patchSums;
  sums.assign(patchCount, {Vec3::Zero(), Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.0, false, Vec3::Zero(), Vec3::Zero(),
                           0.0, 0.0, 0.0, Vec3::Zero(), Vec3::Zero(), 0.0});
  for (std::size_t i = 0; i < pairs.size(); ++i) {  // still in insertion order
    auto& q = sums[pairs[i].patch];
    if (!q.seen) q.fallbackNormal = s.pairNormalB[i];
    q.seen = true;
  }
  const MatrixPose aFromB(xfAFromB);
  const MatrixPose bFromA(xfAFromB.inverse());
  const MatrixPose identity{Pose{}};
  // A's triangles, each clipped by the B triangles it meets in its patch.
  std::sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    return x.patch != y.patch ? x.patch < y.patch : (x.ta != y.ta ? x.ta < y.ta : x.tb < y.tb);
  });
  for (std::size_t i = 0; i < pairs.size();) {
    std::size_t j = i;
    s.clippers.clear();
    while (j < pairs.size() && pairs[j].patch == pairs[i].patch && pairs[j].ta == pairs[i].ta) {
      s.clippers.push_back(pairs[j++].tb);
    }
    const std::uint32_t t = pairs[i].ta;
    const std::uint32_t patch = pairs[i].patch;
    clipByHalfSpaces(ma.corner(t, 0), ma.corner(t, 1), ma.corner(t, 2), mb, aFromB, s.clippers, s.poly, s.polyTmp);
    QueryScratch::Impl::Piece piece{polygonAreaVector(s.poly), Vec3::Zero(), 0.0};  // n_A * area (counter-clockwise)
    accumulateCentroid(s.poly, identity, piece.weightedCentroid, piece.area);
    addToSide(sums[patch], s.patchNormal[patch], true, piece.areaVector, piece.weightedCentroid, piece.area);
    for (std::size_t k = i; k < j; ++k) s.pieceA[pairs[k].index] = piece;
    i = j;
  }
  // B's triangles, clipped by the A triangles they meet in the patch, in B's frame, then moved to A's.
  std::sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    return x.patch != y.patch ? x.patch < y.patch : (x.tb != y.tb ? x.tb < y.tb : x.ta < y.ta);
  });
  for (std::size_t i = 0; i < pairs.size();) {
    std::size_t j = i;
    s.clippers.clear();
    while (j < pairs.size() && pairs[j].patch == pairs[i].patch && pairs[j].tb == pairs[i].tb) {
      s.clippers.push_back(pairs[j++].ta);
    }
    const std::uint32_t t = pairs[i].tb;
    const std::uint32_t patch = pairs[i].patch;
    clipByHalfSpaces(mb.corner(t, 0), mb.corner(t, 1), mb.corner(t, 2), ma, bFromA, s.clippers, s.poly, s.polyTmp);
    QueryScratch::Impl::Piece piece{xfAFromB.rotation * polygonAreaVector(s.poly), Vec3::Zero(), 0.0};
    accumulateCentroid(s.poly, aFromB, piece.weightedCentroid, piece.area);
    addToSide(sums[patch], s.patchNormal[patch], false, piece.areaVector, piece.weightedCentroid, piece.area);
    for (std::size_t k = i; k < j; ++k) s.pieceB[pairs[k].index] = piece;
    i = j;
  }
  bool anyFlat = false;
  for (std::uint32_t p = 0; p < patchCount; ++p) {
    const auto& q = sums[p];
    s.patchCurved[p] =
        q.vectorA.norm() < kFlatSpreadCos * q.absoluteA && q.vectorB.norm() < kFlatSpreadCos * q.absoluteB;
    anyFlat = anyFlat || s.patchCurved[p] == 0;
  }
  if (complete && anyFlat) {  // only flat patches' depths use them
    // Inside means deeper than the rounding of a surface point's distance at the bodies' size.
    const double tolerance = 1e-9 * (bodyA.diagonal() + bodyB.diagonal());
    addWhollyInsideTriangles(bodyA, bodyB, true, bFromA, identity, tolerance, s);
    addWhollyInsideTriangles(bodyB, bodyA, false, aFromB, aFromB, tolerance, s);
  }
  for (std::uint32_t p = 0; p < patchCount; ++p) {
    const auto& q = sums[p];
    s.patchNormal[p] = planeSideNormal(q, s.patchNormal[p]);
    const double len = s.patchNormal[p].norm();
    s.patchNormal[p] = len > 0.0 ? Vec3(s.patchNormal[p] / len) : q.fallbackNormal;
    if (q.areaA > 0.0 && q.areaB > 0.0) {
      s.patchDepth[p] = patchDepth(q, s.patchNormal[p], s.patchCurved[p] != 0);
    }
  }
}

std::uint32_t findPatchRoot(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];  // path halving
    i = parent[i];
  }
  return i;
}

// Groups the intersecting triangle pairs into connected patches: two pairs belong to one patch
// when their intersection points (segment ends, overlap-polygon corners) coincide within `tol`
// and both are coplanar (face-on-face touching) or both are crossing. Where the intersection
// curve of two closed meshes passes from one triangle into the next, the two pairs compute the
// same crossing point, so a connected curve (or overlap region) chains into one patch, while
// separate touching regions stay apart even when they share a large triangle (a box's 2-triangle
// face touching both the ground and a bump). Flush coplanar regions are kept apart from crossing
// ones: a flush face contact says "touching along the face normal, depth 0", and merged with a
// bump it would dilute the bump's normal and depth over the whole face (docs/narrow-phase.md).
// Points are hashed into cells of 64 tol and sorted by cell: points of one cell are compared with
// each other, and a point within tol of a cell face also with the neighbour cell(s) across it
// (rare: ~3 % per axis), so the cost is one sort, O(k log k), not 27 look-ups per point.
// Returns the patch count; sets volumePairs[i].patch (insertion order) to 0 .. count-1.
std::uint32_t groupPatches(QueryScratch::Impl& s, double tol) {
  const std::size_t n = s.volumePairs.size();
  s.patchParent.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) s.patchParent[i] = i;
  const double cellSize = 64.0 * tol;
  s.cellPoints.clear();
  for (std::uint32_t k = 0; k < s.exactContacts.size(); ++k) {
    const Vec3 q = s.exactContacts[k].contact.point / cellSize;
    s.cellPoints.push_back({{static_cast<std::int64_t>(std::floor(q.x())), static_cast<std::int64_t>(std::floor(q.y())),
                             static_cast<std::int64_t>(std::floor(q.z()))},
                            k});
  }
  std::sort(s.cellPoints.begin(), s.cellPoints.end(),
            [](const auto& x, const auto& y) { return x.cell != y.cell ? x.cell < y.cell : x.contact < y.contact; });
  const double tol2 = tol * tol;
  auto join = [&](std::uint32_t ci, std::uint32_t cj) {
    const auto& x = s.exactContacts[ci];
    const auto& y = s.exactContacts[cj];
    if (x.pair == y.pair || s.pairCoplanar[x.pair] != s.pairCoplanar[y.pair]) return;
    if ((x.contact.point - y.contact.point).squaredNorm() > tol2) return;
    const std::uint32_t ra = findPatchRoot(s.patchParent, x.pair);
    const std::uint32_t rb = findPatchRoot(s.patchParent, y.pair);
    if (ra != rb) s.patchParent[std::max(ra, rb)] = std::min(ra, rb);
  };
  const std::size_t m = s.cellPoints.size();
  for (std::size_t i = 0; i < m; ++i) {
    const auto& cp = s.cellPoints[i];
    // Same cell: the points after it in the run.
    for (std::size_t j = i + 1; j < m && s.cellPoints[j].cell == cp.cell; ++j) join(cp.contact, s.cellPoints[j].contact);
    // Neighbour cells across the faces it is within tol of (each such pair is seen from both
    // sides; joining twice is harmless).
    const Vec3 q = s.exactContacts[cp.contact].contact.point / cellSize;
    std::array<std::int64_t, 3> lo{}, hi{};
    bool near = false;
    for (int d = 0; d < 3; ++d) {
      const double frac = q[d] - static_cast<double>(cp.cell[static_cast<std::size_t>(d)]);
      lo[static_cast<std::size_t>(d)] = frac * cellSize <= tol ? -1 : 0;
      hi[static_cast<std::size_t>(d)] = (1.0 - frac) * cellSize <= tol ? 1 : 0;
      near = near || lo[static_cast<std::size_t>(d)] != 0 || hi[static_cast<std::size_t>(d)] != 0;
    }
    if (!near) continue;
    for (std::int64_t dx = lo[0]; dx <= hi[0]; ++dx) {
      for (std::int64_t dy = lo[1]; dy <= hi[1]; ++dy) {
        for (std::int64_t dz = lo[2]; dz <= hi[2]; ++dz) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const std::array<std::int64_t, 3> cell{cp.cell[0] + dx, cp.cell[1] + dy, cp.cell[2] + dz};
          auto it = std::lower_bound(s.cellPoints.begin(), s.cellPoints.end(), cell,
                                     [](const auto& x, const auto& c) { return x.cell < c; });
          for (; it != s.cellPoints.end() && it->cell == cell; ++it) join(cp.contact, it->contact);
        }
      }
    }
  }
  // Number the patches in order of their first pair, so the numbering is deterministic.
  std::uint32_t count = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = findPatchRoot(s.patchParent, i);
    if (r == i) s.volumePairs[i].patch = count++;
  }
  for (std::uint32_t i = 0; i < n; ++i) s.volumePairs[i].patch = s.volumePairs[findPatchRoot(s.patchParent, i)].patch;
  return count;
}

// Per-point normals in a curved patch. A patch's one normal is the average of its surface's
// normals over the patch; where the patch follows a curved surface for long (a nut's load flank is
// one helical band: its average normal is the thread's axis, and the screw ratios of its contacts
// spread over both signs, so a push along the flanks could not turn the nut), a contact takes the
// volume gradient of its own triangle pair instead -- the area vectors of the pair's two inside
// pieces, B's minus A's -- where that pair's surface is clear:
//  * conformal: its two triangles face each other within kConformalCos (two flank facets);
//  * one-sided: the faces cross at 45 deg or more (kOneSidedCrossingCos) and one piece is at
//    least kDominantPiece times the other's area, i.e. one triangle is the surface and the other
//    only grazes it with an edge (a flank facet sunk past the other part's crest, whose inside
//    strip is as wide as the penetration).
// Other pairs -- two faces crossing steeply with comparable pieces: two boxes' edges crossed, a
// ball's intersection ring -- keep the patch's answer: there neither triangle is the contact's
// surface, and their local gradients tilt apart where the patch's is right; so do contacts whose
// local normal leaves a 45 deg cone about the patch's (kLocalConeCos). Only in curved
// patches (both sides' pieces spread): a flat side -- a box's top face under anything -- keeps the
// patch normal on every point. The depth stays the patch's: the pair's own pieces' centroid
// distance along its normal is no penetration where one piece is a sliver (one-sided pairs), and
// with it the depth-weighted resultant of bunny-on-bunny contacts drifted up to 23 deg from the
// volume gradient (VolumeReference.ExactModelNormalFollowsTheVolumeGradientOnTheBunny).
void localNormal(const QueryScratch::Impl& s, std::uint32_t pair, Contact& c) {
  const auto& pa = s.pieceA[pair];
  const auto& pb = s.pieceB[pair];
  const bool conformal = s.pairNormalB[pair].dot(-s.pairNormalA[pair]) >= kConformalCos;
  const bool steep = s.pairNormalB[pair].dot(-s.pairNormalA[pair]) <= kOneSidedCrossingCos;
  const bool oneSided = steep && (pa.area >= kDominantPiece * pb.area || pb.area >= kDominantPiece * pa.area);
  if (!conformal && !oneSided) return;
  const Vec3 n = pb.areaVector - pa.areaVector;
  const double len = n.norm();
  if (!(len > 0.0) || n.dot(c.normal) < kLocalConeCos * len) return;
  c.normal = n / len;
}

// The penetration along the normal line through a point on both surfaces (a point of the
// intersection curve): how far it moves along +n before it leaves B plus how far along -n before it
// leaves A (each ray starts past the triangles at the point; an open sheet, which the point lies
// on, adds nothing: the other body's part is how far it reaches behind the sheet). Moves c.point to
// the middle of that span and returns its length, 0 where the line only grazes.
double lineThrough(const CollisionBody& bodyA, const CollisionBody& bodyB, const MatrixPose& bFromA, const Vec3& n,
                   Contact& c) {
  if (!bodyA.isClosed() && !bodyB.isClosed()) return 0.0;
  detail::RayHit exitA, exitB;
  const double insideB = detail::distanceToLeave(bodyB, bFromA.apply(c.point), bFromA.rotation * n, 1e-9 * bodyB.diagonal(), exitB);
  const double insideA = detail::distanceToLeave(bodyA, c.point, -n, 1e-9 * bodyA.diagonal(), exitA);
  if (!(insideA > 0.0) && !(insideB > 0.0)) return 0.0;
  c.point += 0.5 * (insideB - insideA) * n;
  return insideA + insideB;
}

// Per-point depth in the exact model: the vertices of either body that lie inside the other,
// next to a patch, each a contact with its own penetration along the normal line through it --
// how far it moves along +n before it leaves B plus how far along -n before it leaves A (one ray
// per body on the triangle hierarchies), the quantity `Contact::errorBound` promises
// (docs/narrow-phase.md, "Error bounds"), so the bound is 0. Candidates are the vertices of the
// patch's crossing triangles behind the plane of the triangle they cross: with a penetration
// shallower than the triangles (a body resting on another) these are the deepest points of the
// overlap. Where a patch has any, they replace its points on the intersection curve, whose
// penetration along any line is 0 and which all carried the patch's one depth: a mesh landing
// tilted on an edge pushed back along the whole edge at its mean depth, where a body touches
// first at its lowest vertex (docs/narrow-phase.md, "exact"). A patch with none (two edges
// crossing) keeps its curve points and depth. In a curved patch a vertex takes the local normal of
// the triangle pair it was found from (localNormal: a thread's flank), with the depth across it.
// Its two surface points (contactPointOnA / OnB) are where the line leaves each body, on
// featureA / featureB. Finished queries only, and only vertices inside a closed body (an open
// body's inside is not defined; the other side may be open: a scanned bunny with holes resting
// on a box). Cost: up to two rays per candidate vertex.
void vertexContacts(const CollisionBody& bodyA, const CollisionBody& bodyB, const Pose& xfAFromB, bool complete,
                    QueryScratch::Impl& s) {
  s.vertexContacts.clear();
  s.patchHasVertices.assign(s.patchNormal.size(), 0);
  s.patchVertexDepth.assign(s.patchNormal.size(), 0.0);
  if (!complete || s.volumePairs.empty()) return;
  const MatrixPose aFromB(xfAFromB);
  const MatrixPose bFromA(xfAFromB.inverse());
  const MatrixPose identity{Pose{}};
  const bool convexSide = bodyA.isConvexPolyhedron() || bodyB.isConvexPolyhedron();
  detail::RayHit exitA, exitB;
  // The vertices of one side's triangle of `pair` behind the other side's triangle, each a
  // contact if the line along the patch normal leaves the other body (A's vertices go along +n
  // into B, B's along -n into A). A vertex is inside a closed body only.
  auto trySide = [&](const QueryScratch::Impl::VolumePair& pair, bool sideA) {
    const CollisionBody& self = sideA ? bodyA : bodyB;
    const CollisionBody& other = sideA ? bodyB : bodyA;
    if (!other.isClosed() && !self.isClosed()) return;
    const TriangleMesh& mesh = self.mesh();
    const TriangleMesh& otherMesh = other.mesh();
    const MatrixPose& aFromSelf = sideA ? identity : aFromB;
    const MatrixPose& aFromOther = sideA ? aFromB : identity;
    const std::uint32_t own = sideA ? pair.ta : pair.tb, crossed = sideA ? pair.tb : pair.ta;
    const Vec3 c0 = aFromOther.apply(otherMesh.corner(crossed, 0));
    const Vec3 crossedNormal = aFromOther.rotation * otherMesh.triangleNormal(crossed);
    const Vec3& n = s.patchNormal[pair.patch];
    const Vec3 nB = bFromA.rotation * n;
    auto& tried = s.vertexTried[sideA ? 0 : 1];
    if (tried.size() < mesh.vertices.size()) tried.resize(mesh.vertices.size(), 0);
    for (const std::uint32_t v : mesh.triangles[own]) {
      const Vec3 p = aFromSelf.apply(mesh.vertices[v]);
      if (tried[v] != 0 || crossedNormal.dot(p - c0) >= 0.0) continue;
      tried[v] = 1;
      s.triedVertices[sideA ? 0 : 1].push_back(v);
      // First into the other body; then its own, which it leaves at once unless the line runs
      // into it (the triangles at p itself are skipped).
      auto intoB = [&](double tMin) { return detail::distanceToLeave(bodyB, bFromA.apply(p), nB, tMin, exitB); };
      auto intoA = [&](double tMin) { return detail::distanceToLeave(bodyA, p, -n, tMin, exitA); };
      const double inOther = sideA ? intoB(0.0) : intoA(0.0);
      if (!(inOther > 0.0)) continue;
      const double inSelf = sideA ? intoA(1e-9 * bodyA.diagonal()) : intoB(1e-9 * bodyB.diagonal());
      const double insideA = sideA ? inSelf : inOther, insideB = sideA ? inOther : inSelf;
      Contact c;
      c.point = p + 0.5 * (insideB - insideA) * n;
      c.normal = n;
      c.depth = insideA + insideB;
      c.errorBound = 0.0;
      c.level = s.pairLevel[pair.index];
      c.featureA = insideA > 0.0 || !sideA ? exitA.triangle : own;
      c.featureB = insideB > 0.0 || sideA ? exitB.triangle : own;
      c.featureKind = ContactFeature::kTriangle;
      s.vertexContacts.push_back(c);
      s.patchHasVertices[pair.patch] = 1;
      s.patchVertexDepth[pair.patch] = std::max(s.patchVertexDepth[pair.patch], c.depth);
    }
  };
  for (const auto& pair : s.volumePairs) {
    if (s.patchCurved[pair.patch] != 0 && !convexSide) continue;
    trySide(pair, true);
    trySide(pair, false);
  }
  for (int side = 0; side < 2; ++side) {
    for (std::uint32_t v : s.triedVertices[side]) s.vertexTried[side][v] = 0;
    s.triedVertices[side].clear();
  }
}

// Returns true if every frontier pair got its triangle tests.
bool exactContacts(const CollisionBody& bodyA, const CollisionBody& bodyB, const Pose& xfAFromB,
                   const std::vector<SpherePair>& front, bool traversalFinished, Meter& meter,
                   QueryScratch::Impl& s, std::vector<Contact>& out, std::uint64_t& triangleTests,
                   std::vector<std::array<std::uint32_t, 2>>& hits) {
  const SphereTree& ta = bodyA.sphereTree();
  const SphereTree& tb = bodyB.sphereTree();
  const TriangleMesh& ma = bodyA.mesh();
  const TriangleMesh& mb = bodyB.mesh();
  s.pairDone.assign(front.size(), 0);
  s.trianglePairs.clear();
  s.exactContacts.clear();
  s.volumePairs.clear();
  s.pairCoplanar.clear();
  s.pairNormalA.clear();
  s.pairNormalB.clear();
  s.pairLevel.clear();
  hits.clear();
  bool complete = traversalFinished;
  if (traversalFinished) {
    // A triangle can belong to several leaves: test each triangle pair once, on behalf of the
    // highest-priority frontier pair that holds it (front is sorted by priority). Pairs are
    // generated in frontier order and deduplicated with an open-addressing set of (ta, tb) keys:
    // the first occurrence is the highest-priority one, and no sort is needed (sorting the
    // candidate list was ~40 % of a deep bunny query, perf).
    std::uint64_t candidates = 0;
    for (const SpherePair& p : front) candidates += std::uint64_t{ta.triangles(p.a).size()} * tb.triangles(p.b).size();
    std::size_t capacity = 64;
    while (capacity < 2 * candidates) capacity *= 2;
    s.pairSet.assign(capacity, 0);
    const std::size_t mask = capacity - 1;
    const int shift = 64 - std::countr_zero(capacity);
    for (std::uint32_t i = 0; i < front.size(); ++i) {
      for (std::uint32_t triA : ta.triangles(front[i].a)) {
        for (std::uint32_t triB : tb.triangles(front[i].b)) {
          const std::uint64_t key = ((std::uint64_t{triA} + 1) << 32) | triB;  // never 0 (empty)
          std::size_t slot = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift);
          while (s.pairSet[slot] != 0 && s.pairSet[slot] != key) slot = (slot + 1) & mask;
          if (s.pairSet[slot] == key) continue;
          s.pairSet[slot] = key;
          s.trianglePairs.push_back({triA, triB, i});
        }
      }
    }

    // Plane-distance tolerance: rounding of coordinates of the size of the two bodies.
    const double eps = 1e-12 * (bodyA.diagonal() + bodyB.diagonal() + xfAFromB.translation.norm());
    narrowphase::TriangleIntersection hit;
    const MatrixPose aFromB(xfAFromB);
    std::size_t k = 0;
    const std::size_t n = s.trianglePairs.size();
    for (std::uint32_t i = 0; i < front.size() && complete; ++i) {
      meter.setFrontier(front.size() - i);  // pairs the cfm fallback would answer if stopped now
      meter.setRemainingTests(n - k);
      for (; k < n && s.trianglePairs[k].pair == i; ++k) {
        if (!meter.take()) {
          complete = false;
          break;
        }
        ++triangleTests;
        const auto& ref = s.trianglePairs[k];
        const Vec3 b0 = aFromB.apply(mb.corner(ref.tb, 0));
        const Vec3 b1 = aFromB.apply(mb.corner(ref.tb, 1));
        const Vec3 b2 = aFromB.apply(mb.corner(ref.tb, 2));
        if (!narrowphase::intersectTriangles(ma.corner(ref.ta, 0), ma.corner(ref.ta, 1), ma.corner(ref.ta, 2), b0, b1,
                                             b2, eps, hit)) {
          continue;
        }
        hits.push_back({ref.ta, ref.tb});
        // Coplanar triangles facing the same way are flush side by side (two boxes' aligned side
        // faces), not pressed against each other: no contact.
        if (hit.coplanar && hit.normalA.dot(hit.normalB) > 0.0) continue;
        if (hit.touching) continue;
        const auto pairIndex = static_cast<std::uint32_t>(s.volumePairs.size());
        s.volumePairs.push_back({ref.ta, ref.tb, 0, pairIndex});
        s.pairCoplanar.push_back(hit.coplanar ? 1 : 0);
        s.pairNormalA.push_back(hit.normalA);
        s.pairNormalB.push_back(hit.normalB);
        s.pairLevel.push_back(std::max(bodyA.sphereLevel(front[i].a), bodyB.sphereLevel(front[i].b)));
        // Normal and depth are filled in below, once all intersecting pairs are known.
        const std::uint64_t key = (std::uint64_t{ref.ta} << 32) | ref.tb;
        Contact c;
        c.errorBound = 0.0;
        c.level = std::max(bodyA.sphereLevel(front[i].a), bodyB.sphereLevel(front[i].b));
        c.featureA = ref.ta;
        c.featureB = ref.tb;
        c.featureKind = ContactFeature::kTriangle;
        for (std::uint32_t q = 0; q < hit.count; ++q) {
          c.point = hit.points[q];
          s.exactContacts.push_back({key, pairIndex, c});
        }
      }
      if (complete) s.pairDone[i] = 1;
    }
  }
  if (complete) {
    // Finished: order by triangle pair, so the answer does not depend on the frontier's order.
    std::stable_sort(s.exactContacts.begin(), s.exactContacts.end(),
                     [](const auto& x, const auto& y) { return x.key < y.key; });
  }
  // Per patch normal and depth. Patch tolerance: far above the rounding of intersection points
  // computed by two pairs (~1e-16 relative, more for nearly parallel planes), far below any
  // feature size: 1e-7 of the bodies' size.
  const double patchTol = 1e-7 * (bodyA.diagonal() + bodyB.diagonal());
  const std::uint32_t patches = groupPatches(s, patchTol);
  // The pairs' patch numbers in insertion order, before penetrationVolumeNormals sorts them.
  s.patchParent.resize(s.volumePairs.size());
  for (std::size_t i = 0; i < s.volumePairs.size(); ++i) s.patchParent[i] = s.volumePairs[i].patch;
  penetrationVolumeNormals(bodyA, bodyB, xfAFromB, patches, complete, s);
  vertexContacts(bodyA, bodyB, xfAFromB, complete, s);
  out.insert(out.end(), s.vertexContacts.begin(), s.vertexContacts.end());
  const MatrixPose bFromA(xfAFromB.inverse());
  for (auto& kc : s.exactContacts) {
    const std::uint32_t patch = s.patchParent[kc.pair];
    if (s.patchHasVertices[patch] != 0) {
      const double depth = lineThrough(bodyA, bodyB, bFromA, s.patchNormal[patch], kc.contact);
      // A patch whose vertices are in by rounding only (a box standing on a floor, 1e-19 to 1e-9)
      // has its crossings touching as well, the line through them finding no depth: dropped as
      // grazing, a thin box over a floor's rim kept its inner corners only and toppled sideways
      // (exact, unlimited budget). There the crossings are contacts at the depth they have.
      const bool resting = s.patchVertexDepth[patch] <= patchTol;
      if ((depth > patchTol || resting) && depth <= s.patchVertexDepth[patch] + patchTol) {
        // A point of the intersection curve that the line along the normal finds inside both
        // bodies: where a box standing over an edge of the other body crosses it, a corner of
        // their overlap that is no body's vertex (with the vertices alone the box turned about
        // its inner ones and fell off). On a curved patch's rim the line only grazes (depth 0).
        // The overlap's corners between the vertices are no deeper than its deepest vertex; a
        // line deeper than that ran along a face it lies in (a box flush against a wall: up the
        // wall's face to its top, 2 m).
        kc.contact.normal = s.patchNormal[patch];
        kc.contact.depth = depth;
        out.push_back(kc.contact);
      }
      continue;
    }
    kc.contact.normal = s.patchNormal[patch];
    // Coplanar faces pressed together (their patches hold no crossing pair) touch: no volume lies
    // between them. (Their pieces' areas differ -- a wall against a box's face -- and the volume
    // formula read that difference as 13-26 mm of depth, pushing a box off the wall it stood flush
    // against.)
    kc.contact.depth = s.pairCoplanar[kc.pair] != 0 ? 0.0 : s.patchDepth[patch];
    if (s.patchCurved[patch] != 0) localNormal(s, kc.pair, kc.contact);
    out.push_back(kc.contact);
  }
  std::sort(hits.begin(), hits.end());
  return complete;
}

// How a bake gets the section a model needs (apps/clod/cmd_bake.cpp).
constexpr const char* kCfmOption = "'clod bake', which adds closest feature maps by default (--stacks sets their size)";
constexpr const char* kContactTreeOption =
    "'clod bake', which adds the contact tree unless --no-sdf is given (--sdf-error/--sdf-depth set its accuracy)";

void throwMissing(const CollisionBody& body, const char* which, const char* what, const char* model,
                  const char* option) {
  throw Error(ErrorCode::kBakeMissingSection, std::string("body ") + which +
                                                  (body.name().empty() ? "" : " ('" + body.name() + "')") + " has no " +
                                                  what + ", which the " + model + " model needs (bake with " + option + ")");
}

void checkSettings(const QuerySettings& s) {
  if (s.maxContacts == 0) throw Error(ErrorCode::kInvalidArgument, "maxContacts must be >= 1");
  if (s.budget.maxTests == 0) throw Error(ErrorCode::kInvalidArgument, "budget maxTests must be >= 1");
  if (!(s.mergeDistanceRel >= 0.0) || !std::isfinite(s.mergeDistanceRel)) {
    throw Error(ErrorCode::kInvalidArgument, "mergeDistanceRel must be finite and >= 0");
  }
  if (s.budget.now == nullptr) throw Error(ErrorCode::kInvalidArgument, "budget clock is null");
  if (!(s.marginAbs >= 0.0) || !std::isfinite(s.marginAbs)) {
    throw Error(ErrorCode::kInvalidArgument, "marginAbs must be finite and >= 0");
  }
}

// QuerySettings::marginAbs: one speculative contact at the exact closest points of two surfaces
// at most `margin` apart, when no contact of `raw` (world frame) penetrates beyond its error
// bound (a coarse or sampled contact within its bound of zero may be the bodies about to touch,
// and is kept beside it). The closest points are the answer every model would converge to for
// bodies apart, and a pair of points is all a solver needs to stop an approach before it
// penetrates (Bullet and Box2D keep points within a margin the same way).
void addSpeculativeContact(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b,
                           const Pose& xfWorldFromB, double margin, std::uint32_t level,
                           detail::SeparationHeap& heap, std::vector<Contact>& raw) {
  if (std::any_of(raw.begin(), raw.end(), [](const Contact& c) { return c.depth - c.errorBound > 0.0; })) return;
  const Separation gap = detail::separationBetween(a, xfWorldFromA, b, xfWorldFromB, margin, heap);
  if (!gap.withinMax || gap.overlapping || !(gap.distance > 0.0)) return;
  Contact c;
  c.point = 0.5 * (gap.pointA + gap.pointB);
  c.normal = (gap.pointA - gap.pointB) / gap.distance;
  c.depth = -gap.distance;
  c.errorBound = 0.0;
  c.level = level;
  c.featureA = gap.triangleA;
  c.featureB = gap.triangleB;
  c.featureKind = ContactFeature::kTriangle;
  raw.push_back(c);
}

template <class Pair, class SideA, class SideB>
void fillFrontier(const std::vector<Pair>& front, const SideA& sa, const SideB& sb, QueryResult& result) {
  result.frontier.clear();
  result.minLevel = 0;
  result.maxLevel = 0;
  bool first = true;
  for (const Pair& p : front) {
    FrontierPair f{SideA::index(p.a), SideB::index(p.b), sa.level(p.a), sb.level(p.b)};
    result.frontier.push_back(f);
    const std::uint32_t level = std::max(f.levelA, f.levelB);
    result.minLevel = first ? level : std::min(result.minLevel, level);
    result.maxLevel = first ? level : std::max(result.maxLevel, level);
    first = false;
  }
}

// Updates the per-pair answer cost from a timed answer of at least 8 pairs
// (exponential average: one slow answer, e.g. a cold cache, moves it by a quarter).
void learnAnswerCost(const AnswerClock& answer, double& secondsPerPair) {
  if (!answer.timed() || answer.answered() < 8) return;
  const double measured = answer.secondsSinceStart() / static_cast<double>(answer.answered());
  secondsPerPair = 0.75 * secondsPerPair + 0.25 * measured;
}

// Runs the traversal from the roots or from a cache's front. Returns true when finished.
template <class SideA, class SideB, class Pair>
bool traverse(const SideA& sa, const SideB& sb, const Pose& xfAFromB, Meter& meter, std::vector<Pair>& front,
              std::vector<Pair>& next, std::vector<Pair>& separated, bool track, std::vector<Pair>* cachedOverlap,
              std::vector<Pair>* cachedSeparated, std::uint64_t directPairs, double& smallestGap) {
  Traversal<SideA, SideB> t(sa, sb, xfAFromB, meter, directPairs);
  front.clear();
  separated.clear();
  std::vector<Pair>* sep = track ? &separated : nullptr;
  if (cachedOverlap != nullptr) {
    // Last frame's overlapping pairs first (deepest first, as they were left), then the
    // separated ones; under a tight budget the untested keep last frame's status.
    t.retest(*cachedOverlap, true, front, sep);
    t.retest(*cachedSeparated, false, front, sep);
  } else {
    next.clear();
    next.push_back({sa.root(), sb.root(), 0.0});
    t.retest(next, false, front, sep);
  }
  const bool finished = t.refine(front, next, sep);
  smallestGap = t.smallestGap();
  return finished;
}

}  // namespace

void queryContacts(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b, const Pose& xfWorldFromB,
                   const QuerySettings& settings, QueryScratch& scratch, QueryResult& result, CoherenceCache* cache) {
  const auto start = std::chrono::steady_clock::now();
  checkSettings(settings);
  const ContactModel model = settings.model;
  if (model == ContactModel::kCfm || model == ContactModel::kAverage) {
    const char* name = model == ContactModel::kCfm ? "cfm" : "average";
    if (!a.hasClosestFeatureMap()) throwMissing(a, "A", "closest feature map", name, kCfmOption);
    if (!b.hasClosestFeatureMap()) throwMissing(b, "B", "closest feature map", name, kCfmOption);
  }
  if (model == ContactModel::kContactTree) {
    if (!a.hasContactTree()) throwMissing(a, "A", "contact tree", "contact-tree", kContactTreeOption);
    if (!b.hasContactTree()) throwMissing(b, "B", "contact tree", "contact-tree", kContactTreeOption);
  }

  for (const Pose* pose : {&xfWorldFromA, &xfWorldFromB}) {
    // A NaN pose would answer "colliding" with NaN contacts; a zero quaternion has no rotation.
    const double qn = pose->rotation.norm();
    if (!pose->translation.allFinite() || !std::isfinite(qn) || qn < 1e-12) {
      throw Error(ErrorCode::kInvalidArgument, std::string("query: the pose of body ") + (pose == &xfWorldFromA ? "A" : "B") +
                                                   " is not finite or has a zero rotation quaternion");
    }
  }
  QueryScratch::Impl& s = scratch.impl();
  const Pose xfAFromB = xfWorldFromA.inverse() * xfWorldFromB;
  double& answerCost = s.answerSecondsPerPair[static_cast<std::size_t>(model)];
  Meter meter(settings.budget, settings.budget.answerWithinDeadline ? answerCost : 0.0);
  result.contacts.clear();
  result.pairsAnswered = 0;
  result.fallbackPairs = 0;
  result.fallbackModel = model;
  result.triangleTests = 0;
  result.intersectingTriangles.clear();
  s.raw.clear();

  const bool cells = model == ContactModel::kContactTree;
  CoherenceCache::Impl* c = cache ? &cache->impl() : nullptr;
  const bool warm = c != nullptr && c->valid && c->a == &a && c->b == &b && c->cells == cells;
  bool finished = false;
  double sampleMarginAbs = 0.0;  // the contact tree's sample margin this answer uses (below)
  bool exactInterrupted = false;
  double smallestGap = 0.0;  // the traversal's, QueryResult::separation

  const bool surfaceModel = model == ContactModel::kExact || model == ContactModel::kContactTree;
  const bool convexPair = surfaceModel && a.patchIsWholeConvexBody(0) && b.patchIsWholeConvexBody(0);
  if (convexPair) {
    // Two convex polyhedra: the separating-axis test over their face normals and edge-edge axes
    // gives the exact penetration depth and normal, and clipping the facing faces the exact
    // contact polygon -- the triangle-level answer, in one test (convexPolyhedraContacts). The
    // contact tree answers such a pair the same way: the root cell of a convex polyhedron keeps
    // the body's corners as its support points (its hull is the body), so its coarsest answer
    // already knows the whole surface, where sampling its fields at a coarse frontier found a
    // part of a face-on-face overlap (a twisted box on a box rested on three contacts on one
    // side and tipped 8-11 deg at 16 tests per frame; a box sliding down a slope tipped over at
    // 256 tests). cfm's root patches of convex polyhedra answer the same way (sphereContacts).
    convexPolyhedraContacts(a, b, xfAFromB, s.raw);
    meter.take();
    finished = true;
    s.sphereFront.assign(1, SpherePair{0, 0, 0.0});
    fillFrontier(s.sphereFront, SphereSide{a.sphereTree(), a, UINT32_MAX}, SphereSide{b.sphereTree(), b, UINT32_MAX}, result);
    result.pairsAnswered = 1;
    result.colliding = !s.raw.empty();
    if (cache != nullptr) cache->clear();  // nothing to refine: the next query starts from the roots too
    for (Contact& ct : s.raw) ct = toWorld(ct, xfWorldFromA);
  } else if (!cells) {
    const std::uint32_t cap = model == ContactModel::kExact ? UINT32_MAX : settings.maxLevel;
    const bool wholeBodyIsLeaf = model == ContactModel::kCfm && settings.maxLevel == UINT32_MAX;
    const SphereSide sa{a.sphereTree(), a, cap, wholeBodyIsLeaf};
    const SphereSide sb{b.sphereTree(), b, cap, wholeBodyIsLeaf};
    finished = traverse(sa, sb, xfAFromB, meter, s.sphereFront, s.sphereNext, s.sphereSeparated, c != nullptr,
                        warm ? &c->sphereOverlapping : nullptr, warm ? &c->sphereSeparated : nullptr,
                        model == ContactModel::kExact ? kExactDirectPairs : 0, smallestGap);
    fillFrontier(s.sphereFront, sa, sb, result);
    if (model == ContactModel::kExact) {
      const bool complete =
          exactContacts(a, b, xfAFromB, s.sphereFront, finished, meter, s, s.raw, result.triangleTests,
                        result.intersectingTriangles);
      for (std::uint8_t done : s.pairDone) result.pairsAnswered += done;
      if (!complete) {
        // Frontier pairs that did not get their triangle tests answer from their spheres: as cfm
        // does when both bodies carry closest feature maps (no tests: the maps and patches are
        // looked up, not tested), else with D&O contacts. D&O normals follow the sphere centre
        // lines and were as far off as dos's (bunny at 1024 tests: 19.8 deg median).
        s.sphereNext.clear();
        for (std::size_t i = 0; i < s.sphereFront.size(); ++i) {
          if (!s.pairDone[i]) s.sphereNext.push_back(s.sphereFront[i]);
        }
        const ContactModel fallback =
            a.hasClosestFeatureMap() && b.hasClosestFeatureMap() ? ContactModel::kCfm : ContactModel::kDos;
        AnswerClock answer(settings.budget, kAnswerBatch);
        sphereContacts(fallback, a, b, xfAFromB, s.sphereNext, answer, s, s.raw);
        learnAnswerCost(answer, answerCost);
        result.fallbackPairs = s.sphereNext.size();
        result.fallbackModel = fallback;
        result.pairsAnswered += answer.answered();
        finished = false;
        exactInterrupted = fallback == ContactModel::kCfm;
        // cfm drops pairs proven apart, as in the cfm model: then colliding means some contact.
        result.colliding = fallback == ContactModel::kCfm ? !s.raw.empty() : !s.sphereFront.empty();
      } else {
        result.colliding = !s.raw.empty();
      }
    } else {
      AnswerClock answer(settings.budget, kAnswerBatch);
      sphereContacts(model, a, b, xfAFromB, s.sphereFront, answer, s, s.raw);
      learnAnswerCost(answer, answerCost);
      result.pairsAnswered = answer.answered();
      // cfm drops pairs proven apart: colliding means some pair gave a contact.
      result.colliding = model == ContactModel::kCfm ? !s.raw.empty() : !s.sphereFront.empty();
    }
    if (c != nullptr) {
      c->a = &a;
      c->b = &b;
      c->cells = false;
      c->valid = !s.sphereFront.empty();
      c->sphereOverlapping.assign(s.sphereFront.begin(), s.sphereFront.end());
      c->sphereSeparated.assign(s.sphereSeparated.begin(), s.sphereSeparated.end());
    }
    for (Contact& ct : s.raw) ct = toWorld(ct, xfWorldFromA);
  } else {
    const CellSide sa{a.contactTree(), settings.maxLevel};
    const CellSide sb{b.contactTree(), settings.maxLevel};
    finished = traverse(sa, sb, xfAFromB, meter, s.cellFront, s.cellNext, s.cellSeparated, c != nullptr,
                        warm ? &c->cellOverlapping : nullptr, warm ? &c->cellSeparated : nullptr, 0, smallestGap);
    fillFrontier(s.cellFront, sa, sb, result);
    ContactSamplingSettings sampling = settings.contactSampling;
    // Samples within the margin of touching are contacts only in a finished answer: an
    // interrupted one's depths are its coarse cells' support points, known only to within their
    // bounds (centimetres on a 1 m box), so "within the margin" says nothing there.
    sampleMarginAbs = finished ? settings.contactSampling.marginAbs : 0.0;
    sampling.marginAbs = sampleMarginAbs;
    sampling.maxDepth = kContactTreeLeafDepth;
    sampling.supportPoints = !finished;
    s.sampled.clear();
    AnswerClock answer(settings.budget, 1);
    for (const CellPair& p : s.cellFront) {
      if (!answer.next(!s.raw.empty())) break;
      // Field queries always go to the leaves: the budget buys traversal, and a coarse cell's
      // trilinear field is too smooth to say whether a sample penetrates (measured: a box on a
      // box then gets no contact at all from a 16-test traversal). O(depth) per sample.
      const std::size_t first = s.sampled.size();
      sampleCellPair(a.contactTree(), p.a, xfWorldFromA, b.contactTree(), p.b, xfWorldFromB, sampling, s.sampled);
      const std::size_t mid = s.sampled.size();
      sampleCellPair(b.contactTree(), p.b, xfWorldFromB, a.contactTree(), p.a, xfWorldFromA, sampling, s.sampled);
      // The reverse call's normals point out of A toward B: flip them to B -> A.
      for (std::size_t i = mid; i < s.sampled.size(); ++i) s.sampled[i].normal = -s.sampled[i].normal;
      const std::uint32_t level = std::max(p.a.depth, p.b.depth);
      for (std::size_t i = first; i < s.sampled.size(); ++i) {
        const ContactPoint& cp = s.sampled[i];
        if (cp.depth < -sampleMarginAbs) continue;
        Contact ct;
        ct.point = cp.point;
        ct.normal = cp.normal;
        ct.depth = cp.depth;
        ct.errorBound = cp.errorBound;
        ct.level = level;
        ct.featureA = p.a.node;
        ct.featureB = p.b.node;
        ct.featureKind = ContactFeature::kCell;
        s.raw.push_back(ct);
      }
    }
    learnAnswerCost(answer, answerCost);
    result.pairsAnswered = answer.answered();
    result.colliding = !s.raw.empty();
    if (c != nullptr) {
      c->a = &a;
      c->b = &b;
      c->cells = true;
      c->valid = !s.cellFront.empty();
      c->cellOverlapping.assign(s.cellFront.begin(), s.cellFront.end());
      c->cellSeparated.assign(s.cellSeparated.begin(), s.cellSeparated.end());
    }
  }

  bool found = false;  // a containment answer replaced the contacts
  {
    // Containment (docs/narrow-phase.md): one closed body wholly inside the other. Its surfaces
    // meet nothing: the query found no contact, or only loose sphere pairs' ones. A few exact field
    // queries, only when the root spheres overlap (and, with contacts, only when one root sphere
    // lies inside the other); counted as tests as far as the budget allows (the answer is given
    // whatever the budget).
    const bool haveContacts = !s.raw.empty();
    const std::size_t first = s.raw.size();
    const std::uint32_t queries = detail::containmentContacts(a, b, xfAFromB, settings.maxContacts, haveContacts,
                                                              s.containment, s.raw, found);
    meter.count(queries);
    if (found) {
      s.raw.erase(s.raw.begin(), s.raw.begin() + static_cast<std::ptrdiff_t>(first));
      result.colliding = true;
      for (Contact& ct : s.raw) ct = toWorld(ct, xfWorldFromA);
    }
  }

  if (settings.marginAbs > 0.0 && !found) {
    addSpeculativeContact(a, xfWorldFromA, b, xfWorldFromB, settings.marginAbs, result.maxLevel, s.separationHeap,
                          s.raw);
  }

  result.rawContacts = s.raw.size();
  ManifoldSettings manifold;
  manifold.maxContacts = settings.maxContacts;
  manifold.mergeDistanceAbs = settings.mergeDistanceRel * std::min(a.diagonal(), b.diagonal());
  // Normal pooling (ManifoldSettings::poolNormalsCos) for the contacts of the sphere-tree
  // lookups, whose normals are noisy one by one: cfm, and an interrupted exact query (its
  // unfinished pairs answer as cfm). 60 deg: contacts of one curved patch differ by tens of
  // degrees, a floor and a wall by 90. Measured (bunny / fandisk full-budget cfm median
  // normal error, 300 poses, docs/benchmarks/narrowphase.md): off 8.87 / 13.53 deg, 30 deg
  // 7.07 / 12.71, 45 deg 6.52 / 11.67, 60 deg 6.49 / 11.81, 90 deg 6.26 / 10.54.
  if (model == ContactModel::kCfm || exactInterrupted) manifold.poolNormalsCos = kPoolNormalsCos;
  const std::size_t kept = reduceManifold(s.raw, manifold, s.manifold);
  result.contacts.assign(s.raw.begin(), s.raw.begin() + static_cast<std::ptrdiff_t>(kept));
  // The contact tree's lattice samples lie inside the rim of their contact area: push the kept
  // ones out to it (contact_rim.h), so the manifold has the support polygon the bodies have.
  // Not counted as tests (like the sampling, the budget buys traversal) and not begun past an
  // answer deadline.
  const bool answerTimeLeft = !(settings.budget.deadline != QueryBudget::TimePoint::max() &&
                                settings.budget.answerWithinDeadline && settings.budget.now() >= settings.budget.deadline);
  if (cells && !convexPair && !found && kept >= 2 && answerTimeLeft) {
    extendContactsToRim(a.contactTree(), xfWorldFromA, b.contactTree(), xfWorldFromB, result.contacts,
                        sampleMarginAbs);
  }
  std::stable_sort(result.contacts.begin(), result.contacts.end(),
                   [](const Contact& x, const Contact& y) { return x.depth > y.depth; });

  result.tests = meter.used();
  result.sphereTests = result.tests - result.triangleTests;
  result.finished = finished && !meter.stopped();
  // Proven apart: a finished traversal with an empty answer frontier separated every pair by its
  // bounding spheres, which hold the surfaces, so the smallest such gap bounds the surfaces'
  // distance (a convex pair's separating-axis answer is not a traversal: 0).
  const bool frontEmpty = cells ? s.cellFront.empty() : s.sphereFront.empty();
  result.separation = !convexPair && result.finished && frontEmpty && result.contacts.empty() && std::isfinite(smallestGap)
                          ? smallestGap
                          : 0.0;
  result.stop = result.finished ? QueryStop::kFinished : (meter.stopped() ? meter.stop() : QueryStop::kTestBudget);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double proveApart(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b, const Pose& xfWorldFromB,
                  std::uint64_t maxTests, QueryScratch& scratch, std::uint64_t* testsUsed) {
  if (testsUsed != nullptr) *testsUsed = 0;
  if (maxTests == 0) return 0.0;
  QueryScratch::Impl& s = scratch.impl();
  const Pose xfAFromB = xfWorldFromA.inverse() * xfWorldFromB;
  Meter meter(QueryBudget::tests(maxTests), 0.0);
  const SphereSide sa{a.sphereTree(), a, UINT32_MAX};
  const SphereSide sb{b.sphereTree(), b, UINT32_MAX};
  double gap = 0.0;
  using SpherePairs = std::vector<SpherePair>;
  const bool finished = traverse(sa, sb, xfAFromB, meter, s.sphereFront, s.sphereNext, s.sphereSeparated, false,
                                 static_cast<SpherePairs*>(nullptr), static_cast<SpherePairs*>(nullptr), 0, gap);
  std::uint64_t used = meter.used();
  double proven = 0.0;
  if (finished && !meter.stopped() && s.sphereFront.empty() && std::isfinite(gap) && gap > 0.0) {
    // Apart surfaces with one closed body inside the other are the deepest overlap there is.
    bool contained = false;
    s.raw.clear();
    used += detail::containmentContacts(a, b, xfAFromB, 1, false, s.containment, s.raw, contained);
    s.raw.clear();
    if (!contained) proven = gap;
  }
  if (testsUsed != nullptr) *testsUsed = used;
  return proven;
}

QueryResult queryContacts(const CollisionBody& a, const Pose& xfWorldFromA, const CollisionBody& b,
                          const Pose& xfWorldFromB, const QuerySettings& settings) {
  QueryScratch scratch;
  QueryResult result;
  queryContacts(a, xfWorldFromA, b, xfWorldFromB, settings, scratch, result);
  return result;
}

std::string_view queryStopName(QueryStop stop) noexcept {
  switch (stop) {
    case QueryStop::kFinished: return "finished";
    case QueryStop::kTestBudget: return "test_budget";
    case QueryStop::kDeadline: return "deadline";
  }
  return "unknown";
}

}  // namespace clod
