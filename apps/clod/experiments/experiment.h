#pragma once
// The experiment table behind `clod experiment NAME`: each experiment reproduces a table or a
// figure of the papers, lives in its own file in this folder and registers itself with
// ExperimentRegistration (like CLI subcommands, command.h). The runner (cmd_experiment.cpp)
// writes what an experiment returns:
//   OUTDIR/NAME.json   the document (a stable contract: external checks read it)
//   OUTDIR/NAME.csv    its main table
//   OUTDIR/<file>      every extra file (more CSV tables, time series)
//   OUTDIR/<plot>.png  every plot, drawn by gnuplot from those CSV files; the gnuplot script
//                      is kept beside it as <plot>.gp so a figure can be redrawn or restyled
// and `clod experiment all -o OUTDIR` adds OUTDIR/report.html with every experiment's section.
// Everything an experiment computes is computed before anything is written; every file is
// written atomically.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace clod::cli {

struct ExperimentOptions {
  std::string name;
  bool json = false;
  std::string outDir;
  std::string neighbours = "nearest-4";  ///< sampling: neighbour definition of the rows
  long queries = 100000;                 ///< sampling: random directions per lookup-accuracy row
  /// Where the shared meshes are (default: $CLOD_MESH_DIR, else ../shared/data/meshes).
  std::string meshDir;
  /// Randomised runs per configuration for the experiments that average over initial
  /// conditions (0 = the experiment's own default, which is what the report uses).
  long trials = 0;
  std::uint64_t seed = 1;  ///< seed of every random choice (same seed, same numbers)
  /// `--quick`: a reduced configuration for smoke tests (shorter simulated times, fewer levels);
  /// same JSON keys, but not the numbers the report shows. Experiments without one ignore it.
  bool quick = false;
  /// degradation: the matrix, as comma-separated lists (empty = the experiment's defaults):
  /// scenarios or category names, contact models, test budgets, time budgets (µs), rates (Hz);
  /// and the simulated time of every run (0 = each scenario's own).
  std::string categories, models, budgets, budgetsUs, rates;
  double duration = 0.0;
};

/// One curve of a plot: columns of a CSV file the experiment writes (header line skipped).
struct PlotSeries {
  std::string dataFile;       ///< a file of ExperimentResult::files, or "NAME.csv"
  std::string columns = "1:2";///< gnuplot `using` clause, e.g. "1:3" or "($1*1000):2"
  std::string title;          ///< legend entry
  std::string style = "linespoints";  ///< gnuplot `with` clause
  /// gnuplot `every` clause; empty = "::1" (skip the CSV header line). One column per curve
  /// reads best: write a wide CSV for the plot rather than filtering rows (see sampling.cpp).
  std::string every;
};

struct Plot {
  std::string file;  ///< file stem: writes <file>.png and <file>.gp
  std::string title, xLabel, yLabel;
  std::vector<PlotSeries> series;
  /// Raw gnuplot settings inserted before `plot` (e.g. "set logscale y", "set yrange [0:1]").
  std::vector<std::string> settings;
};

struct ExperimentResult {
  nlohmann::json document;
  std::string csv;
  std::string text;  ///< the human summary printed to stdout
  std::map<std::string, std::string> files;  ///< extra output files: name -> contents
  std::vector<Plot> plots;
  /// The experiment's section of report.html (HTML fragment: tables of ours next to the
  /// paper's values, and why they differ). Empty: the report shows `text`. Plots are appended.
  std::string reportHtml;
};

using ExperimentFn = ExperimentResult (*)(const ExperimentOptions&);

struct Experiment {
  const char* name;
  const char* summary;  ///< one line for --help
  const char* paper;    ///< what of the papers it reproduces (report heading)
  ExperimentFn run;
  int order;            ///< position in `all` and in the report
};

/// Registers an experiment at static-initialisation time (one per experiment file).
struct ExperimentRegistration {
  explicit ExperimentRegistration(const Experiment& experiment);
};

/// Every registered experiment, sorted by `order`.
std::vector<Experiment> registeredExperiments();

/// Path of a shared test mesh: options.meshDir, else $CLOD_MESH_DIR, else ../shared/data/meshes.
std::filesystem::path sharedMeshPath(const ExperimentOptions& options, const std::string& name);

/// HTML helpers for report sections.
std::string htmlEscape(const std::string& text);
std::string htmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
/// Fixed-point number with `digits` decimals (for tables).
std::string formatNumber(double value, int digits);

/// Writes NAME.json, NAME.csv, the extra files and the plots of one result into dir (created
/// if needed). Throws clod::Error(kFileWriteFailed) when a file cannot be written and
/// clod::Error(kExternalToolFailed) when gnuplot is missing or fails, naming the plot.
void writeExperimentOutput(const std::filesystem::path& dir, const std::string& name, const ExperimentResult& result);

/// Writes dir/report.html: one section per (experiment, result), with plots inlined as images.
void writeExperimentReport(const std::filesystem::path& dir,
                           const std::vector<std::pair<Experiment, const ExperimentResult*>>& sections);

}  // namespace clod::cli
