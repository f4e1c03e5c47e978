// The test runners' main: GoogleTest, sharded by whole test suites.
//
// ctest runs each runner as CLOD_SUITE_SHARDS processes (tests/CMakeLists.txt), shard i running
// the suites this main assigns to it. GoogleTest's own sharding (GTEST_TOTAL_SHARDS) deals out
// single tests round robin, so every shard ran a few tests of every suite and built each suite's
// shared fixture (a baked body, a contact tree: SetUpTestSuite, function statics) again: under
// the sanitizers the narrow-phase runner's three shards cost twice the CPU of one process.
// Suites go to the shard with the fewest tests so far, largest suites first: deterministic, and
// about as balanced as GoogleTest's split. A --gtest_filter given by hand runs unsharded.
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

std::string suiteFilter(int shards, int index) {
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  struct Suite {
    std::string name;
    int tests;
  };
  std::vector<Suite> suites;
  for (int i = 0; i < unit.total_test_suite_count(); ++i)
    suites.push_back({unit.GetTestSuite(i)->name(), unit.GetTestSuite(i)->total_test_count()});
  std::stable_sort(suites.begin(), suites.end(), [](const Suite& a, const Suite& b) { return a.tests > b.tests; });
  std::vector<int> load(static_cast<std::size_t>(shards), 0);
  std::string filter;
  for (const Suite& suite : suites) {
    const auto shard = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    load[static_cast<std::size_t>(shard)] += suite.tests;
    if (shard == index) filter += suite.name + ".*:";
  }
  return filter.empty() ? "-*" : filter;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const int shards = envInt("CLOD_SUITE_SHARDS", 1);
  const int index = envInt("CLOD_SUITE_SHARD_INDEX", 0);
  if (shards > 1 && index >= 0 && index < shards && GTEST_FLAG_GET(filter) == "*")
    GTEST_FLAG_SET(filter, suiteFilter(shards, index));
  return RUN_ALL_TESTS();
}
