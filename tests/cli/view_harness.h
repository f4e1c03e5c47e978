#pragma once
// Test harness for `clod view` (view_test.cpp, view_limits_test.cpp): starts the built CLI as a
// child process on port 0, reads the URL it prints, and talks raw HTTP/1.1 to it over sockets.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace clod::test::view {

namespace fs = std::filesystem;

struct HttpReply {
  int status = 0;
  std::string head;
  std::string body;
  // The value of header `name` (case-insensitive), or "" if absent.
  std::string header(const std::string& name) const {
    std::string lowerHead = head, key = "\r\n" + name + ": ";
    for (std::string* t : {&lowerHead, &key})
      std::transform(t->begin(), t->end(), t->begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const std::size_t at = lowerHead.find(key);
    if (at == std::string::npos) return std::string();
    const std::size_t begin = at + key.size();
    return head.substr(begin, head.find('\r', begin) - begin);
  }
};

// A TCP connection to 127.0.0.1:port, or -1.
inline int connectTo(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(std::uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd >= 0 && ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) return fd;
  if (fd >= 0) ::close(fd);
  return -1;
}

// Splits a whole answer into status, head and body.
inline HttpReply parseReply(const std::string& all) {
  HttpReply reply;
  const std::size_t split = all.find("\r\n\r\n");
  if (split == std::string::npos) return reply;
  reply.head = all.substr(0, split + 2);
  reply.body = all.substr(split + 4);
  if (reply.head.rfind("HTTP/1.1 ", 0) == 0) reply.status = std::atoi(reply.head.c_str() + 9);
  return reply;
}

// Sends one raw request and reads until the server closes the connection.
inline HttpReply request(int port, const std::string& raw) {
  const int fd = connectTo(port);
  if (fd < 0) return HttpReply{};
  timeval timeout{20, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  ::send(fd, raw.data(), raw.size(), MSG_NOSIGNAL);
  std::string all;
  char buffer[8192];
  ssize_t n;
  while ((n = ::recv(fd, buffer, sizeof buffer, 0)) > 0) all.append(buffer, std::size_t(n));
  ::close(fd);
  return parseReply(all);
}

inline HttpReply get(int port, const std::string& target, const std::string& method = "GET") {
  return request(port, method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
}

inline std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeFile(const fs::path& path, const std::string& content) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << content;
}

// A running `clod view` child process; its first stdout line carries the URL.
struct Server {
  pid_t pid = -1;
  int port = 0;
  std::string firstLine;
};

inline Server startServer(const std::vector<std::string>& args) {
  Server server;
  int out[2];
  if (::pipe(out) != 0) return server;
  server.pid = ::fork();
  if (server.pid == 0) {
    ::dup2(out[1], STDOUT_FILENO);
    ::close(out[0]);
    ::close(out[1]);
    std::vector<char*> argv{const_cast<char*>(CLOD_CLI_PATH), const_cast<char*>("view")};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(CLOD_CLI_PATH, argv.data());
    ::_exit(127);
  }
  ::close(out[1]);
  // Wait for the URL line (generous: the sanitizer build starts slowly).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::string text;
  while (text.find('\n') == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    pollfd p{out[0], POLLIN, 0};
    if (::poll(&p, 1, 200) <= 0) continue;
    char c[256];
    const ssize_t n = ::read(out[0], c, sizeof c);
    if (n <= 0) break;
    text.append(c, std::size_t(n));
  }
  ::close(out[0]);  // the server's later lines go nowhere; it ignores SIGPIPE
  server.firstLine = text.substr(0, text.find('\n'));
  const std::string prefix = "http://127.0.0.1:";
  const std::size_t at = server.firstLine.find(prefix);
  if (at != std::string::npos) {
    const char* digits = server.firstLine.c_str() + at + prefix.size();
    if (std::isdigit(static_cast<unsigned char>(*digits))) server.port = std::atoi(digits);
  }
  return server;
}

// Stops the server with `signal` and returns its exit code (-1 if it did not stop in time).
inline int stopServer(Server& server, int signal = SIGTERM) {
  if (server.pid <= 0) return -1;
  ::kill(server.pid, signal);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(server.pid, &status, WNOHANG) == server.pid) {
      server.pid = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(server.pid, SIGKILL);
  ::waitpid(server.pid, &status, 0);
  server.pid = -1;
  return -1;
}

}  // namespace clod::test::view
