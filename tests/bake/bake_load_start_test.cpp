// loadBake checks a file's header and section table before it reads (or allocates) the rest:
// checkBakeFileStart on the first bytes, as bake_file.h describes.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <unistd.h>

#include <gtest/gtest.h>

#include "bake_test_support.h"
#include "clod/bake_file.h"

namespace clod {
namespace {

namespace fs = std::filesystem;
using test::thrownCode;

TEST(BakeFileStart, AsksForTheHeaderThenTheTableThenIsSatisfied) {
  const std::vector<std::byte> file = encodeBake(test::makeTestContents());
  std::uint32_t count = 0;
  std::memcpy(&count, file.data() + 16, sizeof count);
  const std::size_t tableEnd = kBakeHeaderSize + std::size_t{count} * kBakeTableEntrySize;
  EXPECT_EQ(checkBakeFileStart({file.data(), 0}, file.size()), kBakeHeaderSize);
  EXPECT_EQ(checkBakeFileStart({file.data(), 10}, file.size()), kBakeHeaderSize);
  EXPECT_EQ(checkBakeFileStart({file.data(), kBakeHeaderSize}, file.size()), tableEnd);
  EXPECT_EQ(checkBakeFileStart({file.data(), tableEnd}, file.size()), 0u);
  EXPECT_EQ(checkBakeFileStart(file, file.size()), 0u);
  // The declared size is checked against the file's, not against the bytes in hand.
  EXPECT_EQ(thrownCode([&] { checkBakeFileStart({file.data(), tableEnd}, file.size() + 64); }),
            ErrorCode::kBakeCorrupt);
  EXPECT_EQ(thrownCode([&] { checkBakeFileStart({file.data(), tableEnd}, file.size() - 1); }),
            ErrorCode::kBakeTruncated);
  // Not a bake: refused on its first bytes.
  const std::vector<std::byte> zeros(kBakeHeaderSize);
  EXPECT_EQ(thrownCode([&] { checkBakeFileStart(zeros, std::uint64_t{1} << 40); }), ErrorCode::kBakeCorrupt);
}

class BakeLoadHugeFile : public ::testing::Test {
protected:
  void SetUp() override {
    path_ = fs::temp_directory_path() / ("clod_bake_huge_" + std::to_string(::getpid()) + ".clod");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  // Makes path_ a sparse file of 1 TiB starting with `start` (no disk space, no time); a
  // reader that read it whole would run out of memory or time, so passing means it did not.
  bool makeHuge(const std::vector<std::byte>& start) {
    std::ofstream(path_, std::ios::binary).write(reinterpret_cast<const char*>(start.data()), std::streamsize(start.size()));
    std::error_code ec;
    fs::resize_file(path_, std::uint64_t{1} << 40, ec);
    return !ec;
  }
  std::string loadError() {
    try {
      loadBake(path_);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kBakeCorrupt) << e.what();
      return e.what();
    }
    return "no error";
  }
  fs::path path_;
};

TEST_F(BakeLoadHugeFile, OfZerosIsRefusedByItsMagic) {
  if (!makeHuge({})) GTEST_SKIP() << "no sparse files here";
  EXPECT_NE(loadError().find("magic"), std::string::npos);
}

TEST_F(BakeLoadHugeFile, WithABakeHeaderIsRefusedByItsDeclaredSize) {
  if (!makeHuge(encodeBake(test::makeTestContents()))) GTEST_SKIP() << "no sparse files here";
  EXPECT_NE(loadError().find("its header declares"), std::string::npos);
}

}  // namespace
}  // namespace clod
