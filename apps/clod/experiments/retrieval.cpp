// retrieval: how long a closest-feature-map normal lookup takes, per sampling scheme and tree
// level, against the baselines it replaces -- the D&O normal (normalise p - c), the averaged
// normal of the sphere's triangles, and an exact closest-point query on the mesh -- and how the
// nearest-sample retrieval methods compare (the paper's formula, its geodesic quadrant search,
// a linear scan). Giang & O'Sullivan 2006, sections 5-6: constant-time polar retrieval, and a
// geodesic quadrant search "four times faster than an elementary linear search".
//
// Timing: std::chrono::steady_clock (wall) and std::clock (process CPU) around batches of
// lookups over 4,096 pre-drawn queries, each batch long enough (>= ~4 ms) for the clocks; the
// median of the batches is reported (--trials = batches, default 7). Text, plot and ratios use the
// CPU medians: on a shared machine the wall clock also counts the time the process was preempted.
// This is a measurement in an experiment, not a unit test.
//
// JSON keys:
//   mesh, triangles, spheres, levels, batches, queries
//   lookups[] {method, scheme, stacks, level, spheres, samples, ns_median, ns_min, ns_max,
//              cpu_ns_median, lookups_per_batch}
//       method: cfm | dos | average | exact-closest-point | closest-among-sphere-triangles
//       (scheme and stacks are null for the non-cfm methods)
//   nearest[] {scheme, stacks, samples, method, ns_median, ns_min, ns_max, cpu_ns_median}
//       method: nearest (ours) | paper-formula | quadrant-search | linear-scan
//   ratios (of CPU medians) {cfm_over_dos_root, exact_over_cfm_root, geodesic_linear_over_quadrant_10,
//           geodesic_linear_over_quadrant_16}
//   paper {constant_time_polar, geodesic_quadrant_speedup}
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/error.h"
#include "clod/mesh_io.h"
#include "clod/proximity.h"
#include "clod/sphere_sampling.h"
#include "clod/sphere_tree_builder.h"
#include "experiment.h"

namespace clod::cli {
namespace {

constexpr std::size_t kQueries = 4096;
constexpr long kDefaultBatches = 7;
constexpr double kMinBatchSeconds = 0.004;  // well above steady_clock and std::clock resolution

// Keeps the optimiser from dropping the timed work: every lookup's answer feeds this sum.
volatile double gSink = 0.0;

struct Timing {
  double nsMedian = 0.0, nsMin = 0.0, nsMax = 0.0, cpuNsMedian = 0.0;
  std::size_t perBatch = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Times fn(i) for i cycling over the queries. The batch size doubles from 64 until one batch
// takes kMinBatchSeconds (so cheap and expensive lookups are both timed over a few ms), then
// `batches` batches of that size are timed.
template <class Fn>
Timing timeLookups(long batches, Fn&& fn) {
  auto runBatch = [&](std::size_t n, double& cpuSeconds) {
    double sum = 0.0;
    const std::clock_t c0 = std::clock();
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < n; ++i) sum += fn(i % kQueries);
    const auto t1 = std::chrono::steady_clock::now();
    cpuSeconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    gSink = gSink + sum;
    return std::chrono::duration<double>(t1 - t0).count();
  };
  std::size_t n = 64;
  double cpu = 0.0;
  while (n < (std::size_t(1) << 22) && runBatch(n, cpu) < kMinBatchSeconds) n *= 2;
  std::vector<double> wall, cpus;
  for (long b = 0; b < batches; ++b) {
    wall.push_back(runBatch(n, cpu) * 1e9 / static_cast<double>(n));
    cpus.push_back(cpu * 1e9 / static_cast<double>(n));
  }
  Timing t;
  t.nsMedian = median(wall);
  t.nsMin = *std::min_element(wall.begin(), wall.end());
  t.nsMax = *std::max_element(wall.begin(), wall.end());
  t.cpuNsMedian = median(cpus);
  t.perBatch = n;
  return t;
}

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  for (;;) {
    const Vec3 v(g(rng), g(rng), g(rng));
    const double n = v.norm();
    if (n > 1e-9) return v / n;
  }
}

ExperimentResult runRetrieval(const ExperimentOptions& options) {
  if (options.trials > 1000) {
    throw Error(ErrorCode::kInvalidArgument, "--trials " + std::to_string(options.trials) + " outside [0, 1000] (retrieval: timed batches)");
  }
  const long batches = options.trials > 0 ? options.trials : kDefaultBatches;
  const std::string meshName = "spot.obj";  // the mesh of docs/benchmarks/cfm.md
  const MeshDistance distance(loadMesh(sharedMeshPath(options, meshName)).mesh);
  const SphereTreeSettings treeSettings;  // the bake default (medial, 8-ary, 5 levels)
  const SphereTree tree = buildSphereTree(distance, treeSettings);
  const std::uint32_t levels = tree.levelCount();

  // Per level: kQueries (sphere of that level, contact point on its surface) pairs.
  std::mt19937_64 rng(options.seed);
  struct LevelQueries { std::vector<std::uint32_t> sphere; std::vector<Vec3> point; };
  std::vector<LevelQueries> queries(levels);
  for (std::uint32_t l = 0; l < levels; ++l) {
    std::uniform_int_distribution<std::uint32_t> pick(tree.levelBegin(l), tree.levelEnd(l) - 1);
    for (std::size_t q = 0; q < kQueries; ++q) {
      const std::uint32_t s = pick(rng);
      const Vec3 c(tree.centerX[s], tree.centerY[s], tree.centerZ[s]);
      queries[l].sphere.push_back(s);
      queries[l].point.push_back(c + tree.radius[s] * randomUnit(rng));
    }
  }
  auto centre = [&](std::uint32_t s) { return Vec3(tree.centerX[s], tree.centerY[s], tree.centerZ[s]); };

  ExperimentResult result;
  nlohmann::json& doc = result.document;
  doc["experiment"] = "retrieval";
  doc["paper"] = "Giang & O'Sullivan 2006, sections 5-6 (retrieval); docs/benchmarks/cfm.md";
  doc["mesh"] = meshName;
  doc["triangles"] = distance.mesh().triangleCount();
  doc["spheres"] = tree.sphereCount();
  doc["levels"] = levels;
  doc["batches"] = batches;
  doc["queries"] = kQueries;
  doc["lookups"] = nlohmann::json::array();
  std::ostringstream csv, text;
  csv << "method,scheme,stacks,level,spheres,samples,ns_median,ns_min,ns_max,cpu_ns_median,lookups_per_batch\n";
  csv << std::setprecision(6);
  text << std::fixed << std::setprecision(1);
  text << "CFM retrieval on " << meshName << " (" << distance.mesh().triangleCount() << " triangles, " << tree.sphereCount()
       << " spheres, " << levels << " levels); median CPU ns per lookup over " << batches << " batches\n";

  // ns per level per curve, for the plot: curve label -> level -> ns.
  std::map<std::string, std::map<std::uint32_t, double>> curves;
  std::vector<std::string> curveOrder;
  auto addRow = [&](const std::string& method, std::optional<SamplingScheme> scheme, int stacks, std::uint32_t level,
                    std::uint32_t samples, const Timing& t) {
    const nlohmann::json schemeJson = scheme ? nlohmann::json(samplingSchemeName(*scheme)) : nlohmann::json(nullptr);
    const nlohmann::json stacksJson = scheme ? nlohmann::json(stacks) : nlohmann::json(nullptr);
    const std::uint32_t spheres = tree.levelEnd(level) - tree.levelBegin(level);
    doc["lookups"].push_back({{"method", method}, {"scheme", schemeJson}, {"stacks", stacksJson}, {"level", level},
                              {"spheres", spheres}, {"samples", samples}, {"ns_median", t.nsMedian}, {"ns_min", t.nsMin},
                              {"ns_max", t.nsMax}, {"cpu_ns_median", t.cpuNsMedian}, {"lookups_per_batch", t.perBatch}});
    csv << method << "," << (scheme ? std::string(samplingSchemeName(*scheme)) : "") << ","
        << (scheme ? std::to_string(stacks) : "") << "," << level << "," << spheres << "," << samples << "," << t.nsMedian
        << "," << t.nsMin << "," << t.nsMax << "," << t.cpuNsMedian << "," << t.perBatch << "\n";
    const std::string label = scheme ? "cfm " + std::string(samplingSchemeName(*scheme)) + " " + std::to_string(stacks) : method;
    if (!curves.count(label)) curveOrder.push_back(label);
    curves[label][level] = t.cpuNsMedian;
  };

  // Baselines first (independent of the maps).
  std::map<std::uint32_t, double> dosNs, exactNs, cfmDefaultNs;
  for (std::uint32_t l = 0; l < levels; ++l) {
    const LevelQueries& lq = queries[l];
    const Timing dos = timeLookups(batches, [&](std::size_t i) {
      return (lq.point[i] - centre(lq.sphere[i])).normalized().x();
    });
    addRow("dos", std::nullopt, 0, l, 0, dos);
    dosNs[l] = dos.cpuNsMedian;
    const Timing exact = timeLookups(batches, [&](std::size_t i) { return distance.closestPoint(lq.point[i]).normal.x(); });
    addRow("exact-closest-point", std::nullopt, 0, l, 0, exact);
    exactNs[l] = exact.cpuNsMedian;
    const Timing among = timeLookups(batches, [&](std::size_t i) {
      return distance.closestPointAmong(lq.point[i], tree.triangles(lq.sphere[i])).normal.x();
    });
    addRow("closest-among-sphere-triangles", std::nullopt, 0, l, 0, among);
  }

  // The maps: every scheme at the paper's 10 stacks and at our default 16 (adaptive polar).
  struct MapConfig { SamplingScheme scheme; int stacks; };
  std::vector<MapConfig> configs;
  for (SamplingScheme s : allSamplingSchemes()) configs.push_back({s, 10});
  for (SamplingScheme s : allSamplingSchemes()) configs.push_back({s, 16});
  bool averageDone = false;
  for (const MapConfig& config : configs) {
    ClosestFeatureMapSettings settings;
    settings.scheme = config.scheme;
    settings.rootStacks = config.stacks;
    const ClosestFeatureMap map = buildClosestFeatureMap(distance, tree, settings);
    for (std::uint32_t l = 0; l < levels; ++l) {
      const LevelQueries& lq = queries[l];
      if (!averageDone) {
        const Timing avg = timeLookups(batches, [&](std::size_t i) { return map.averageNormal(lq.sphere[i]).x(); });
        addRow("average", std::nullopt, 0, l, 0, avg);
      }
      const Timing t = timeLookups(batches, [&](std::size_t i) {
        const std::uint32_t s = lq.sphere[i];
        return map.normal(s, lq.point[i] - centre(s)).x();
      });
      addRow("cfm", config.scheme, config.stacks, l, map.samplesAtLevel(l), t);
      if (config.scheme == SamplingScheme::kAdaptivePolar && config.stacks == 16) cfmDefaultNs[l] = t.cpuNsMedian;
    }
    averageDone = true;
  }

  // Nearest-sample retrieval alone (the sampling, no map): our exact lookup, the paper's formula,
  // its geodesic quadrant search, and a linear scan.
  doc["nearest"] = nlohmann::json::array();
  std::vector<Vec3> directions;
  for (std::size_t q = 0; q < kQueries; ++q) directions.push_back(randomUnit(rng));
  std::map<int, double> geoLinear, geoQuadrant;
  std::ostringstream nearestCsv;
  nearestCsv << "scheme,stacks,samples,method,ns_median,ns_min,ns_max,cpu_ns_median\n" << std::setprecision(6);
  for (int stacks : {10, 16}) {
    for (SamplingScheme scheme : allSamplingSchemes()) {
      const SphereSampling sampling = SphereSampling::buildForStacks(scheme, stacks);
      const bool ring = sampling.ringCount() > 0;
      std::vector<std::pair<std::string, Timing>> rows;
      rows.emplace_back("nearest", timeLookups(batches, [&](std::size_t i) { return double(sampling.nearest(directions[i])); }));
      if (ring) {
        rows.emplace_back("paper-formula",
                          timeLookups(batches, [&](std::size_t i) { return double(sampling.nearestPaperFormula(directions[i])); }));
      }
      if (scheme == SamplingScheme::kGeodesic) {
        rows.emplace_back("quadrant-search",
                          timeLookups(batches, [&](std::size_t i) { return double(sampling.nearestQuadrantSearch(directions[i])); }));
      }
      rows.emplace_back("linear-scan", timeLookups(batches, [&](std::size_t i) { return double(sampling.nearestLinearScan(directions[i])); }));
      for (const auto& [method, t] : rows) {
        doc["nearest"].push_back({{"scheme", samplingSchemeName(scheme)}, {"stacks", stacks}, {"samples", sampling.size()},
                                  {"method", method}, {"ns_median", t.nsMedian}, {"ns_min", t.nsMin}, {"ns_max", t.nsMax},
                                  {"cpu_ns_median", t.cpuNsMedian}});
        nearestCsv << samplingSchemeName(scheme) << "," << stacks << "," << sampling.size() << "," << method << ","
                   << t.nsMedian << "," << t.nsMin << "," << t.nsMax << "," << t.cpuNsMedian << "\n";
        if (scheme == SamplingScheme::kGeodesic && method == "linear-scan") geoLinear[stacks] = t.cpuNsMedian;
        if (scheme == SamplingScheme::kGeodesic && method == "quadrant-search") geoQuadrant[stacks] = t.cpuNsMedian;
      }
    }
  }
  result.files["retrieval_nearest.csv"] = nearestCsv.str();

  const double cfmOverDos = cfmDefaultNs[0] / dosNs[0];
  const double exactOverCfm = exactNs[0] / cfmDefaultNs[0];
  doc["ratios"] = {{"cfm_over_dos_root", cfmOverDos},
                   {"exact_over_cfm_root", exactOverCfm},
                   {"geodesic_linear_over_quadrant_10", geoLinear[10] / geoQuadrant[10]},
                   {"geodesic_linear_over_quadrant_16", geoLinear[16] / geoQuadrant[16]}};
  doc["paper"] = {{"constant_time_polar", "polar retrieval is a constant-time lookup (no timing figure given)"},
                  {"geodesic_quadrant_speedup", 4.0}};

  // Text summary: ns per level for the main curves.
  text << "  method                           ";
  for (std::uint32_t l = 0; l < levels; ++l) text << "  level " << l;
  text << "\n";
  for (const std::string& label : curveOrder) {
    if (label.rfind("cfm ", 0) == 0 && label != "cfm adaptive-polar 16" && label != "cfm adaptive-polar 10" &&
        label != "cfm geodesic 10")
      continue;
    text << "  " << std::left << std::setw(32) << label << std::right;
    for (std::uint32_t l = 0; l < levels; ++l) text << std::setw(9) << curves[label][l];
    text << "\n";
  }
  text << std::setprecision(2) << "  cfm (adaptive polar 16) / D&O at the root: " << cfmOverDos
       << "x; exact closest point / cfm: " << exactOverCfm << "x\n"
       << "  geodesic linear scan / quadrant search: " << geoLinear[10] / geoQuadrant[10] << "x (10 stacks), "
       << geoLinear[16] / geoQuadrant[16] << "x (16 stacks); paper: 4x\n";

  // Plot: ns per lookup against level (wide CSV, one column per curve).
  std::vector<std::string> plotted = {"cfm adaptive-polar 16", "cfm adaptive-polar 10", "cfm polar 10", "cfm geodesic 10",
                                      "cfm healpix 10", "cfm fibonacci 10", "dos", "average", "exact-closest-point",
                                      "closest-among-sphere-triangles"};
  std::string wide = "level";
  for (const std::string& label : plotted) wide += "," + label;
  wide += "\n";
  for (std::uint32_t l = 0; l < levels; ++l) {
    wide += std::to_string(l);
    for (const std::string& label : plotted) wide += "," + std::to_string(curves[label][l]);
    wide += "\n";
  }
  result.files["retrieval_levels.csv"] = wide;
  Plot plot{"retrieval_levels", "Normal retrieval time per lookup (" + meshName + ", median of " + std::to_string(batches) + " batches)",
            "sphere-tree level (0 = root)", "CPU ns per lookup", {}, {"set logscale y", "set xtics 1", "set key outside right"}};
  for (std::size_t i = 0; i < plotted.size(); ++i) {
    // The maps solid, the baselines dashed: ten curves share gnuplot's eight colours.
    const bool baseline = plotted[i].rfind("cfm ", 0) != 0;
    plot.series.push_back({"retrieval_levels.csv", "1:" + std::to_string(i + 2), plotted[i],
                           baseline ? "linespoints dashtype 2 linewidth 2" : "linespoints", ""});
  }
  result.plots.push_back(std::move(plot));

  // Report section.
  std::vector<std::vector<std::string>> rows;
  for (const std::string& label : plotted) {
    std::vector<std::string> row = {label};
    for (std::uint32_t l = 0; l < levels; ++l) row.push_back(formatNumber(curves[label][l], 1));
    rows.push_back(row);
  }
  std::vector<std::string> header = {"method (CPU ns per lookup, median)"};
  for (std::uint32_t l = 0; l < levels; ++l) header.push_back("level " + std::to_string(l));
  std::vector<std::vector<std::string>> nearestRows;
  for (const nlohmann::json& r : doc["nearest"]) {
    nearestRows.push_back({r["scheme"].get<std::string>(), std::to_string(r["stacks"].get<int>()),
                           std::to_string(r["samples"].get<std::uint32_t>()), r["method"].get<std::string>(),
                           formatNumber(r["ns_median"].get<double>(), 1), formatNumber(r["cpu_ns_median"].get<double>(), 1)});
  }
  std::ostringstream html;
  html << "<p>Mesh " << meshName << " (" << distance.mesh().triangleCount() << " triangles), bake-default sphere-tree ("
       << tree.sphereCount() << " spheres, " << levels << " levels), " << kQueries
       << " random (sphere, contact point on it) queries per level; median of " << batches
       << " timed batches. Figures are process CPU time (std::clock) per lookup: on the 2 shared cores the std::chrono "
          "wall times (in the JSON and CSV) are inflated by preemption, up to 3x in single batches.</p>"
       << htmlTable(header, rows)
       << "<p><b>Paper:</b> polar retrieval is a constant-time lookup (equations 4-5), no timing is given; the geodesic "
          "quadrant search was &ldquo;four times faster than an elementary linear search&rdquo;. <b>Ours:</b> the CFM lookup "
          "costs about the same at every level (constant time; deeper levels have fewer samples and are not slower), "
       << formatNumber(cfmOverDos, 1) << "x a D&amp;O normal at the root and " << formatNumber(exactOverCfm, 1)
       << "x cheaper than an exact closest-point query on the whole mesh (BVH). The geodesic linear scan over quadrant search: "
       << formatNumber(geoLinear[10] / geoQuadrant[10], 1) << "x at 10 stacks, " << formatNumber(geoLinear[16] / geoQuadrant[16], 1)
       << "x at 16 (paper 4x; the ratio grows with the sample count, and the paper does not say its resolution). "
          "Our default <i>nearest</i> lookup is exact (the paper's formula can miss the nearest sample near ring "
          "boundaries, see the sampling experiment) and for geodesic uses a cube-map candidate list instead of the "
          "quadrant search.</p>"
       << "<p><b>docs/benchmarks/cfm.md</b> (Google Benchmark, spot, 10 stacks, random sphere of any level): adaptive polar "
          "118 ns CPU, geodesic 53 ns, D&amp;O 5.6 ns. The figures here are per level and CPU time, so directly comparable.</p>"
       << htmlTable({"scheme", "stacks", "samples", "nearest-sample method", "ns (wall)", "ns (CPU)"}, nearestRows);
  result.reportHtml = html.str();
  result.csv = csv.str();
  result.text = text.str();
  return result;
}

const ExperimentRegistration kRegistration({"retrieval",
                                            "CFM retrieval timings: ns per normal lookup per scheme and level vs D&O, average and exact closest point",
                                            "Closest feature maps, retrieval timings (sections 5-6)", runRetrieval, 35});

}  // namespace
}  // namespace clod::cli
