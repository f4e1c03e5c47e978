// writeFileAtomically replaces regular files only: the rename would turn a device, a pipe or
// a directory at the target path into a regular file.
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "clod/atomic_file.h"
#include "clod/error.h"

namespace clod {
namespace {

namespace fs = std::filesystem;

class AtomicFile : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clod_atomic_file_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The kFileWriteFailed message of writing to `path`.
  static std::string writeError(const fs::path& path) {
    try {
      writeFileAtomically(path, "data");
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kFileWriteFailed) << e.what();
      return e.what();
    }
    return "no error";
  }
  std::size_t entries() const {
    return std::size_t(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}));
  }
  fs::path dir_;
};

TEST_F(AtomicFile, ReplacesARegularFileAndALinkToOne) {
  std::ofstream(dir_ / "file") << "old";
  writeFileAtomically(dir_ / "file", "new");
  EXPECT_EQ(readWholeFile(dir_ / "file"), "new");
  fs::create_symlink(dir_ / "file", dir_ / "link");
  writeFileAtomically(dir_ / "link", "newer");
  EXPECT_EQ(readWholeFile(dir_ / "link"), "newer");
}

TEST_F(AtomicFile, RefusesToReplaceWhatIsNotARegularFile) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe").c_str(), 0600), 0);
  fs::create_directory(dir_ / "directory");
  EXPECT_EQ(writeError(dir_ / "pipe"), "refusing to replace '" + (dir_ / "pipe").string() +
                                           "': it is a named pipe, not a regular file");
  EXPECT_NE(writeError(dir_ / "directory").find("it is a directory"), std::string::npos);
  EXPECT_TRUE(fs::is_fifo(dir_ / "pipe"));
  EXPECT_TRUE(fs::is_directory(dir_ / "directory"));
  EXPECT_EQ(entries(), 2u) << "no temporary file left behind";
}

TEST_F(AtomicFile, RefusesToReplaceADevice) {
  // A private copy of /dev/full (needs root, as the original bug did: `clod bake -o /dev/full`
  // replaced the device), so a regression damages nothing outside the test's directory.
  const fs::path device = dir_ / "full";
  if (::mknod(device.c_str(), S_IFCHR | 0666, makedev(1, 7)) != 0) GTEST_SKIP() << "cannot make a device node";
  EXPECT_NE(writeError(device).find("it is a character device"), std::string::npos);
  EXPECT_TRUE(fs::is_character_file(device));
}

TEST_F(AtomicFile, ThreadsWritingTheSameTargetEachRenameTheirOwnFile) {
  // Parallel scene builds sharing a bake cache write the same file from several threads of one
  // process; the temporary name was the process id only, so one thread renamed the other's
  // half-written file or found its own gone ("cannot rename into ...").
  const fs::path target = dir_ / "shared";
  const std::string content(1 << 16, 'x');
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 25; ++i) {
        try {
          writeFileAtomically(target, content);
        } catch (const Error&) {
          ++failures;
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(readWholeFile(target), content);
  EXPECT_EQ(entries(), 1u) << "no temporary file left behind";
}

}  // namespace
}  // namespace clod
