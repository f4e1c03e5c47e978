// replaceDirectoryAtomically: the owned files of an output directory change as one unit, a
// failure before the exchange leaves the directory as it was, and the user's other entries
// survive. Oracle: the directory's listing and file contents, read back with std::filesystem.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "clod/atomic_directory.h"
#include "clod/atomic_file.h"
#include "clod/error.h"

namespace clod {
namespace {

namespace fs = std::filesystem;

const std::string kOwned[] = {"a.csv", "b.json"};

class AtomicDirectory : public ::testing::Test {
protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("clod_atomic_directory_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    out_ = root_ / "out";
  }
  void TearDown() override { fs::remove_all(root_); }

  // Every regular file below `dir`, by relative path, with its content.
  static std::map<std::string, std::string> listing(const fs::path& dir) {
    std::map<std::string, std::string> files;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
      if (!e.is_regular_file()) continue;
      std::ifstream in(e.path());
      std::stringstream s;
      s << in.rdbuf();
      files[fs::relative(e.path(), dir).string()] = s.str();
    }
    return files;
  }
  // Entries of root_ other than out_: a staging directory left behind.
  std::size_t strays() const {
    std::size_t n = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(root_)) n += e.path() != out_;
    return n;
  }

  fs::path root_, out_;
};

TEST_F(AtomicDirectory, AWriterThatThrowsLeavesTheDirectoryUntouchedAndNoStagingBehind) {
  fs::create_directories(out_ / "bake-cache");
  writeFileAtomically(out_ / "a.csv", "old a");
  writeFileAtomically(out_ / "b.json", "old b");
  writeFileAtomically(out_ / "bake-cache" / "x.clod", "cache");
  const auto before = listing(out_);
  fs::path seenStaging;
  EXPECT_THROW(replaceDirectoryAtomically(out_, kOwned,
                                          [&](const fs::path& staging) {
                                            seenStaging = staging;
                                            writeFileAtomically(staging / "a.csv", "new a");
                                            throw std::runtime_error("writer failed half-way");
                                          }),
               std::runtime_error);
  EXPECT_EQ(listing(out_), before);
  EXPECT_EQ(seenStaging.parent_path(), root_) << "the staging directory is a sibling of OUTDIR";
  EXPECT_EQ(seenStaging.filename().string().rfind(".out.tmp.", 0), 0u) << seenStaging;
  EXPECT_EQ(strays(), 0u);
}

TEST_F(AtomicDirectory, ReplacesOwnedFilesKeepsOthersAndDropsStaleOwnedOnes) {
  fs::create_directories(out_ / "bake-cache");
  writeFileAtomically(out_ / "a.csv", "old a");
  writeFileAtomically(out_ / "b.json", "old b");                  // owned, not written this time
  writeFileAtomically(out_ / "a.csv.tmp.999.0", "killed writer");  // a killed writeFileAtomically's leftover
  writeFileAtomically(out_ / "bake-cache" / "x.clod", "cache");
  writeFileAtomically(out_ / "notes.txt", "mine");
  replaceDirectoryAtomically(out_, kOwned, [](const fs::path& staging) { writeFileAtomically(staging / "a.csv", "new a"); });
  const std::map<std::string, std::string> expected = {
      {"a.csv", "new a"}, {"bake-cache/x.clod", "cache"}, {"notes.txt", "mine"}};
  EXPECT_EQ(listing(out_), expected);
  EXPECT_EQ(strays(), 0u);
}

TEST_F(AtomicDirectory, CreatesAMissingDirectoryAndItsParents) {
  const fs::path nested = root_ / "deeper" / "out";
  replaceDirectoryAtomically(nested / "", kOwned, [](const fs::path& staging) { writeFileAtomically(staging / "b.json", "b"); });
  EXPECT_EQ(listing(nested), (std::map<std::string, std::string>{{"b.json", "b"}}));
  EXPECT_EQ(std::distance(fs::directory_iterator(root_ / "deeper"), fs::directory_iterator()), 1);
}

TEST_F(AtomicDirectory, RefusesAnOutputThatIsAFileOrADevice) {
  writeFileAtomically(root_ / "file", "keep");
  for (const fs::path& target : {root_ / "file", fs::path("/dev/null")}) {
    bool called = false;
    try {
      replaceDirectoryAtomically(target, kOwned, [&](const fs::path&) { called = true; });
      ADD_FAILURE() << target << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kFileWriteFailed);
      EXPECT_NE(std::string(e.what()).find("not a directory"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(called) << "nothing is written for a refused target";
  }
  EXPECT_EQ(readWholeFile(root_ / "file"), "keep");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_EQ(strays(), 1u);  // only "file"
}

}  // namespace
}  // namespace clod
