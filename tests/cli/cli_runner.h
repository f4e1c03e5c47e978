#pragma once
// Runs the built clod CLI (CLOD_CLI_PATH) as a child process, as external checks do, and
// captures its exit code, stdout and stderr. Shared by the CLI tests.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace clod::test {

struct CliRun {
  int exitCode = -1;
  std::string out;
  std::string err;
};

/// Runs `clod ARGS`; stderr goes through a per-process temporary file.
inline CliRun runCli(const std::string& args) {
  namespace fs = std::filesystem;
  const fs::path errPath = fs::temp_directory_path() / ("clod_cli_test_" + std::to_string(::getpid()) + ".err");
  // Appended piece by piece: GCC 12 reports a false -Wrestrict on `std::string("\"") + ...` chains.
  std::string command = "\"";
  command += CLOD_CLI_PATH;
  command += "\" ";
  command += args;
  command += " 2>\"";
  command += errPath.string();
  command += '"';
  CliRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return run;
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream err(errPath);
  run.err.assign(std::istreambuf_iterator<char>(err), std::istreambuf_iterator<char>());
  fs::remove(errPath);
  return run;
}

/// A path in double quotes, for a shell command line.
inline std::string quoted(const std::filesystem::path& path) {
  std::string text = "\"";  // appends, not `"\"" + ...`: GCC 12 -Wrestrict false positive
  text += path.string();
  text += '"';
  return text;
}

}  // namespace clod::test
