// clod experiment NAME [--json] [-o OUTDIR]: reproduce a table or figure of the papers.
//
// The experiments live in experiments/ (one file each, self-registering; experiment.h says what
// an experiment returns and what the runner writes). --json prints the document; -o OUTDIR writes
// the experiment's files and plots. "all" runs every experiment in order, prints the summaries,
// and with -o also writes all.json (every document under its experiment's name), all.csv and
// report.html. Everything is computed before anything is printed or written, so an error leaves
// no partial output.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "clod/atomic_file.h"
#include "clod/error.h"
#include "command.h"
#include "experiments/experiment.h"

namespace clod::cli {
namespace {

constexpr const char* kAll = "all";

Experiment findExperiment(const std::string& name) {
  std::string valid;
  for (const Experiment& e : registeredExperiments()) {
    if (name == e.name) return e;
    valid += (valid.empty() ? "" : ", ") + std::string(e.name);
  }
  throw Error(ErrorCode::kInvalidArgument, "unknown experiment '" + name + "' (valid: " + valid + ", " + kAll + ")");
}

int runOne(const ExperimentOptions& options) {
  const Experiment experiment = findExperiment(options.name);
  const ExperimentResult result = experiment.run(options);
  if (!options.outDir.empty()) writeExperimentOutput(options.outDir, options.name, result);
  if (options.json) {
    printJson(result.document);
  } else {
    std::cout << result.text;
  }
  return 0;
}

int runAll(const ExperimentOptions& options) {
  const std::vector<Experiment> experiments = registeredExperiments();
  std::vector<ExperimentResult> results;
  results.reserve(experiments.size());
  for (const Experiment& e : experiments) {
    if (!options.json) std::cerr << "experiment " << e.name << " ...\n";
    results.push_back(e.run(options));
  }
  nlohmann::json all = nlohmann::json::object();
  std::string csv, text;
  std::vector<std::pair<Experiment, const ExperimentResult*>> sections;
  for (std::size_t i = 0; i < experiments.size(); ++i) {
    all[experiments[i].name] = results[i].document;
    csv += "# " + std::string(experiments[i].name) + "\n" + results[i].csv;
    text += results[i].text;
    sections.emplace_back(experiments[i], &results[i]);
  }
  if (!options.outDir.empty()) {
    for (std::size_t i = 0; i < experiments.size(); ++i) writeExperimentOutput(options.outDir, experiments[i].name, results[i]);
    writeFileAtomically(std::filesystem::path(options.outDir) / "all.json", all.dump(2) + "\n");
    writeFileAtomically(std::filesystem::path(options.outDir) / "all.csv", csv);
    writeExperimentReport(options.outDir, sections);
  }
  if (options.json) {
    printJson(all);
  } else {
    std::cout << text;
  }
  return 0;
}

const CommandRegistration kRegistration("experiment", [](CLI::App& app) {
  auto options = std::make_shared<ExperimentOptions>();
  std::string names;
  for (const Experiment& e : registeredExperiments()) names += std::string("\n  ") + e.name + ": " + e.summary;
  names += std::string("\n  ") + kAll + ": every experiment above, and report.html with -o";
  CLI::App* sub = app.add_subcommand("experiment", "Reproduce a table or figure of the papers. Experiments:" + names);
  sub->add_option("name", options->name, "Experiment name")->required();
  sub->add_flag("--json", options->json, "Print the result as one JSON object (stable keys)");
  sub->add_option("-o,--output", options->outDir,
                  "Also write NAME.json, NAME.csv, extra tables and plots (PNG via gnuplot) into this directory");
  sub->add_option("--neighbours", options->neighbours, "sampling: neighbour definition of the rows (nearest-1, nearest-4, nearest-6)")
      ->capture_default_str();
  sub->add_option("--mesh-dir", options->meshDir,
                  "directory of the shared test meshes (default $CLOD_MESH_DIR or ../shared/data/meshes)");
  sub->add_option("--queries", options->queries, "sampling: random directions per lookup-accuracy row")->capture_default_str();
  sub->add_option("--trials", options->trials, "randomised runs per configuration (0 = each experiment's default)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--seed", options->seed, "seed of every random choice")->capture_default_str();
  sub->add_flag("--quick", options->quick,
                "reduced configuration for smoke tests (shorter simulations; same keys, not the report's numbers)");
  sub->add_option("--categories", options->categories,
                  "degradation: scenarios or categories (stacks, slide, slopes, drops), comma-separated");
  sub->add_option("--models", options->models, "degradation: contact models, comma-separated (default cfm,contact-tree,exact)");
  sub->add_option("--budgets", options->budgets, "degradation: tests per frame, comma-separated, 0 = unlimited (default 16,64,256,1024,0)");
  sub->add_option("--budgets-us", options->budgetsUs, "degradation: narrow-phase microseconds per frame, comma-separated (default 50,200,1000)");
  sub->add_option("--rates", options->rates, "degradation: frame rates in Hz, comma-separated (default 240,60)");
  sub->add_option("--duration", options->duration, "degradation: simulated seconds of every run (0 = each scenario's own)")
      ->check(CLI::NonNegativeNumber);
  return [options] { return options->name == kAll ? runAll(*options) : runOne(*options); };
});

}  // namespace
}  // namespace clod::cli
