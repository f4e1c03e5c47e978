#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "clod/error.h"
#include "clod/points_io.h"

namespace {

using clod::ErrorCode;

// Runs parsePoints and returns the error it throws (fails the test if it does not throw).
clod::Error parseError(std::string_view text) {
  try {
    clod::parsePoints(text);
  } catch (const clod::Error& e) {
    return e;
  }
  ADD_FAILURE() << "no error for: " << text;
  return clod::Error(ErrorCode::kInvalidArgument, "");
}

TEST(PointsParser, ReadsOnePointPerLineInFileOrder) {
  const auto points = clod::parsePoints("1 2 3\n-4.5 +5e-1 6E2\n");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0], clod::Vec3(1, 2, 3));
  EXPECT_EQ(points[1], clod::Vec3(-4.5, 0.5, 600));
}

TEST(PointsParser, SkipsBlankLinesCommentsAndCarriageReturns) {
  const auto points = clod::parsePoints("# header\r\n\r\n  0.25\t0.5 1 # trailing\r\n\n7 8 9");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0], clod::Vec3(0.25, 0.5, 1));
  EXPECT_EQ(points[1], clod::Vec3(7, 8, 9));
}

TEST(PointsParser, AcceptsSeveralPointsOnOneLine) {
  const auto points = clod::parsePoints("1 2 3 4 5 6\n");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[1], clod::Vec3(4, 5, 6));
}

TEST(PointsParser, EmptyTextGivesNoPoints) {
  EXPECT_TRUE(clod::parsePoints("").empty());
  EXPECT_TRUE(clod::parsePoints("\n# nothing\n  \n").empty());
}

TEST(PointsParser, RoundTripsDoublesExactly) {
  const double x = 0.1, y = -1.0 / 3.0, z = 6.02214076e23;
  char text[128];
  std::snprintf(text, sizeof text, "%.17g %.17g %.17g", x, y, z);
  const auto points = clod::parsePoints(text);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0], clod::Vec3(x, y, z));
}

TEST(PointsParser, NonNumericTokenIsAParseErrorNamingLineAndToken) {
  const auto e = parseError("1 2 3\n4 five 6\n");
  EXPECT_EQ(e.code(), ErrorCode::kParseError);
  EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("'five'"), std::string::npos) << e.what();
}

TEST(PointsParser, NumberWithTrailingGarbageIsAParseError) {
  EXPECT_EQ(parseError("1 2 3x\n").code(), ErrorCode::kParseError);
  EXPECT_EQ(parseError("1,2,3\n").code(), ErrorCode::kParseError);
  EXPECT_EQ(parseError("0x10 2 3\n").code(), ErrorCode::kParseError);
  EXPECT_EQ(parseError("+-1 2 3\n").code(), ErrorCode::kParseError);
}

TEST(PointsParser, CountNotAMultipleOfThreeNamesTheLine) {
  const auto e = parseError("1 2 3\n\n4 5\n");
  EXPECT_EQ(e.code(), ErrorCode::kParseError);
  EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("2 numbers"), std::string::npos) << e.what();
  EXPECT_EQ(parseError("1 2 3 4\n").code(), ErrorCode::kParseError);
}

TEST(PointsParser, NanAndInfinityAreNonFiniteErrors) {
  for (const char* text : {"nan 0 0", "0 inf 0", "0 0 -Infinity", "1 2 1e400"}) {
    const auto e = parseError(text);
    EXPECT_EQ(e.code(), ErrorCode::kNonFiniteVertex) << text;
    EXPECT_NE(std::string(e.what()).find("line 1"), std::string::npos) << e.what();
  }
}

TEST(PointsParser, UnderflowIsNotAnError) {
  const auto points = clod::parsePoints("1e-400 0 0\n");
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].x(), 0.0);
}

TEST(PointsParser, BinaryGarbageIsEscapedInTheMessage) {
  const auto e = parseError(std::string_view("1 2 \x01\x02\xff", 7));
  EXPECT_EQ(e.code(), ErrorCode::kParseError);
  EXPECT_NE(std::string(e.what()).find("\\x01\\x02\\xff"), std::string::npos) << e.what();
}

class PointsFile : public ::testing::Test {
protected:
  std::filesystem::path dir_ = std::filesystem::temp_directory_path() /
                               ("clod_points_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { std::filesystem::create_directories(dir_); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const std::string& content) {
    auto path = dir_ / name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }
};

TEST_F(PointsFile, ReadsPointsFromDisk) {
  const auto points = clod::readPointsFile(write("p.txt", "1 2 3\n4 5 6\n"));
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[1], clod::Vec3(4, 5, 6));
}

TEST_F(PointsFile, MissingFileIsFileNotFound) {
  try {
    clod::readPointsFile(dir_ / "absent.txt");
    FAIL();
  } catch (const clod::Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kFileNotFound);
  }
}

TEST_F(PointsFile, ZeroByteFileIsEmptyFile) {
  try {
    clod::readPointsFile(write("empty.txt", ""));
    FAIL();
  } catch (const clod::Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kEmptyFile);
  }
}

TEST_F(PointsFile, ParseErrorsNameThePathAndLine) {
  const auto path = write("bad.txt", "1 2 3\n1 2 nan\n");
  try {
    clod::readPointsFile(path);
    FAIL();
  } catch (const clod::Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNonFiniteVertex);
    EXPECT_NE(std::string(e.what()).find("bad.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
}

}  // namespace
