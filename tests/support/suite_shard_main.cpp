// The test runners' main: GoogleTest, sharded by whole test suites.
//
// ctest runs each runner as CLOD_SUITE_SHARDS processes (tests/CMakeLists.txt), shard i running
// the suites this main assigns to it. GoogleTest's own sharding (GTEST_TOTAL_SHARDS) deals out
// single tests round robin, so every shard ran a few tests of every suite and built each suite's
// shared fixture (a baked body, a contact tree: SetUpTestSuite, function statics) again: under
// the sanitizers the narrow-phase runner's three shards cost twice the CPU of one process.
// Suites go to the shard with the fewest tests so far, largest first (a suite too large for one
// shard is dealt out test by test): deterministic. A --gtest_filter given by hand runs unsharded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

int envInt(const char* name, int fallback) {
  const char* value = std::getenv(name);
  return value && *value ? std::atoi(value) : fallback;
}

// A unit of work for one shard: a whole suite, or one test of a suite too large to keep whole.
struct Unit {
  std::string pattern;  // "Suite.*" or "Suite.Test"
  int tests;
};

std::vector<Unit> units(int shards) {
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  const int perShard = unit.total_test_count() / shards;
  std::vector<Unit> out;
  for (int i = 0; i < unit.total_test_suite_count(); ++i) {
    const testing::TestSuite& suite = *unit.GetTestSuite(i);
    // A suite holding more than half a shard's share is dealt out test by test: left whole it
    // would make one shard the run's tail (the world's main suite has most of its tests).
    if (suite.total_test_count() * 2 <= perShard) {
      out.push_back({std::string(suite.name()) + ".*", suite.total_test_count()});
      continue;
    }
    for (int t = 0; t < suite.total_test_count(); ++t)
      out.push_back({std::string(suite.name()) + "." + suite.GetTestInfo(t)->name(), 1});
  }
  return out;
}

std::string shardFilter(int shards, int index) {
  std::vector<Unit> work = units(shards);
  std::stable_sort(work.begin(), work.end(), [](const Unit& a, const Unit& b) { return a.tests > b.tests; });
  std::vector<int> load(static_cast<std::size_t>(shards), 0);
  std::string filter;
  for (const Unit& u : work) {
    const auto shard = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    load[static_cast<std::size_t>(shard)] += u.tests;
    if (shard == index) filter += u.pattern + ":";
  }
  return filter.empty() ? "-*" : filter;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int shards = envInt("CLOD_SUITE_SHARDS", 1);
  const int index = envInt("CLOD_SUITE_SHARD_INDEX", 0);
  if (shards > 1 && index >= 0 && index < shards && GTEST_FLAG_GET(filter) == "*")
    GTEST_FLAG_SET(filter, shardFilter(shards, index));
  return RUN_ALL_TESTS();
}
