// Registration of experiments and writing their output: files, gnuplot plots, report.html.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "clod/atomic_file.h"
#include "clod/error.h"
#include "experiment.h"

namespace clod::cli {
namespace {

std::vector<Experiment>& experimentTable() {
  static std::vector<Experiment> table;  // function-local: filled during static initialisation
  return table;
}

// Single-quoted for /bin/sh: ' becomes '\''.
std::string shellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Double-quoted gnuplot string literal.
std::string gnuplotString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

std::string gnuplotScript(const Plot& plot) {
  std::ostringstream gp;
  // `clod experiment` passes outfile=<name>.png.tmp (renamed into place on success); by hand,
  // `gnuplot <name>.gp` in the output folder redraws <name>.png directly.
  gp << "# Drawn by `clod experiment`; redraw with: gnuplot " << plot.file << ".gp\n"
     << "if (!exists(\"outfile\")) outfile = " << gnuplotString(plot.file + ".png") << "\n"
     << "set terminal pngcairo noenhanced size 960,600 font \"sans,10\"\n"
     << "set output outfile\n"
     << "set datafile separator \",\"\n"
     << "set title " << gnuplotString(plot.title) << "\n"
     << "set xlabel " << gnuplotString(plot.xLabel) << "\n"
     << "set ylabel " << gnuplotString(plot.yLabel) << "\n"
     << "set grid\nset key outside right top\n";
  for (const std::string& setting : plot.settings) gp << setting << "\n";
  gp << "plot ";
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const PlotSeries& s = plot.series[i];
    gp << (i ? ", \\\n     " : "") << gnuplotString(s.dataFile) << " every " << (s.every.empty() ? "::1" : s.every)
       << " using " << s.columns << " with " << s.style << " title " << gnuplotString(s.title);
  }
  gp << "\n";
  return gp.str();
}

// Runs gnuplot on dir/<plot>.gp; the PNG appears under a temporary name and is renamed into
// place only when gnuplot succeeded, so a failed plot never leaves a half-drawn image.
void drawPlot(const std::filesystem::path& dir, const Plot& plot) {
  if (plot.series.empty()) throw Error(ErrorCode::kInvalidArgument, "plot '" + plot.file + "' has no series");
  writeFileAtomically(dir / (plot.file + ".gp"), gnuplotScript(plot));
  const std::filesystem::path log = dir / (plot.file + ".gp.log.tmp");
  const std::string command = "cd " + shellQuoted(dir.string()) + " && gnuplot -e " + shellQuoted("outfile=\"" + plot.file + ".png.tmp\"") + " " + shellQuoted(plot.file + ".gp") +
                              " > " + shellQuoted(log.filename().string()) + " 2>&1";
  const int status = std::system(command.c_str());
  std::string messages;
  {
    std::ifstream in(log);
    std::stringstream buffer;
    buffer << in.rdbuf();
    messages = buffer.str();
  }
  std::error_code ignored;
  std::filesystem::remove(log, ignored);
  const std::filesystem::path png = dir / (plot.file + ".png.tmp");
  if (status != 0 || !std::filesystem::exists(png)) {
    std::filesystem::remove(png, ignored);
    throw Error(ErrorCode::kExternalToolFailed,
                "gnuplot failed on plot '" + plot.file + "' (is gnuplot installed? scripts/install-deps.sh installs it)" +
                    (messages.empty() ? std::string() : ": " + messages.substr(0, 400)));
  }
  std::filesystem::rename(png, dir / (plot.file + ".png"));
}

void createDirectory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw Error(ErrorCode::kFileWriteFailed,
                "output directory '" + dir.string() + "': " + (ec ? ec.message() : std::string("not a directory")));
  }
}

constexpr const char* kReportStyle =
    "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}"
    "th{background:#f3f3f3}td:first-child,th:first-child{text-align:left}pre{background:#f7f7f7;padding:.8em;"
    "overflow-x:auto}img{max-width:100%;border:1px solid #ddd;margin:.5em 0}h2{border-bottom:2px solid #ddd}"
    "nav a{margin-right:1em}";

}  // namespace

ExperimentRegistration::ExperimentRegistration(const Experiment& experiment) { experimentTable().push_back(experiment); }

std::vector<Experiment> registeredExperiments() {
  std::vector<Experiment> sorted = experimentTable();
  std::stable_sort(sorted.begin(), sorted.end(), [](const Experiment& a, const Experiment& b) { return a.order < b.order; });
  return sorted;
}

std::filesystem::path sharedMeshPath(const ExperimentOptions& options, const std::string& name) {
  std::string dir = options.meshDir;
  if (dir.empty()) {
    const char* env = std::getenv("CLOD_MESH_DIR");
    dir = env != nullptr && *env != '\0' ? env : "../shared/data/meshes";
  }
  return std::filesystem::path(dir) / name;
}

std::string htmlEscape(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '&': escaped += "&amp;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

std::string htmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::string html = "<table><tr>";
  for (const std::string& h : header) html += "<th>" + htmlEscape(h) + "</th>";
  html += "</tr>\n";
  for (const auto& row : rows) {
    html += "<tr>";
    for (const std::string& cell : row) html += "<td>" + htmlEscape(cell) + "</td>";
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

std::string formatNumber(double value, int digits) {
  if (!std::isfinite(value)) return "n/a";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

void writeExperimentOutput(const std::filesystem::path& dir, const std::string& name, const ExperimentResult& result) {
  createDirectory(dir);
  writeFileAtomically(dir / (name + ".json"), result.document.dump(2) + "\n");
  writeFileAtomically(dir / (name + ".csv"), result.csv);
  for (const auto& [file, contents] : result.files) writeFileAtomically(dir / file, contents);
  for (const Plot& plot : result.plots) drawPlot(dir, plot);
}

void writeExperimentReport(const std::filesystem::path& dir,
                           const std::vector<std::pair<Experiment, const ExperimentResult*>>& sections) {
  createDirectory(dir);
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>clod: the papers' experiments"
       << "</title><style>" << kReportStyle << "</style></head><body>\n"
       << "<h1>clod: the papers' experiments, reproduced</h1>\n"
       << "<p>Written by <code>clod experiment all -o OUTDIR</code> (REPRODUCING.md says how to rerun it). Each "
          "section shows our numbers next to the values the papers report and explains the differences. Every "
          "figure's data is in the CSV/JSON files beside this page and its gnuplot script in the .gp file.</p>\n<nav>";
  for (const auto& [experiment, result] : sections) html << "<a href=\"#" << experiment.name << "\">" << experiment.name << "</a>";
  html << "</nav>\n";
  for (const auto& [experiment, result] : sections) {
    html << "<section id=\"" << experiment.name << "\"><h2>" << htmlEscape(experiment.name) << ": "
         << htmlEscape(experiment.paper) << "</h2>\n";
    html << (result->reportHtml.empty() ? "<pre>" + htmlEscape(result->text) + "</pre>\n" : result->reportHtml);
    for (const Plot& plot : result->plots) {
      html << "<figure><img src=\"" << htmlEscape(plot.file) << ".png\" alt=\"" << htmlEscape(plot.title)
           << "\"><figcaption>" << htmlEscape(plot.title) << "</figcaption></figure>\n";
    }
    html << "<p>Data: <a href=\"" << experiment.name << ".csv\">" << experiment.name << ".csv</a>, <a href=\""
         << experiment.name << ".json\">" << experiment.name << ".json</a></p></section>\n";
  }
  html << "</body></html>\n";
  writeFileAtomically(dir / "report.html", html.str());
}

}  // namespace clod::cli
