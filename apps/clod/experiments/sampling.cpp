// sampling: Tables 1 and 2 of the closest-feature-map paper (see docs/sampling.md). JSON keys:
//   rows[]   {scheme, stacks, resolution, samples, std_dev, paper_std_dev (null if none),
//             neighbour_definition, mean_distance, min_distance, max_distance}
//   table1[] {scheme, root_stacks, leaf_level, leaf_stacks, root_samples, leaf_samples,
//             paper_root_samples, paper_leaf_samples (null if none)}
//   other_definitions[] the rows' {scheme, stacks, samples, std_dev, paper_std_dev,
//             neighbour_definition} for the other neighbour definitions
//   paper_formula[] {scheme, stacks, samples, queries, misses, miss_rate, max_excess_deg,
//             mean_excess_deg}: how often the paper's plain lookup formula misses the nearest sample
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "clod/error.h"
#include "experiment.h"
#include "clod/sampling_statistics.h"
#include "clod/sphere_sampling.h"

namespace clod::cli {
namespace {

nlohmann::json optionalJson(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }
nlohmann::json optionalJson(const std::optional<std::uint32_t>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

ExperimentResult runSampling(const ExperimentOptions& options) {
  if (options.queries < 1 || options.queries > 100000000) {
    throw Error(ErrorCode::kInvalidArgument, "--queries " + std::to_string(options.queries) + " outside [1, 100000000]");
  }
  const NeighbourDefinition primary = parseNeighbourDefinition(options.neighbours);
  ExperimentResult result;
  nlohmann::json& doc = result.document;
  doc["experiment"] = "sampling";
  doc["paper"] = "Giang & O'Sullivan 2006, Computers & Graphics 30:423-431, Tables 1 and 2";
  doc["neighbour_definition"] = neighbourDefinitionName(primary);

  std::ostringstream csv, text;
  csv << "scheme,stacks,resolution,samples,neighbour_definition,std_dev,paper_std_dev,mean_distance\n";
  csv << std::setprecision(9);
  text << std::setprecision(4) << std::fixed;
  text << "Table 2: std. dev. of neighbour distances, unit sphere (" << neighbourDefinitionName(primary) << ")\n";
  text << "  scheme           stacks  samples   std_dev   paper\n";
  doc["rows"] = nlohmann::json::array();
  for (const SamplingTable2Row& row : computeSamplingTable2(primary)) {
    const std::string_view scheme = samplingSchemeName(row.scheme);
    doc["rows"].push_back({{"scheme", scheme},
                           {"stacks", row.stacks},
                           {"resolution", row.resolution},
                           {"samples", row.samples},
                           {"std_dev", row.stats.stdDev},
                           {"paper_std_dev", optionalJson(row.paperStdDev)},
                           {"neighbour_definition", neighbourDefinitionName(row.neighbourDefinition)},
                           {"mean_distance", row.stats.mean},
                           {"min_distance", row.stats.min},
                           {"max_distance", row.stats.max}});
    csv << scheme << "," << row.stacks << "," << row.resolution << "," << row.samples << ","
        << neighbourDefinitionName(row.neighbourDefinition) << "," << row.stats.stdDev << ","
        << (row.paperStdDev ? std::to_string(*row.paperStdDev) : std::string()) << "," << row.stats.mean << "\n";
    text << "  " << std::left << std::setw(16) << scheme << std::right << std::setw(7) << row.stacks
         << std::setw(9) << row.samples << std::setw(10) << row.stats.stdDev;
    if (row.paperStdDev) text << std::setw(10) << *row.paperStdDev;
    text << "\n";
  }

  doc["other_definitions"] = nlohmann::json::array();
  for (NeighbourDefinition other : {NeighbourDefinition::kNearest1, NeighbourDefinition::kNearest4, NeighbourDefinition::kNearest6}) {
    if (other == primary) continue;
    for (const SamplingTable2Row& row : computeSamplingTable2(other)) {
      doc["other_definitions"].push_back({{"scheme", samplingSchemeName(row.scheme)},
                                          {"stacks", row.stacks},
                                          {"samples", row.samples},
                                          {"std_dev", row.stats.stdDev},
                                          {"paper_std_dev", optionalJson(row.paperStdDev)},
                                          {"neighbour_definition", neighbourDefinitionName(other)}});
    }
  }

  text << "Table 1: samples at the root and at level-2 leaves (stacks halve per level)\n";
  doc["table1"] = nlohmann::json::array();
  for (const SamplingTable1Row& row : computeSamplingTable1()) {
    doc["table1"].push_back({{"scheme", samplingSchemeName(row.scheme)},
                             {"root_stacks", row.rootStacks},
                             {"leaf_level", row.leafLevel},
                             {"leaf_stacks", row.leafStacks},
                             {"root_samples", row.rootSamples},
                             {"leaf_samples", row.leafSamples},
                             {"paper_root_samples", optionalJson(row.paperRootSamples)},
                             {"paper_leaf_samples", optionalJson(row.paperLeafSamples)}});
    text << "  " << std::left << std::setw(16) << samplingSchemeName(row.scheme) << std::right << " stacks "
         << std::setw(2) << row.rootStacks << " -> " << row.leafStacks << ": root " << row.rootSamples
         << ", leaf " << row.leafSamples;
    if (row.paperRootSamples) text << " (paper " << *row.paperRootSamples << " / " << *row.paperLeafSamples << ")";
    text << "\n";
  }
  doc["table1_note"] =
      "adaptive polar: n_i = max(1, round(S sin(i pi / S))), rings i = 0..S-1; reproduces 65 (S=10), 3 (S=2), "
      "11 (S=4); the paper's 167 at S=16 is not reproduced (the rule gives 163)";

  text << "Paper's plain lookup formula vs the exact lookup (" << options.queries << " random directions)\n";
  doc["paper_formula"] = nlohmann::json::array();
  for (SamplingScheme scheme : {SamplingScheme::kPolar, SamplingScheme::kAdaptivePolar, SamplingScheme::kHealpix}) {
    for (int stacks : {5, 10, 16, 20}) {
      const SphereSampling sampling = SphereSampling::buildForStacks(scheme, stacks);
      const PaperFormulaMissStats miss = measurePaperFormulaMisses(sampling, static_cast<std::uint64_t>(options.queries), 20061);
      const double rate = static_cast<double>(miss.misses) / static_cast<double>(miss.queries);
      doc["paper_formula"].push_back({{"scheme", samplingSchemeName(scheme)},
                                      {"stacks", stacks},
                                      {"samples", sampling.size()},
                                      {"queries", miss.queries},
                                      {"misses", miss.misses},
                                      {"miss_rate", rate},
                                      {"max_excess_deg", miss.maxExcessAngle * 180.0 / M_PI},
                                      {"mean_excess_deg", miss.meanExcessAngleOfMisses * 180.0 / M_PI}});
      text << "  " << std::left << std::setw(16) << samplingSchemeName(scheme) << std::right << " stacks "
           << std::setw(2) << stacks << ": misses " << std::setw(7) << 100.0 * rate << " %, worst excess "
           << miss.maxExcessAngle * 180.0 / M_PI << " deg\n";
    }
  }
  // Table 2 as a figure: neighbour-distance spread against stacks, ours as lines, the paper's
  // values (polar and adaptive polar only) as points. gnuplot wants one column per curve.
  const std::vector<std::string> schemes = {"polar", "adaptive-polar", "geodesic", "healpix", "fibonacci"};
  std::map<int, std::map<std::string, std::string>> wide;  // stacks -> column -> value
  for (const nlohmann::json& row : doc["rows"]) {
    const int stacks = row["stacks"].get<int>();
    const std::string scheme = row["scheme"].get<std::string>();
    wide[stacks][scheme] = std::to_string(row["std_dev"].get<double>());
    if (!row["paper_std_dev"].is_null()) wide[stacks]["paper " + scheme] = std::to_string(row["paper_std_dev"].get<double>());
  }
  std::string plotCsv = "stacks";
  for (const std::string& scheme : schemes) plotCsv += "," + scheme;
  plotCsv += ",paper polar,paper adaptive-polar\n";
  for (const auto& [stacks, columns] : wide) {
    plotCsv += std::to_string(stacks);
    for (const std::string& scheme : schemes) plotCsv += "," + (columns.count(scheme) ? columns.at(scheme) : std::string("NaN"));
    for (const char* paper : {"paper polar", "paper adaptive-polar"}) plotCsv += "," + (columns.count(paper) ? columns.at(paper) : std::string("NaN"));
    plotCsv += "\n";
  }
  result.files["sampling_std_dev.csv"] = plotCsv;
  Plot plot{"sampling_std_dev", "CFM paper Table 2: spread of neighbour distances (" + std::string(neighbourDefinitionName(primary)) + ")",
            "stacks", "std. dev. of neighbour distance (rad)", {}, {"set xtics (5, 10, 20)", "set yrange [0:*]"}};
  for (std::size_t i = 0; i < schemes.size(); ++i) {
    plot.series.push_back({"sampling_std_dev.csv", "1:" + std::to_string(i + 2), schemes[i], "linespoints", ""});
  }
  plot.series.push_back({"sampling_std_dev.csv", "1:7", "paper: polar", "points pointtype 6 pointsize 2", ""});
  plot.series.push_back({"sampling_std_dev.csv", "1:8", "paper: adaptive-polar", "points pointtype 8 pointsize 2", ""});
  result.plots.push_back(std::move(plot));

  // Report: Table 2 and Table 1 beside the paper's values, with the differences explained.
  std::vector<std::vector<std::string>> t2;
  double minRatio = 1e30, maxRatio = 0.0;
  std::map<int, std::map<std::string, double>> ours;  // stacks -> scheme -> std dev
  for (const nlohmann::json& row : doc["rows"]) {
    ours[row["stacks"].get<int>()][row["scheme"].get<std::string>()] = row["std_dev"].get<double>();
    if (row["paper_std_dev"].is_null()) continue;
    const double ratio = row["std_dev"].get<double>() / row["paper_std_dev"].get<double>();
    minRatio = std::min(minRatio, ratio);
    maxRatio = std::max(maxRatio, ratio);
    t2.push_back({row["scheme"].get<std::string>(), std::to_string(row["stacks"].get<int>()),
                  std::to_string(row["samples"].get<std::uint32_t>()), formatNumber(row["std_dev"].get<double>(), 4),
                  formatNumber(row["paper_std_dev"].get<double>(), 4), formatNumber(ratio, 2)});
  }
  bool adaptiveBelowFull = true;
  for (const auto& [stacks, bySchemes] : ours) {
    if (bySchemes.count("polar") && bySchemes.count("adaptive-polar")) {
      adaptiveBelowFull = adaptiveBelowFull && bySchemes.at("adaptive-polar") < bySchemes.at("polar");
    }
  }
  std::vector<std::vector<std::string>> t1;
  for (const nlohmann::json& row : doc["table1"]) {
    if (row["paper_root_samples"].is_null()) continue;
    t1.push_back({row["scheme"].get<std::string>(),
                  std::to_string(row["root_stacks"].get<int>()) + " → " + std::to_string(row["leaf_stacks"].get<int>()),
                  std::to_string(row["root_samples"].get<std::uint32_t>()) + " (" +
                      std::to_string(row["paper_root_samples"].get<std::uint32_t>()) + ")",
                  std::to_string(row["leaf_samples"].get<std::uint32_t>()) + " (" +
                      std::to_string(row["paper_leaf_samples"].get<std::uint32_t>()) + ")"});
  }
  std::vector<std::vector<std::string>> misses;
  for (const nlohmann::json& row : doc["paper_formula"]) {
    if (row["stacks"] != 10 && row["stacks"] != 16) continue;
    misses.push_back({row["scheme"].get<std::string>(), std::to_string(row["stacks"].get<int>()),
                      formatNumber(100.0 * row["miss_rate"].get<double>(), 1) + " %",
                      formatNumber(row["max_excess_deg"].get<double>(), 1)});
  }
  std::ostringstream html;
  html << "<h3>Table 2: standard deviation of neighbour distances (unit sphere, " << neighbourDefinitionName(primary)
       << ")</h3>" << htmlTable({"scheme", "stacks", "samples", "ours", "paper", "ours / paper"}, t2)
       << "<p><b>Comparison.</b> Ours are " << formatNumber(minRatio, 2) << "&ndash;" << formatNumber(maxRatio, 2)
       << " times the paper's. The paper does not define &ldquo;neighbouring&rdquo;; we count each sample's 4 nearest "
          "samples (chord length), the definition closest to its figures (nearest-1 and nearest-6 are in the JSON; "
          "docs/sampling.md). Whether pole duplicates, ties and mutual pairs count is not stated either, which is what "
          "the remaining 10&ndash;20 % reflect. The paper's conclusions hold: adaptive polar spreads less than full "
          "polar at every stack count ("
       << (adaptiveBelowFull ? "yes" : "NO") << " here) and both fall as the stacks grow.</p>"
       << "<h3>Table 1: samples per sphere, root and level-2 leaves (stacks halved per level)</h3>"
       << htmlTable({"scheme", "stacks root → leaf", "root (paper)", "leaf (paper)"}, t1)
       << "<p><b>Comparison.</b> 65 / 3 at 10 stacks and 11 at the leaves at 16 match; the paper's 167 at the root at "
          "16 stacks is not what the adaptive rule gives (163), and no variant of the rule we tried gives all four "
          "counts (docs/sampling.md). The bake sizes are in the <a href=\"#sizes\">sizes</a> section.</p>"
       << "<h3>The paper's O(1) lookup formula vs the exact nearest sample</h3>"
       << htmlTable({"scheme", "stacks", "misses the nearest sample", "worst extra angle (deg)"}, misses)
       << "<p>The paper's index formula (its equations 4&ndash;5) picks the ring and the slot by rounding &phi; and "
          "&theta;; near ring boundaries that is not the nearest sample. It reports no such figure; our default lookup "
          "checks the neighbouring rings and is exact.</p>";
  result.reportHtml = html.str();
  result.csv = csv.str();
  result.text = text.str();
  return result;
}

const ExperimentRegistration kRegistration({"sampling", "CFM paper Tables 1-2: sample counts, neighbour-distance spread, lookup accuracy",
                                            "Closest feature maps, Tables 1 and 2", runSampling, 10});

}  // namespace
}  // namespace clod::cli
