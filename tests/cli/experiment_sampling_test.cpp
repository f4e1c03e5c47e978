// `clod experiment sampling`: the JSON contract external checks rely on, -o output, bad usage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exitCode = -1;
  std::string out, err;
};

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clod_experiment_sampling_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

CliRun runCli(const std::string& args, const fs::path& scratch) {
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string command = std::string("\"") + CLOD_CLI_PATH + "\" " + args + " > \"" + out.string() + "\" 2> \"" + err.string() + "\"";
  const int status = std::system(command.c_str());
  CliRun run;
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = readFile(out);
  run.err = readFile(err);
  return run;
}

// Smaller lookup-accuracy sample: the contract is the same, and the CLI test must stay quick.
constexpr const char* kArgs = "experiment sampling --queries 20000";

TEST(ExperimentSamplingCli, JsonHasTable2RowsWithThePapersFiguresAndTable1Counts) {
  const fs::path dir = scratchDir("json");
  const CliRun run = runCli(std::string(kArgs) + " --json", dir);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto doc = nlohmann::json::parse(run.out);
  ASSERT_TRUE(doc.contains("rows"));
  ASSERT_EQ(doc["rows"].size(), 15u);  // 5 schemes x 5, 10, 20 stacks
  int withPaper = 0;
  for (const auto& row : doc["rows"]) {
    for (const char* key : {"scheme", "stacks", "samples", "std_dev", "paper_std_dev", "neighbour_definition"}) {
      ASSERT_TRUE(row.contains(key)) << key;
    }
    const std::string scheme = row["scheme"];
    const int stacks = row["stacks"];
    EXPECT_TRUE(stacks == 5 || stacks == 10 || stacks == 20);
    EXPECT_GE(row["std_dev"].get<double>(), 0.0);
    EXPECT_EQ(row["neighbour_definition"], "nearest-4");
    if (scheme == "polar" || scheme == "adaptive-polar") {
      ASSERT_TRUE(row["paper_std_dev"].is_number()) << scheme;
      ++withPaper;
    } else {
      EXPECT_TRUE(row["paper_std_dev"].is_null()) << scheme;
    }
    // The paper's Table 2 figures, as printed.
    if (scheme == "polar" && stacks == 10) {
      EXPECT_DOUBLE_EQ(row["paper_std_dev"].get<double>(), 0.144332);
    }
    if (scheme == "adaptive-polar" && stacks == 20) {
      EXPECT_DOUBLE_EQ(row["paper_std_dev"].get<double>(), 0.0661784);
    }
    // Sample counts: full polar S^2, adaptive polar 65 at S = 10 (paper Table 1).
    if (scheme == "polar") {
      EXPECT_EQ(row["samples"].get<int>(), stacks * stacks);
    }
    if (scheme == "adaptive-polar" && stacks == 10) {
      EXPECT_EQ(row["samples"].get<int>(), 65);
    }
  }
  EXPECT_EQ(withPaper, 6);

  ASSERT_TRUE(doc.contains("table1"));
  bool saw10 = false, saw16 = false;
  for (const auto& row : doc["table1"]) {
    if (row["scheme"] != "adaptive-polar") continue;
    if (row["root_stacks"] == 10) {
      saw10 = true;
      EXPECT_EQ(row["root_samples"], 65);
      EXPECT_EQ(row["leaf_samples"], 3);
      EXPECT_EQ(row["leaf_stacks"], 2);
    }
    if (row["root_stacks"] == 16) {
      saw16 = true;
      EXPECT_EQ(row["root_samples"], 163);  // the rule; the paper printed 167
      EXPECT_EQ(row["paper_root_samples"], 167);
      EXPECT_EQ(row["leaf_samples"], 11);
      EXPECT_EQ(row["leaf_stacks"], 4);
    }
  }
  EXPECT_TRUE(saw10 && saw16);
  fs::remove_all(dir);
}

TEST(ExperimentSamplingCli, OutputDirectoryGetsTheSameJsonAndACsv) {
  const fs::path dir = scratchDir("out");
  const fs::path outDir = dir / "results" / "nested";
  const CliRun run = runCli(std::string(kArgs) + " --json -o \"" + outDir.string() + "\"", dir);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  ASSERT_TRUE(fs::exists(outDir / "sampling.json"));
  ASSERT_TRUE(fs::exists(outDir / "sampling.csv"));
  EXPECT_EQ(nlohmann::json::parse(readFile(outDir / "sampling.json")), nlohmann::json::parse(run.out));
  const std::string csv = readFile(outDir / "sampling.csv");
  EXPECT_EQ(csv.rfind("scheme,stacks,", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 16);  // header + 15 rows
  // Exactly the document, the table, and Table 2's figure (its data, gnuplot script, image);
  // no temporary files left behind by the atomic writes.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(outDir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"sampling.csv", "sampling.json", "sampling_std_dev.csv", "sampling_std_dev.gp",
                                             "sampling_std_dev.png"}));
  EXPECT_GT(fs::file_size(outDir / "sampling_std_dev.png"), 1000u);
  fs::remove_all(dir);
}

TEST(ExperimentSamplingCli, BadUsageExitsWithTwoAndBadOutputPathWithOne) {
  const fs::path dir = scratchDir("bad");
  CliRun run = runCli("experiment no-such-experiment", dir);
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("no-such-experiment"), std::string::npos);
  EXPECT_TRUE(run.out.empty());

  run = runCli(std::string(kArgs) + " --neighbours delaunay", dir);
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("delaunay"), std::string::npos);

  run = runCli("experiment sampling --queries 0", dir);
  EXPECT_EQ(run.exitCode, 2);

  // -o names an existing regular file: a data/IO error (1), nothing printed, file untouched.
  const fs::path blocker = dir / "blocker";
  std::ofstream(blocker) << "keep";
  run = runCli(std::string(kArgs) + " --json -o \"" + blocker.string() + "\"", dir);
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_TRUE(run.out.empty());
  EXPECT_EQ(readFile(blocker), "keep");
  fs::remove_all(dir);
}

}  // namespace
