#include <gtest/gtest.h>

#include <set>
#include <string_view>

#include "clod/error.h"

namespace {

TEST(ErrorCodes, EveryCodeHasAStableDistinctName) {
  std::set<std::string_view> names;
  for (int code = 1; code <= static_cast<int>(clod::ErrorCode::kResourceLimit); ++code) {
    auto name = clod::errorCodeName(static_cast<clod::ErrorCode>(code));
    EXPECT_NE(name, "unknown_error") << "code " << code;
    EXPECT_TRUE(names.insert(name).second) << "duplicate name " << name;
  }
}

TEST(ErrorCodes, ErrorCarriesCodeAndMessage) {
  clod::Error error(clod::ErrorCode::kIndexOutOfRange, "triangle 3: vertex index 9 >= vertex count 4");
  EXPECT_EQ(error.code(), clod::ErrorCode::kIndexOutOfRange);
  EXPECT_STREQ(error.what(), "triangle 3: vertex index 9 >= vertex count 4");
}

}  // namespace
