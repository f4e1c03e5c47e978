#pragma once
// The budget of an interruptible collision query (query.h): a count of primitive tests, a
// wall-clock deadline, or both. Running out is not an error (docs/conventions.md, tier 3): the
// query answers from what it reached and says so.
//
// What counts as one test: one sphere-sphere overlap test of the traversal (sphere-tree spheres
// or contact-tree cell spheres), or, in the exact model, one triangle-triangle intersection
// test. A query never performs more tests than maxTests.
//
// Deadline: the clock is read once per batch of kDeadlineBatch tests, before the batch starts,
// and never before the first batch (so a query whose deadline has already passed still makes
// up to kDeadlineBatch tests, and queries of fewer tests never read the clock).
//
// The answer (turning the frontier into contacts) is inside the deadline too, unless
// answerWithinDeadline is false: the traversal stops when the time left no longer covers
// answering its current frontier at the per-pair cost its QueryScratch has measured
// (QueryScratch::answerSecondsPerPair), and the answer itself reads the clock once per batch of
// frontier pairs (8 sphere pairs, or one contact-tree cell pair; not before the first batch) and
// leaves the rest of the frontier unanswered once the deadline has passed
// (QueryResult::pairsAnswered) -- unless it has no contact yet: then up to kDeadlineBatch more
// pairs are answered until one gives a contact. A query therefore overruns its deadline by at
// most one batch of tests, one batch of frontier pairs (plus those kDeadlineBatch pairs when the
// first ones gave nothing) and the manifold reduction of the contacts answered. With
// answerWithinDeadline false the traversal stops at the deadline and the whole frontier is
// answered, however long that takes.

#include <chrono>
#include <cstdint>
#include <limits>

namespace clod {

/// Tests between two clock reads.
inline constexpr std::uint32_t kDeadlineBatch = 32;

/// maxTests value meaning "no limit".
inline constexpr std::uint64_t kUnlimitedTests = std::numeric_limits<std::uint64_t>::max();

struct QueryBudget {
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  /// Most tests the query may make (>= 1; kUnlimitedTests for no limit).
  std::uint64_t maxTests = kUnlimitedTests;
  /// The query stops at the first batch boundary at or after this instant.
  TimePoint deadline = TimePoint::max();
  /// The clock the deadline is read from; replaceable so tests can count clock reads instead
  /// of timing. Must be non-null.
  TimePoint (*now)() = &Clock::now;
  /// Keep turning the frontier into contacts within the deadline as well (see above).
  bool answerWithinDeadline = true;

  /// Unlimited: run to the leaves.
  static QueryBudget unlimited() { return {}; }
  /// At most `tests` tests.
  static QueryBudget tests(std::uint64_t tests) {
    QueryBudget b;
    b.maxTests = tests;
    return b;
  }
  /// A deadline `microseconds` from now (Clock::now()).
  static QueryBudget microsecondsFromNow(double microseconds) {
    QueryBudget b;
    b.deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double, std::micro>(microseconds));
    return b;
  }
  bool isUnlimited() const { return maxTests == kUnlimitedTests && deadline == TimePoint::max(); }
};

}  // namespace clod
