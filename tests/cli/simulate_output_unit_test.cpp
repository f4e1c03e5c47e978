// Issue 21, B21: `clod simulate` writes its five outputs as one unit. Two scenes whose box is
// named "first_run" and "second_run"; run the first to completion, then kill the second with
// SIGKILL at moments spread over its whole run. Oracle: the body name inside each output file --
// after every kill, all five files must come from the same run, and OUTDIR holds nothing but
// them and the bake cache (no .tmp files).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

const char* const kOutputs[] = {"trajectory.csv", "contacts.csv", "summary.json", "scene.glb", "layers.json"};

fs::path writeScene(const fs::path& dir, const std::string& boxName) {
  const fs::path path = dir / (boxName + ".json");
  std::ofstream(path) << R"({"dt": 0.0166666, "duration": 1.0, "contact_model": "cfm", "bodies": [
    {"name": "ground", "box": [2, 2, 0.25], "position": [0, 0, 0], "static": true},
    {"name": ")" << boxName << R"(", "box": [0.5, 0.5, 0.5], "position": [0, 0, 0.4], "density": 1000}]})";
  return path;
}

// Starts `clod simulate scene -o out --gltf`, output discarded.
pid_t startSimulate(const fs::path& scene, const fs::path& out) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    ::execl(CLOD_CLI_PATH, CLOD_CLI_PATH, "simulate", scene.c_str(), "-o", out.c_str(), "--gltf", nullptr);
    ::_exit(127);
  }
  return pid;
}

int waitExit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// "first_run" or "second_run" if every output names that run's box alone; else what is wrong.
std::string runOfOutputs(const fs::path& out) {
  std::string run;
  for (const char* name : kOutputs) {
    const std::string content = readAll(out / name);
    const bool first = content.find("first_run") != std::string::npos;
    const bool second = content.find("second_run") != std::string::npos;
    if (first == second) return std::string(name) + " names " + (first ? "both runs" : "neither run");
    const std::string mine = first ? "first_run" : "second_run";
    if (!run.empty() && run != mine) return "a mix: " + std::string(name) + " is from " + mine + ", others from " + run;
    run = mine;
  }
  for (const fs::directory_entry& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name != "bake-cache" && std::find(std::begin(kOutputs), std::end(kOutputs), name) == std::end(kOutputs))
      return "stray entry " + name;
  }
  return run;
}

TEST(SimulateOutputUnit, AKillAtAnyMomentLeavesAllFilesFromOneRun) {
  const fs::path root = fs::temp_directory_path() / ("clod_simulate_unit_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root);
  const fs::path first = writeScene(root, "first_run"), second = writeScene(root, "second_run");
  const fs::path out = root / "out";

  // How long the second run takes when not killed (bake cache warm, as in the loop).
  ASSERT_EQ(waitExit(startSimulate(second, out)), 0);
  ASSERT_EQ(waitExit(startSimulate(first, out)), 0);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(waitExit(startSimulate(second, out)), 0);
  const auto full = std::chrono::steady_clock::now() - start;
  ASSERT_EQ(runOfOutputs(out), "second_run");

  constexpr int kKills = 24;
  int completed = 0;
  for (int k = 0; k < kKills; ++k) {
    ASSERT_EQ(waitExit(startSimulate(first, out)), 0);
    ASSERT_EQ(runOfOutputs(out), "first_run");
    // Kills spread from the start to 1.2 times the run's length (some runs finish first).
    const pid_t pid = startSimulate(second, out);
    std::this_thread::sleep_for(full * (k + 1) / (kKills * 5 / 6));
    ::kill(pid, SIGKILL);
    completed += waitExit(pid) == 0;
    const std::string run = runOfOutputs(out);
    EXPECT_TRUE(run == "first_run" || run == "second_run") << "kill " << k << ": " << run;
  }
  // A staging directory of a killed run may remain beside OUTDIR (named by its pid); a new run
  // still succeeds.
  ASSERT_EQ(waitExit(startSimulate(second, out)), 0);
  EXPECT_EQ(runOfOutputs(out), "second_run");
  RecordProperty("runs_completed_before_the_kill", completed);
  fs::remove_all(root);
}

}  // namespace
