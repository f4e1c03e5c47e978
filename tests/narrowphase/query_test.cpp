// The anytime narrow phase against analytic answers (cube on cube, sphere on sphere), budget and
// deadline accounting, and temporal coherence.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>
#include <random>
#include <string>
#include <vector>

#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::settingsFor;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Two unit cubes (half extent 1) and two icospheres (radius 1, 1280 triangles), three levels.
struct Bodies {
  CollisionBody cubeA, cubeB, sphereA, sphereB;
  Bodies()
      : cubeA(test::makeTestBody(makeBox(Vec3::Constant(1.0)), 2)),
        cubeB(test::makeTestBody(makeBox(Vec3::Constant(1.0)), 2)),
        sphereA(test::makeTestBody(makeIcosphere(1.0, 3), 2)),
        sphereB(test::makeTestBody(makeIcosphere(1.0, 3), 2)) {}
};

const Bodies& bodies() {
  static const Bodies b;
  return b;
}

const std::vector<std::uint64_t>& budgets() {
  static const std::vector<std::uint64_t> b = {16, 64, 256, 1024, kUnlimitedTests};
  return b;
}

// Cube A resting face-down on cube B (at the origin), pushed `penetration` into it, offset
// sideways by (dx, dy): up to a quarter of the width (0.5).
Pose restingPose(double dx, double dy, double penetration) {
  Pose p;
  p.translation = Vec3(dx, dy, 2.0 - penetration);
  return p;
}

const std::vector<Vec3>& restingOffsets() {
  // Both components non-zero: equal cubes offset along one axis only have flush side faces
  // (coplanar, facing the same way) whose shared edges make the contact degenerate, see
  // docs/narrow-phase.md.
  static const std::vector<Vec3> o = {{0.5, 0.25, 0}, {0.3, 0.2, 0}, {-0.5, 0.4, 0}, {0.1, -0.45, 0}, {-0.25, -0.5, 0}, {0.05, 0.05, 0}};
  return o;
}

// Penetration 0.5 % of the width: a resting contact, well above rounding, below any level's
// sphere overshoot.
constexpr double kRestingPenetration = 0.01;

// Depth-weighted resultant of a manifold's normals: the direction of the total impulse a
// penalty or impulse solver applies for it.
Vec3 resultantNormal(const QueryResult& r) {
  Vec3 sum = Vec3::Zero();
  for (const Contact& c : r.contacts) sum += std::max(c.depth, 0.0) * c.normal;
  if (sum.squaredNorm() == 0.0) {
    for (const Contact& c : r.contacts) sum += c.normal;
  }
  return sum.normalized();
}

double meanAngleToUp(const QueryResult& r) {
  double sum = 0.0;
  for (const Contact& c : r.contacts) sum += angleBetween(c.normal, Vec3::UnitZ());
  return r.contacts.empty() ? 0.0 : sum / static_cast<double>(r.contacts.size());
}

TEST(NarrowPhaseCubeOnCube, CfmGivesTheFaceNormalWithinTwoDegreesAtEveryBudget) {
  // Every contact of every budget, as the issue asks. 2 degrees: the map's 16-bit normal codec
  // is good to ~0.95 degrees, the face normals of the box are exact.
  const Bodies& b = bodies();
  int contacts = 0;
  for (const Vec3& offset : restingOffsets()) {
    const Pose poseA = restingPose(offset.x(), offset.y(), kRestingPenetration);
    for (std::uint64_t budget : budgets()) {
      const QueryResult r = queryContacts(b.cubeA, poseA, b.cubeB, Pose{}, settingsFor(ContactModel::kCfm, budget));
      ASSERT_TRUE(r.colliding);
      ASSERT_FALSE(r.contacts.empty());
      EXPECT_LE(r.contacts.size(), 8u);
      for (const Contact& c : r.contacts) {
        ++contacts;
        EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 2.0 * kDegree)
            << "offset " << offset.transpose() << " budget " << budget << " level " << c.level << " normal "
            << c.normal.transpose() << " at " << c.point.transpose();
      }
    }
  }
  EXPECT_GT(contacts, 100);  // the poses and budgets produce many contacts (228 when written)
}

TEST(NarrowPhaseCubeOnCube, CfmGivesTheFaceNormalForAlmostAllContactsOfTurnedCubes) {
  // Beyond the case: cube A resting on a face of B, turned about the normal by a random
  // angle (its edges cross B's at random angles) and offset by up to a quarter width, the pair
  // rolled onto another face so the normal is not +z. Here a patch pair's own least-overlap
  // axis can be a side face where a corner of A pokes a few thousandths past B's side plane (or
  // a corner of B past A's): the local patches cannot see the rest of the bodies. Measured with
  // 200 poses x 5 budgets: 7,904 of 7,915 contacts within 2 degrees (11 off, 0.14 %) with the
  // sphere-trees of commit d874279, all 7,588 with those of 7982bde (the medial builder changed).
  // Asserted: 99.5 % of the contacts within 2 degrees.
  const Bodies& b = bodies();
  std::mt19937_64 rng(23);
  // Turns between 10 and 80 degrees (mod 90): edges of A and B at least 10 degrees from
  // parallel. Nearly parallel side faces a few thousandths apart are the near-degenerate version
  // of the flush case (docs/narrow-phase.md, known limits).
  std::uniform_real_distribution<double> angle(10.0 * kDegree, 80.0 * kDegree), offset(-0.5, 0.5);
  std::uniform_int_distribution<int> quarter(0, 3);
  const int poses = test::sanitizerRun() ? 10 : 200;
  const Quat roll(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()));  // B's +z face turned to -y
  const Vec3 up = roll * Vec3::UnitZ();
  int contacts = 0, within = 0;
  QueryScratch scratch;
  QueryResult r;
  for (int i = 0; i < poses; ++i) {
    Pose poseA;
    poseA.rotation = roll * Quat(Eigen::AngleAxisd(angle(rng) + 0.5 * kPi * quarter(rng), Vec3::UnitZ()));
    poseA.translation = roll * Vec3(offset(rng), offset(rng), 2.0 - kRestingPenetration);
    Pose poseB;
    poseB.rotation = roll;
    for (std::uint64_t budget : budgets()) {
      queryContacts(b.cubeA, poseA, b.cubeB, poseB, settingsFor(ContactModel::kCfm, budget), scratch, r);
      ASSERT_TRUE(r.colliding);
      ASSERT_FALSE(r.contacts.empty());
      for (const Contact& c : r.contacts) {
        ++contacts;
        within += angleBetween(c.normal, up) < 2.0 * kDegree ? 1 : 0;
      }
    }
  }
  std::printf("cfm turned cube on cube: %d of %d contacts within 2 degrees\n", within, contacts);
  EXPECT_GE(static_cast<double>(within), 0.995 * contacts);
}

TEST(NarrowPhaseCubeOnCube, ContactTreeAndExactGiveTheFaceNormalAtFullBudget) {
  const Bodies& b = bodies();
  for (ContactModel model : {ContactModel::kContactTree, ContactModel::kExact}) {
    for (const Vec3& offset : restingOffsets()) {
      const Pose poseA = restingPose(offset.x(), offset.y(), kRestingPenetration);
      const QueryResult r = queryContacts(b.cubeA, poseA, b.cubeB, Pose{}, settingsFor(model, kUnlimitedTests));
      ASSERT_TRUE(r.finished);
      ASSERT_TRUE(r.colliding) << contactModelName(model);
      ASSERT_GE(r.contacts.size(), 3u) << contactModelName(model);  // a face contact needs a support polygon
      EXPECT_LE(r.contacts.size(), 8u);
      if (model == ContactModel::kExact) {
        EXPECT_LT(angleBetween(resultantNormal(r), Vec3::UnitZ()), 2.0 * kDegree) << offset.transpose();
      }
      for (const Contact& c : r.contacts) {
        // Exact: every contact. Contact tree: its sampling gives a field gradient at the two
        // points where an edge of A crosses an edge of B (contact_sampling.h's face-wins rule
        // covers edge-on-face only), reported to its owner; the other contacts must be right.
        auto nearEdge = [](double coordinate, double centre) { return std::abs(std::abs(coordinate - centre) - 1.0) < 0.05; };
        const bool edgeCrossing = (nearEdge(c.point.x(), 0.0) && nearEdge(c.point.y(), offset.y())) ||
                                  (nearEdge(c.point.y(), 0.0) && nearEdge(c.point.x(), offset.x()));
        if (model == ContactModel::kExact || !edgeCrossing) {
          EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 2.0 * kDegree)
              << contactModelName(model) << " offset " << offset.transpose() << " normal " << c.normal.transpose()
              << " at " << c.point.transpose();
        }
        // Contacts lie in the overlap of the two faces, at the contact plane z = 1, within the
        // penetration (exact) or the contact tree's field error (2e-3 of the diagonal each).
        EXPECT_NEAR(c.point.z(), 1.0, 0.05) << contactModelName(model);
        // Across the faces: exact to rounding; contact-tree samples of inner cells are moved
        // onto the zero level of the interpolated field, stopping within twice the field's
        // error (projectOntoSurface), so they may lie that far past an edge.
        const double across = model == ContactModel::kExact ? 1e-6 : 2.0 * b.cubeA.contactTree().errorAbs;
        EXPECT_LE(std::abs(c.point.x()), 1.0 + across);
        EXPECT_LE(std::abs(c.point.x() - offset.x()), 1.0 + across);
      }
    }
  }
}

TEST(NarrowPhaseCubeOnCube, CfmAndContactTreeAreNeverWorseThanDos) {
  const Bodies& b = bodies();
  for (const Vec3& offset : restingOffsets()) {
    const Pose poseA = restingPose(offset.x(), offset.y(), kRestingPenetration);
    for (std::uint64_t budget : budgets()) {
      const double dos = meanAngleToUp(queryContacts(b.cubeA, poseA, b.cubeB, Pose{}, settingsFor(ContactModel::kDos, budget)));
      for (ContactModel model : {ContactModel::kCfm, ContactModel::kContactTree}) {
        const QueryResult r = queryContacts(b.cubeA, poseA, b.cubeB, Pose{}, settingsFor(model, budget));
        ASSERT_FALSE(r.contacts.empty()) << contactModelName(model) << " budget " << budget;
        // 1e-9 rad: rounding only.
        EXPECT_LE(meanAngleToUp(r), dos + 1e-9)
            << contactModelName(model) << " offset " << offset.transpose() << " budget " << budget;
      }
    }
  }
}

TEST(NarrowPhaseSpheres, EveryModelGivesTheCentreLine) {
  // The sphere models at the root (budget 1: the root pair's test only), the surface models
  // (contact tree, exact) at full budget. Deeper sphere pairs of a sphere-tree of a sphere are
  // not centred on the bodies' centre line, so their D&O normals are not the centre line either
  // (measured in docs/benchmarks/narrowphase.md), which is the paper's point.
  const Bodies& b = bodies();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  for (int trial = 0; trial < 6; ++trial) {
    Vec3 dir(gauss(rng), gauss(rng), gauss(rng));
    dir.normalize();
    Pose poseA;
    poseA.translation = 1.9 * dir;  // 0.1 overlap of two unit spheres
    for (ContactModel model : allContactModels()) {
      const bool surfaceModel = model == ContactModel::kContactTree || model == ContactModel::kExact;
      const QueryResult r =
          queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, settingsFor(model, surfaceModel ? kUnlimitedTests : 1));
      ASSERT_TRUE(r.colliding) << contactModelName(model);
      ASSERT_FALSE(r.contacts.empty()) << contactModelName(model);
      // dos: the root spheres are concentric with the bodies, so the centre line up to the
      // builder's rounding. cfm/average: the nearest sample is up to half a ring spacing away in
      // both phi and theta (16 stacks: 5.6 deg each, ~8 deg together) and the icosphere's facet
      // normals deviate from radial by up to ~4.6 deg: 13 degrees. Exact / contact tree: facet
      // tilt and the field's gradient error, averaged over the manifold; 6 degrees.
      double tolerance = 6.0 * kDegree;
      if (model == ContactModel::kDos) tolerance = 1e-6;
      if (model == ContactModel::kCfm || model == ContactModel::kAverage) tolerance = 13.0 * kDegree;
      EXPECT_LT(angleBetween(resultantNormal(r), dir), tolerance) << contactModelName(model);
      for (const Contact& c : r.contacts) {
        // The overlap lens is centred at 0.95 dir with radius ~0.31.
        EXPECT_LT((c.point - 0.95 * dir).norm(), 0.35 + c.errorBound) << contactModelName(model);
      }
    }
  }
}

TEST(NarrowPhaseSpheres, SeparatedSpheresDoNotCollide) {
  const Bodies& b = bodies();
  Pose poseA;
  poseA.translation = Vec3(0.3, 2.2, -0.4);
  for (ContactModel model : allContactModels()) {
    const QueryResult r = queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, settingsFor(model, kUnlimitedTests));
    EXPECT_FALSE(r.colliding) << contactModelName(model);
    EXPECT_TRUE(r.contacts.empty());
    EXPECT_TRUE(r.finished);
  }
}

// A NaN or infinite pose, or a zero quaternion, would answer "colliding" with NaN contacts: every
// model refuses it with kInvalidArgument instead.
TEST(NarrowPhaseSpheres, NonFinitePosesAreRefusedByEveryModel) {
  const Bodies& b = bodies();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::pair<Pose, Pose>> bad(3);
  bad[0].first.translation = Vec3(nan, 0.0, 0.0);
  bad[1].second.rotation = Quat(std::numeric_limits<double>::infinity(), 0.0, 0.0, 0.0);
  bad[2].second.rotation = Quat(0.0, 0.0, 0.0, 0.0);
  for (ContactModel model : allContactModels()) {
    for (const auto& [poseA, poseB] : bad) {
      ErrorCode code{};
      try {
        queryContacts(b.sphereA, poseA, b.sphereB, poseB, settingsFor(model, kUnlimitedTests));
      } catch (const Error& e) {
        code = e.code();
      }
      EXPECT_EQ(code, ErrorCode::kInvalidArgument) << contactModelName(model);
    }
  }
}

TEST(NarrowPhaseBudget, TestCountIsNeverExceeded) {
  const Bodies& b = bodies();
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::uint64_t> budget(1, 600);
  const int poses = test::sanitizerRun() ? 40 : 200;
  QueryScratch scratch;
  QueryResult r;
  for (int i = 0; i < poses; ++i) {
    const Pose poseA = test::randomPose(rng, 1.5);
    const Pose poseB = test::randomPose(rng, 0.5);
    const CollisionBody& a = (i % 2) ? b.cubeA : b.sphereA;
    for (ContactModel model : allContactModels()) {
      QuerySettings s = settingsFor(model, budget(rng));
      queryContacts(a, poseA, b.sphereB, poseB, s, scratch, r);
      ASSERT_LE(r.tests, s.budget.maxTests) << contactModelName(model);
      EXPECT_EQ(r.tests, r.sphereTests + r.triangleTests);
      // Out of tests means exactly all of them were used.
      if (r.stop == QueryStop::kTestBudget) {
        EXPECT_EQ(r.tests, s.budget.maxTests);
      }
      EXPECT_LE(r.contacts.size(), s.maxContacts);
      EXPECT_EQ(r.finished, r.stop == QueryStop::kFinished);
    }
  }
}

// A fake clock that advances by one tick per read, so the deadline is crossed after a known
// number of reads and the overrun is counted in tests, not timed.
std::int64_t gTicks = 0;
QueryBudget::TimePoint tickClock() { return QueryBudget::TimePoint(QueryBudget::Clock::duration(gTicks++)); }

TEST(NarrowPhaseBudget, DeadlineOverrunIsAtMostOneBatch) {
  const Bodies& b = bodies();
  Pose poseA;
  poseA.translation = Vec3(0.3, 0.1, 1.2);  // deep overlap: thousands of tests to finish
  const QueryResult full = queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, settingsFor(ContactModel::kExact, kUnlimitedTests));
  ASSERT_GT(full.tests, 20u * kDeadlineBatch);
  for (std::int64_t readsBefore : {0, 1, 3, 10}) {
    for (ContactModel model : allContactModels()) {
      gTicks = 0;
      QuerySettings s = settingsFor(model, kUnlimitedTests);
      s.budget.now = &tickClock;
      s.budget.deadline = QueryBudget::TimePoint(QueryBudget::Clock::duration(readsBefore));
      // The traversal's own accounting: no reserve for the answer, no clock reads while answering
      // (NarrowPhaseBudget.AnswerEndsByTheDeadline covers those).
      s.budget.answerWithinDeadline = false;
      const QueryResult r = queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, s);
      // Reads 0 .. readsBefore-1 see a time before the deadline and each grants one batch; the
      // first batch needs no read. The read that sees the deadline stops the query at once.
      const std::uint64_t allowed = static_cast<std::uint64_t>(readsBefore + 1) * kDeadlineBatch;
      EXPECT_LE(r.tests, allowed) << contactModelName(model);
      if (!r.finished) {
        EXPECT_EQ(r.stop, QueryStop::kDeadline);
        EXPECT_EQ(r.tests, allowed) << contactModelName(model);
        EXPECT_EQ(gTicks, readsBefore + 1);
      }
    }
  }
  // With the real clock and a deadline already past, one batch at most.
  QuerySettings s = settingsFor(ContactModel::kCfm, kUnlimitedTests);
  s.budget.deadline = QueryBudget::Clock::now() - std::chrono::seconds(1);
  const QueryResult r = queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, s);
  EXPECT_LE(r.tests, kDeadlineBatch);
  EXPECT_FALSE(r.finished);
}

TEST(NarrowPhaseBudget, AnswerEndsByTheDeadline) {
  // The traversal stops at the deadline (no reserve for the answer: the estimate is pinned to
  // 0), so the answer starts past it: it answers one batch of frontier pairs (8 sphere pairs or
  // 1 cell pair), then reads the clock, sees the deadline and leaves the rest of the frontier
  // unanswered -- unless no contact came yet, then up to kDeadlineBatch more pairs (budget.h). Before, the whole frontier was answered after the deadline
  // (a cfm query with a 100 us deadline on two deep bunnies returned after 1.1 ms).
  const Bodies& b = bodies();
  Pose poseA;
  poseA.translation = Vec3(0.3, 0.1, 1.2);  // deep overlap: frontiers of hundreds of pairs
  for (ContactModel model : allContactModels()) {
    gTicks = 0;
    QueryScratch scratch;
    scratch.setAnswerSecondsPerPair(model, 0.0);
    QuerySettings s = settingsFor(model, kUnlimitedTests);
    s.budget.now = &tickClock;
    s.budget.deadline = QueryBudget::TimePoint(QueryBudget::Clock::duration(20));
    QueryResult r;
    queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, s, scratch, r);
    ASSERT_EQ(r.stop, QueryStop::kDeadline) << contactModelName(model);
    ASSERT_GT(r.frontier.size(), kDeadlineBatch) << contactModelName(model);
    EXPECT_GE(r.pairsAnswered, 1u) << contactModelName(model);
    EXPECT_LE(r.pairsAnswered, 2 * kDeadlineBatch) << contactModelName(model);
    EXPECT_LT(r.pairsAnswered, r.frontier.size()) << contactModelName(model);
    EXPECT_FALSE(r.contacts.empty()) << contactModelName(model);

    // The same query with the answer outside the deadline answers every frontier pair.
    gTicks = 0;
    s.budget.answerWithinDeadline = false;
    queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, s, scratch, r);
    EXPECT_EQ(r.pairsAnswered, r.frontier.size()) << contactModelName(model);
  }
}

TEST(NarrowPhaseBudget, TraversalStopsEarlyEnoughToAnswerItsFrontier) {
  // Fake clock: one tick (1 ns) per read. With an answer cost of 1 ns per frontier pair the
  // traversal must stop at the first batch boundary where "now + frontier size" reaches the
  // deadline, so its frontier cannot exceed the deadline's tick count by more than one batch of
  // tests can add (each test adds at most one pair). Without the reserve it runs to the deadline.
  const Bodies& b = bodies();
  Pose poseA;
  poseA.translation = Vec3(0.3, 0.1, 1.2);
  constexpr std::int64_t kDeadlineTicks = 100;
  for (ContactModel model : allContactModels()) {
    QuerySettings s = settingsFor(model, kUnlimitedTests);
    s.budget.now = &tickClock;
    s.budget.deadline = QueryBudget::TimePoint(QueryBudget::Clock::duration(kDeadlineTicks));
    QueryScratch scratch;
    scratch.setAnswerSecondsPerPair(model, 1e-9);
    gTicks = 0;
    QueryResult reserved;
    queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, s, scratch, reserved);
    scratch.setAnswerSecondsPerPair(model, 0.0);
    gTicks = 0;
    QueryResult unreserved;
    queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, s, scratch, unreserved);
    ASSERT_EQ(reserved.stop, QueryStop::kDeadline) << contactModelName(model);
    EXPECT_LE(reserved.frontier.size(), static_cast<std::size_t>(kDeadlineTicks) + kDeadlineBatch)
        << contactModelName(model);
    EXPECT_LT(reserved.tests, unreserved.tests) << contactModelName(model);
  }
}

TEST(NarrowPhaseBudget, AnswerCostMustBeFiniteAndNonNegative) {
  QueryScratch scratch;
  EXPECT_THROW(scratch.setAnswerSecondsPerPair(ContactModel::kCfm, -1.0), Error);
  EXPECT_THROW(scratch.setAnswerSecondsPerPair(ContactModel::kCfm, std::nan("")), Error);
  scratch.setAnswerSecondsPerPair(ContactModel::kCfm, 2e-7);
  EXPECT_EQ(scratch.answerSecondsPerPair(ContactModel::kCfm), 2e-7);
}

double penetration(const SphereTree& ta, std::uint32_t a, const SphereTree& tb, std::uint32_t b, const Pose& xfAFromB) {
  return ta.radius[a] + tb.radius[b] - (ta.center(a) - xfAFromB.apply(tb.center(b))).norm();
}

TEST(NarrowPhaseBudget, InterruptedQuerySpendsItsTestsOnTheDeepestPairsFirst) {
  // Within a round, pairs are expanded deepest penetration first. So when a budget stops a round,
  // every pair left unexpanded penetrates no deeper than any pair that was expanded in that round.
  const Bodies& b = bodies();
  const SphereTree& ta = b.sphereA.sphereTree();
  const SphereTree& tb = b.sphereB.sphereTree();
  Pose poseA;
  poseA.translation = Vec3(0.2, 0.1, 1.5);
  int interruptedMidRound = 0;
  for (std::uint64_t budget = 10; budget < 400; budget += 7) {
    const QueryResult r = queryContacts(b.sphereA, poseA, b.sphereB, Pose{}, settingsFor(ContactModel::kDos, budget));
    if (r.finished) break;
    std::uint32_t minRound = ~0u, maxRound = 0;
    for (const FrontierPair& f : r.frontier) {
      minRound = std::min(minRound, f.levelA + f.levelB);
      maxRound = std::max(maxRound, f.levelA + f.levelB);
    }
    if (minRound == maxRound) continue;
    ++interruptedMidRound;
    double shallowestExpanded = 1e300, deepestKept = -1e300;
    for (const FrontierPair& f : r.frontier) {
      if (f.levelA + f.levelB == minRound) {
        deepestKept = std::max(deepestKept, penetration(ta, f.nodeA, tb, f.nodeB, poseA.inverse()));
        continue;
      }
      // The parent pair, by the documented rule (descend the larger sphere; a leaf is never
      // descended): (parent(a), b) if that pair would split A, (a, parent(b)) if it would split B.
      const std::uint32_t pa = ta.parent[f.nodeA];
      const std::uint32_t pb = tb.parent[f.nodeB];
      const bool leafA = ta.childCount[f.nodeA] == 0, leafB = tb.childCount[f.nodeB] == 0;
      const bool viaA = pa != kNoSphere && (leafB || ta.radius[pa] >= tb.radius[f.nodeB]);
      const bool viaB = pb != kNoSphere && (leafA || ta.radius[f.nodeA] < tb.radius[pb]);
      if (viaA == viaB) continue;  // ambiguous (or impossible): not used
      const double parentPen = viaA ? penetration(ta, pa, tb, f.nodeB, poseA.inverse())
                                    : penetration(ta, f.nodeA, tb, pb, poseA.inverse());
      shallowestExpanded = std::min(shallowestExpanded, parentPen);
    }
    EXPECT_LE(deepestKept, shallowestExpanded + 1e-12) << "budget " << budget;
  }
  EXPECT_GT(interruptedMidRound, 3);
}

TEST(NarrowPhaseCoherence, CachedQueryEqualsColdQueryAtUnlimitedBudget) {
  const Bodies& b = bodies();
  CoherenceCache cache;
  QueryScratch scratch, coldScratch;
  QueryResult warm, cold;
  const int frames = test::sanitizerRun() ? 8 : 30;
  for (ContactModel model : {ContactModel::kExact, ContactModel::kDos, ContactModel::kContactTree}) {
    cache.clear();
    for (int f = 0; f < frames; ++f) {
      // Cube A slides over sphere B and rotates, in small steps; it separates near the end.
      Pose poseA;
      poseA.rotation = Quat(Eigen::AngleAxisd(0.02 * f, Vec3(1, 2, 3).normalized()));
      poseA.translation = Vec3(-0.6 + 0.05 * f, 0.1, 1.8 + (f > frames - 5 ? 0.3 * (f - frames + 5) : 0.0));
      const QuerySettings s = settingsFor(model, kUnlimitedTests);
      queryContacts(b.cubeA, poseA, b.sphereB, Pose{}, s, scratch, warm, &cache);
      queryContacts(b.cubeA, poseA, b.sphereB, Pose{}, s, coldScratch, cold);
      ASSERT_TRUE(warm.finished);
      if (model != ContactModel::kExact) {
        // Front tracking may keep leaf pairs whose ancestors no longer overlap (query.h), so it
        // can only report more, never miss a collision.
        if (cold.colliding) {
          EXPECT_TRUE(warm.colliding) << contactModelName(model) << " frame " << f;
        }
        continue;
      }
      EXPECT_EQ(warm.colliding, cold.colliding) << "frame " << f;
      EXPECT_EQ(warm.intersectingTriangles, cold.intersectingTriangles) << "frame " << f;
      ASSERT_EQ(warm.contacts.size(), cold.contacts.size()) << "frame " << f;
      for (std::size_t i = 0; i < warm.contacts.size(); ++i) {
        EXPECT_EQ(warm.contacts[i].point, cold.contacts[i].point) << "frame " << f;
        EXPECT_EQ(warm.contacts[i].normal, cold.contacts[i].normal) << "frame " << f;
      }
    }
  }
}

TEST(NarrowPhaseModels, MissingSectionsAndBadSettingsThrow) {
  const CollisionBody plain = test::makeTestBody(makeBox(Vec3::Constant(1.0)), 1, false, false);
  CollisionBody bare(plain.mesh(), plain.sphereTree());
  Pose poseA;
  poseA.translation = Vec3(0, 0, 1.9);
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kAverage, ContactModel::kContactTree}) {
    try {
      queryContacts(bare, poseA, bare, Pose{}, settingsFor(model, kUnlimitedTests));
      ADD_FAILURE() << contactModelName(model) << " did not throw";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kBakeMissingSection);
      EXPECT_NE(std::string(e.what()).find("bake with 'clod bake"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(queryContacts(bare, poseA, bare, Pose{}, settingsFor(ContactModel::kDos, 10)));
  QuerySettings bad = settingsFor(ContactModel::kDos, 0);
  EXPECT_THROW(queryContacts(bare, poseA, bare, Pose{}, bad), Error);
  bad = settingsFor(ContactModel::kDos, 10);
  bad.maxContacts = 0;
  EXPECT_THROW(queryContacts(bare, poseA, bare, Pose{}, bad), Error);
  EXPECT_EQ(parseContactModel("contact-tree"), ContactModel::kContactTree);
  EXPECT_THROW(parseContactModel("Cfm"), Error);
}

}  // namespace
}  // namespace clod
