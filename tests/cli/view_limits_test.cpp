// `clod view` against hostile clients (issue 21): silent and trickling connections, clients that
// stop reading, foreign Host headers (DNS rebinding), a file far larger than the server should
// ever hold in memory, and paths that try to leave the served folders. Every client here is a
// raw socket to 127.0.0.1 with its own deadline, so no test can hang.
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli_runner.h"
#include "cli/view_harness.h"

namespace {

namespace fs = std::filesystem;
using namespace clod::test::view;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kBigFileBytes = 50u << 20;  // 50 MiB

// FNV-1a over a byte stream: a checksum the test computes both on disk and on the wire.
struct Fnv1a {
  std::uint64_t value = 14695981039346656037ull;
  void add(const char* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) value = (value ^ static_cast<unsigned char>(data[i])) * 1099511628211ull;
  }
};

// Writes `bytes` of a position-dependent pattern (no repeat every 256 bytes, so a chunk sent
// twice or skipped changes the checksum) and returns its checksum.
std::uint64_t writeBigFile(const fs::path& path, std::size_t bytes) {
  std::ofstream out(path, std::ios::binary);
  Fnv1a sum;
  std::vector<char> block(1 << 20);
  std::uint32_t state = 12345;
  for (std::size_t done = 0; done < bytes; done += block.size()) {
    for (char& c : block) {
      state = state * 1664525u + 1013904223u;
      c = char(state >> 24);
    }
    const std::size_t n = std::min(block.size(), bytes - done);
    out.write(block.data(), std::streamsize(n));
    sum.add(block.data(), n);
  }
  return sum.value;
}

// The server's peak resident memory (VmHWM) in KiB, or -1.
long peakResidentKiB(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6);
  return -1;
}

// Waits up to `timeout` for input on `fd`; true if there is some (or the peer closed).
bool readable(int fd, std::chrono::milliseconds timeout) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, int(timeout.count())) > 0;
}

// Reads whatever `fd` has until the server closes it or `timeout` passes; the bytes read.
std::string drain(int fd, std::chrono::milliseconds timeout) {
  std::string all;
  const auto deadline = Clock::now() + timeout;
  char buffer[65536];
  while (Clock::now() < deadline) {
    if (!readable(fd, std::chrono::milliseconds(50))) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    all.append(buffer, std::size_t(n));
  }
  return all;
}

std::string requestWithHost(const std::string& target, const std::string& hostLine) {
  return "GET " + target + " HTTP/1.1\r\n" + hostLine + "\r\n";
}

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

class ClodViewLimits : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("clod_view_limits_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    writeFile(root_ / "viewer" / "index.html", "<!doctype html><title>stand-in viewer</title>\n");
    writeFile(root_ / "out" / "scene.glb", std::string("glTF\x02\0\0\0", 8));
    writeFile(root_ / "secret.txt", kSecret);
    bigChecksum_ = writeBigFile(root_ / "out" / "big.bin", kBigFileBytes);
    fs::create_directory_symlink(root_, root_ / "out" / "escape");
    ::mkfifo((root_ / "out" / "pipe").c_str(), 0600);  // opening it for reading would block
    server_ = startServer(argsWith({}));
  }
  static void TearDownTestSuite() {
    stopServer(server_);
    fs::remove_all(root_);
  }

  static std::vector<std::string> argsWith(const std::vector<std::string>& extra) {
    std::vector<std::string> args{(root_ / "out").string(), "--port", "0", "--viewer-dir",
                                  (root_ / "viewer").string(), "--quit-after", "120"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }

  static inline fs::path root_;
  static inline Server server_;  // default limits: 32 connections, 5 s head timeout, 10 s send timeout
  static inline std::uint64_t bigChecksum_ = 0;
  static constexpr const char* kSecret = "do-not-serve-91c2e0";
};

TEST_F(ClodViewLimits, SilentAndTricklingConnectionsDoNotLockOthersOut) {
  ASSERT_GT(server_.port, 0) << server_.firstLine;
  // Twice the default limit: half send nothing, half an unfinished request head.
  std::vector<int> hostile;
  for (int i = 0; i < 64; ++i) {
    const int fd = connectTo(server_.port);
    ASSERT_GE(fd, 0);
    if (i % 2) ::send(fd, "GET / HTTP/1.1\r\nHost: local", 27, MSG_NOSIGNAL);
    hostile.push_back(fd);
  }
  // Well before the 5 s head timeout could free a slot, real requests are answered.
  const auto start = Clock::now();
  const HttpReply index = get(server_.port, "/");
  const HttpReply scene = get(server_.port, "/data/scene.glb");
  const double elapsed = secondsSince(start);
  EXPECT_EQ(index.status, 200);
  EXPECT_EQ(index.body, readFile(root_ / "viewer" / "index.html"));
  EXPECT_EQ(scene.status, 200);
  EXPECT_LT(elapsed, 2.0);
  // The server made room by dropping the hostile connections that had waited longest.
  int dropped = 0;
  for (int fd : hostile) {
    char c;
    if (readable(fd, std::chrono::milliseconds(0)) && ::recv(fd, &c, 1, MSG_DONTWAIT) <= 0) ++dropped;
    ::close(fd);
  }
  EXPECT_GE(dropped, 32);
  std::printf("[ measured ] 64 hostile connections: GET / + GET /data/scene.glb answered in %.3f s; "
              "%d hostile connections dropped\n", elapsed, dropped);
}

TEST_F(ClodViewLimits, DropsAClientThatTricklesItsHeadAfterTheHeaderTimeout) {
  Server own = startServer(argsWith({"--header-timeout", "1"}));
  ASSERT_GT(own.port, 0) << own.firstLine;
  const int fd = connectTo(own.port);
  ASSERT_GE(fd, 0);
  const std::string head = "GET / HTTP/1.1\r\nHost: localhost\r\nX-Slow: " + std::string(200, 'a') + "\r\n\r\n";
  const auto start = Clock::now();
  std::string answer;
  bool dropped = false;
  for (std::size_t i = 0; i < head.size() && secondsSince(start) < 8.0; ++i) {
    if (::send(fd, &head[i], 1, MSG_NOSIGNAL) != 1) {
      dropped = true;
      break;
    }
    if (readable(fd, std::chrono::milliseconds(100))) {  // one byte per 100 ms
      answer = drain(fd, std::chrono::seconds(2));
      dropped = true;
      break;
    }
  }
  const double elapsed = secondsSince(start);
  ::close(fd);
  EXPECT_TRUE(dropped);
  EXPECT_GE(elapsed, 0.9);
  EXPECT_LT(elapsed, 3.0);
  if (!answer.empty()) {
    EXPECT_EQ(parseReply(answer).status, 408) << answer;
  }
  std::printf("[ measured ] trickling client (1 byte / 100 ms) dropped after %.2f s (--header-timeout 1)\n", elapsed);
  EXPECT_EQ(stopServer(own), 0);
}

TEST_F(ClodViewLimits, ChecksTheHostHeaderAgainstDnsRebinding) {
  const int port = server_.port;
  const std::string p = std::to_string(port);
  const std::vector<std::string> ours{"localhost", "localhost:" + p, "LocalHost:" + p, "127.0.0.1",
                                      "127.0.0.1:" + p, "[::1]", "[::1]:" + p};
  for (const std::string& host : ours)
    EXPECT_EQ(request(port, requestWithHost("/", "Host: " + host + "\r\n")).status, 200) << host;
  const std::vector<std::string> foreign{"evil.example", "evil.example:" + p, "localhost:1", "localhost.evil.example",
                                         "127.0.0.1.evil.example:" + p, "[::1", "10.0.0.1:" + p,
                                         "localhost:" + p + "x"};
  for (const std::string& host : foreign)
    EXPECT_EQ(request(port, requestWithHost("/", "Host: " + host + "\r\n")).status, 403) << host;
  EXPECT_EQ(request(port, requestWithHost("/", "")).status, 400);  // HTTP/1.1 without Host
  EXPECT_EQ(request(port, requestWithHost("/", "Host: localhost\r\nHost: evil.example\r\n")).status, 400);
  EXPECT_EQ(request(port, "GET / HTTP/1.0\r\n\r\n").status, 200);  // Host is optional in HTTP/1.0
}

TEST_F(ClodViewLimits, StreamsALargeFileWithoutHoldingItInMemory) {
  const long peakBefore = peakResidentKiB(server_.pid);
  ASSERT_GT(peakBefore, 0);
  const int fd = connectTo(server_.port);
  ASSERT_GE(fd, 0);
  const std::string ask = "GET /data/big.bin HTTP/1.1\r\nHost: localhost\r\n\r\n";
  ::send(fd, ask.data(), ask.size(), MSG_NOSIGNAL);
  // Read the head only, then let the download sit: another client must still be served.
  std::string head;
  char c;
  while (head.find("\r\n\r\n") == std::string::npos && readable(fd, std::chrono::seconds(5)) &&
         ::recv(fd, &c, 1, 0) == 1)
    head += c;
  const HttpReply reply = parseReply(head);
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.header("Content-Length"), std::to_string(kBigFileBytes));
  EXPECT_EQ(get(server_.port, "/").status, 200);

  const auto start = Clock::now();
  Fnv1a sum;
  std::size_t received = 0;
  std::vector<char> buffer(1 << 20);
  while (secondsSince(start) < 20.0 && readable(fd, std::chrono::seconds(5))) {
    const ssize_t n = ::recv(fd, buffer.data(), buffer.size(), 0);
    if (n <= 0) break;
    sum.add(buffer.data(), std::size_t(n));
    received += std::size_t(n);
  }
  const double seconds = secondsSince(start);
  ::close(fd);
  EXPECT_EQ(received, kBigFileBytes);
  EXPECT_EQ(sum.value, bigChecksum_);
  const long peakAfter = peakResidentKiB(server_.pid);
  EXPECT_LT(peakAfter - peakBefore, 8 * 1024) << "peak RSS grew from " << peakBefore << " to " << peakAfter << " KiB";
  std::printf("[ measured ] 50 MiB streamed in %.3f s; server peak RSS %ld -> %ld KiB\n", seconds, peakBefore,
              peakAfter);
}

TEST_F(ClodViewLimits, DropsClientsThatStopReadingAndAnswers503WhenAllSlotsAreBusy) {
  Server own = startServer(argsWith({"--max-connections", "2", "--send-timeout", "1"}));
  ASSERT_GT(own.port, 0) << own.firstLine;
  const std::string ask = "GET /data/big.bin HTTP/1.1\r\nHost: localhost\r\n\r\n";
  std::vector<int> stalled;
  for (int i = 0; i < 2; ++i) {  // ask for 50 MiB and never read
    const int fd = connectTo(own.port);
    ASSERT_GE(fd, 0);
    ::send(fd, ask.data(), ask.size(), MSG_NOSIGNAL);
    stalled.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  // Both slots hold answers in progress, none of which may be dropped for a newcomer: 503 (or,
  // should the kernel reset the refused connection first, no answer at all) -- but never a wait.
  const auto start = Clock::now();
  const HttpReply busy = get(own.port, "/");
  const double busyAnswerSeconds = secondsSince(start);
  EXPECT_LT(busyAnswerSeconds, 1.0);
  EXPECT_TRUE(busy.status == 503 || busy.status == 0) << busy.status;
  if (busy.status == 503) {
    EXPECT_EQ(busy.header("Retry-After"), "1");
  }
  // After the 1 s send timeout the stalled clients are gone and the slots are free again.
  int status = 0;
  const auto stalledAt = Clock::now();
  while (status != 200 && secondsSince(stalledAt) < 6.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    status = get(own.port, "/").status;
  }
  EXPECT_EQ(status, 200);
  std::printf("[ measured ] 2 stalled readers (--max-connections 2 --send-timeout 1): newcomer answered %d in "
              "%.3f s; slots free again %.2f s later\n", busy.status, busyAnswerSeconds, secondsSince(stalledAt));
  for (int fd : stalled) {
    const std::string got = drain(fd, std::chrono::seconds(5));
    EXPECT_LT(got.size(), kBigFileBytes) << "a client that stopped reading got the whole file";
    ::close(fd);
  }
  EXPECT_EQ(stopServer(own), 0);
}

TEST_F(ClodViewLimits, AnswersAnOversizedHeadWith431) {
  const std::string head = "GET / HTTP/1.1\r\nHost: localhost\r\nX-Big: " + std::string(20000, 'b') + "\r\n\r\n";
  EXPECT_EQ(request(server_.port, head).status, 431);
}

TEST_F(ClodViewLimits, RefusesTraversalLinksOutOfTheRootAndNonRegularFiles) {
  for (const std::string target : {"/../secret.txt", "/data/../../secret.txt", "/data/%2e%2e/%2e%2e/secret.txt"}) {
    const HttpReply r = get(server_.port, target);
    EXPECT_EQ(r.status, 403) << target;
    EXPECT_EQ(r.body.find(kSecret), std::string::npos) << target;
  }
  const HttpReply link = get(server_.port, "/data/escape/secret.txt");
  EXPECT_EQ(link.status, 403);
  EXPECT_EQ(link.body.find(kSecret), std::string::npos);
  const auto start = Clock::now();
  EXPECT_EQ(get(server_.port, "/data/pipe").status, 404);  // a FIFO: refused, not waited on
  EXPECT_LT(secondsSince(start), 2.0);
}

TEST_F(ClodViewLimits, RefusesOutOfRangeLimitsWithExitCode2) {
  for (const std::string& bad : std::vector<std::string>{"--max-connections 0", "--max-connections 513",
                                                         "--header-timeout 0", "--send-timeout -1"}) {
    const auto r = clod::test::runCli("view " + clod::test::quoted(root_ / "out") + " --viewer-dir " +
                                      clod::test::quoted(root_ / "viewer") + " --port 0 --quit-after 5 " + bad);
    EXPECT_EQ(r.exitCode, 2) << bad;
    EXPECT_EQ(r.err.rfind("clod: error [", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(bad.substr(0, bad.find(' '))), std::string::npos) << r.err;
  }
}

}  // namespace
