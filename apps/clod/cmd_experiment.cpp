// clod experiment NAME [--json] [-o OUTDIR]: reproduce a table or figure of the papers.
//
// Experiments are a name -> function table (kExperiments below); each returns a JSON document
// (a stable contract: external checks read it), a CSV of its main table and a text summary.
// --json prints the document; -o OUTDIR writes OUTDIR/NAME.json and OUTDIR/NAME.csv, each
// atomically. "all" runs every experiment. Everything is computed before anything is printed or
// written, so an error leaves no partial output.
//
// sampling: Tables 1 and 2 of the closest-feature-map paper (see docs/sampling.md). JSON keys:
//   rows[]   {scheme, stacks, resolution, samples, std_dev, paper_std_dev (null if none),
//             neighbour_definition, mean_distance, min_distance, max_distance}
//   table1[] {scheme, root_stacks, leaf_level, leaf_stacks, root_samples, leaf_samples,
//             paper_root_samples, paper_leaf_samples (null if none)}
//   other_definitions[] the rows' {scheme, stacks, samples, std_dev, paper_std_dev,
//             neighbour_definition} for the other neighbour definitions
//   paper_formula[] {scheme, stacks, samples, queries, misses, miss_rate, max_excess_deg,
//             mean_excess_deg}: how often the paper's plain lookup formula misses the nearest sample
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "clod/atomic_file.h"
#include "clod/error.h"
#include "clod/sampling_statistics.h"
#include "clod/sphere_sampling.h"
#include "command.h"
#include "clod/bake.h"
#include "clod/closest_feature_map.h"
#include "clod/mesh_io.h"
#include "clod/normal_accuracy.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

namespace clod::cli {
namespace {

struct ExperimentOptions {
  std::string name;
  bool json = false;
  std::string outDir;
  std::string neighbours = std::string(neighbourDefinitionName(NeighbourDefinition::kNearest4));
  long queries = 100000;
  /// normals, sizes: where the shared meshes are (default: $CLOD_MESH_DIR, else ../shared/data/meshes).
  std::string meshDir;
};

struct ExperimentResult {
  nlohmann::json document;
  std::string csv;
  std::string text;
};

using ExperimentFn = ExperimentResult (*)(const ExperimentOptions&);

struct Experiment {
  const char* name;
  const char* summary;
  ExperimentFn run;
};

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
  result.csv = csv.str();
  result.text = text.str();
  return result;
}

std::filesystem::path sharedMeshPath(const ExperimentOptions& options, const std::string& name) {
  std::string dir = options.meshDir;
  if (dir.empty()) {
    const char* env = std::getenv("CLOD_MESH_DIR");
    dir = env != nullptr && *env != '\0' ? env : "../shared/data/meshes";
  }
  return std::filesystem::path(dir) / name;
}

// normals: contact-normal accuracy per sphere-tree level and model (the point of the CFM paper;
// distribution and definitions in normal_accuracy.h and docs/closest-feature-maps.md). JSON keys:
//   meshes[] {mesh, triangles, sign_method, levels[] {level, spheres, points, attempts,
//             models[] {model, median_deg, p95_deg, mean_deg, max_deg}}}
//   settings {points_per_level, near_surface_fraction, seed, sphere_tree}
// Model names: dos, average, cfm-<scheme>-<stacks> (oct16), cfm-adaptive-polar-10-oct32.
ExperimentResult runNormals(const ExperimentOptions& options) {
  ExperimentResult result;
  nlohmann::json& doc = result.document;
  doc["experiment"] = "normals";
  NormalAccuracySettings settings;
  settings.pointsPerLevel = 2000;
  const SphereTreeSettings treeSettings;  // the bake default
  doc["settings"] = {{"points_per_level", settings.pointsPerLevel},
                     {"near_surface_fraction", settings.nearSurfaceFraction},
                     {"seed", settings.seed},
                     {"sphere_tree", {{"method", sphereTreeMethodName(treeSettings.method)},
                                      {"branching", treeSettings.branching},
                                      {"depth", treeSettings.depth}}}};
  std::ostringstream csv, text;
  csv << "mesh,level,spheres,points,model,median_deg,p95_deg,mean_deg,max_deg\n" << std::setprecision(6);
  text << std::fixed << std::setprecision(2);
  doc["meshes"] = nlohmann::json::array();
  const char* meshNames[] = {"box", "spot.obj", "cow.obj", "fandisk.obj", "rocker-arm.obj", "bunny-1500.obj", "teapot.obj", "suzanne.obj"};
  for (const char* name : meshNames) {
    const std::string meshName = name;
    TriangleMesh mesh = meshName == "box" ? makeBox(Vec3(1.0, 0.6, 0.3))
                                          : loadMesh(sharedMeshPath(options, meshName)).mesh;
    const MeshDistance distance(std::move(mesh));
    const SphereTree tree = buildSphereTree(distance, treeSettings);
    std::vector<ClosestFeatureMap> maps;
    std::vector<std::string> labels;
    for (int stacks : {10, 16}) {
      for (SamplingScheme scheme : allSamplingSchemes()) {
        ClosestFeatureMapSettings s;
        s.scheme = scheme;
        s.rootStacks = stacks;
        maps.push_back(buildClosestFeatureMap(distance, tree, s));
        labels.push_back("cfm-" + std::string(samplingSchemeName(scheme)) + "-" + std::to_string(stacks));
      }
    }
    ClosestFeatureMapSettings wide;
    wide.codec = NormalCodec::kOctahedral32;
    maps.push_back(buildClosestFeatureMap(distance, tree, wide));
    labels.push_back("cfm-adaptive-polar-10-oct32");
    std::vector<NormalAccuracyCandidate> candidates = {{"dos", ContactNormalModel::kDingliana, &maps[0]},
                                                       {"average", ContactNormalModel::kAverage, &maps[0]}};
    for (std::size_t k = 0; k < maps.size(); ++k) candidates.push_back({labels[k], ContactNormalModel::kClosestFeatureMap, &maps[k]});
    const std::vector<NormalAccuracyLevel> levels = measureNormalAccuracy(distance, tree, candidates, settings);

    nlohmann::json meshDoc = {{"mesh", meshName}, {"triangles", distance.mesh().triangleCount()},
                              {"sign_method", signMethodName(distance.signMethod())}};
    meshDoc["levels"] = nlohmann::json::array();
    text << meshName << " (" << distance.mesh().triangleCount() << " triangles): median / p95 angle error, degrees\n";
    text << "  level  points       dos   average  cfm-ap-10  cfm-hp-10  cfm-ap-16  cfm-hp-16\n";
    for (const NormalAccuracyLevel& level : levels) {
      nlohmann::json models = nlohmann::json::array();
      for (std::size_t k = 0; k < candidates.size(); ++k) {
        const AngleErrorStats& st = level.models[k];
        models.push_back({{"model", candidates[k].label}, {"median_deg", st.medianDeg}, {"p95_deg", st.p95Deg},
                          {"mean_deg", st.meanDeg}, {"max_deg", st.maxDeg}});
        csv << meshName << "," << level.level << "," << level.spheres << "," << level.points << "," << candidates[k].label
            << "," << st.medianDeg << "," << st.p95Deg << "," << st.meanDeg << "," << st.maxDeg << "\n";
      }
      meshDoc["levels"].push_back({{"level", level.level}, {"spheres", level.spheres}, {"points", level.points},
                                   {"attempts", level.attempts}, {"models", models}});
      // Columns: dos, average, adaptive polar and HEALPix at 10 and 16 stacks.
      text << "  " << std::setw(5) << level.level << std::setw(8) << level.points;
      std::vector<std::size_t> columns;
      for (const char* label : {"dos", "average", "cfm-adaptive-polar-10", "cfm-healpix-10", "cfm-adaptive-polar-16", "cfm-healpix-16"}) {
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          if (candidates[k].label == label) columns.push_back(k);
        }
      }
      for (std::size_t k : columns) {
        std::ostringstream cell;
        cell << std::fixed << std::setprecision(1) << level.models[k].medianDeg << "/" << level.models[k].p95Deg;
        text << " " << std::setw(k < 2 ? 10 : 11) << cell.str();
      }
      text << "\n";
    }
    doc["meshes"].push_back(meshDoc);
  }
  result.csv = csv.str();
  result.text = text.str();
  return result;
}

// sizes: the CFM paper's Table 1 - root and leaf samples at 10 and 16 stacks and bake file sizes
// for a cube and bunny-1500 (sphere-tree of the paper's three levels: depth 2, 8-ary, medial;
// stacks halved per level down to 1 as in the paper, min_stacks 1; 16-bit normals). JSON keys:
//   rows[] {mesh, triangles, stacks, root_samples, leaf_samples, paper_root_samples,
//           paper_leaf_samples, spheres, stored_normals, single_normal_spheres, file_bytes,
//           cfm_bytes, sphere_tree_bytes, mesh_bytes, paper_file_size_k}
ExperimentResult runSizes(const ExperimentOptions& options) {
  ExperimentResult result;
  nlohmann::json& doc = result.document;
  doc["experiment"] = "sizes";
  doc["paper"] = "Giang & O'Sullivan 2006, Table 1 (file also held the sphere-tree)";
  doc["rows"] = nlohmann::json::array();
  std::ostringstream csv, text;
  csv << "mesh,triangles,stacks,root_samples,leaf_samples,paper_root_samples,paper_leaf_samples,file_bytes,cfm_bytes,sphere_tree_bytes,mesh_bytes,paper_file_size_k\n";
  text << "Table 1: samples per sphere (root / leaf) and bake file size\n";
  struct Row { const char* mesh; int stacks; std::uint32_t paperRoot, paperLeaf, paperK; };
  const Row rows[] = {{"cube", 10, 65, 3, 112}, {"bunny-1500.obj", 10, 65, 3, 130},
                      {"cube", 16, 167, 11, 345}, {"bunny-1500.obj", 16, 167, 11, 415}};
  for (const Row& row : rows) {
    const std::string meshName = row.mesh;
    const TriangleMesh mesh = meshName == "cube" ? makeBox(Vec3(1.0, 1.0, 1.0))
                                                 : loadMesh(sharedMeshPath(options, meshName)).mesh;
    BakeSettings settings;
    settings.sphereTree.depth = 2;
    settings.measureFit = false;
    settings.closestFeatureMap.rootStacks = row.stacks;
    settings.closestFeatureMap.minStacks = 1;
    settings.buildContactTree = false;  // the paper's Table 1 files held the sphere-tree and maps only
    const BakeResult baked = bakeMesh(mesh, settings);
    const std::vector<std::byte> bytes = encodeBake(baked.contents);
    const BakeFileReader file(bytes);
    std::uint64_t cfmBytes = 0, treeBytes = 0, meshBytes = 0;
    for (const BakeSectionEntry& e : file.entries()) {
      if (e.tag == kBakeCfmTag) cfmBytes = e.size;
      if (e.tag == kBakeSphereTreeTag) treeBytes = e.size;
      if (e.tag == kBakeMeshTag) meshBytes = e.size;
    }
    const ClosestFeatureMap& cfm = *baked.contents.closestFeatureMap;
    const std::uint32_t leafLevel = cfm.levelCount() - 1;
    std::uint32_t single = 0;
    for (std::uint32_t i = 0; i < cfm.sphereCount(); ++i) single += cfm.isSingleNormal(i) ? 1u : 0u;
    doc["rows"].push_back({{"mesh", meshName}, {"triangles", mesh.triangleCount()}, {"stacks", row.stacks},
                           {"root_samples", cfm.samplesAtLevel(0)}, {"leaf_samples", cfm.samplesAtLevel(leafLevel)},
                           {"paper_root_samples", row.paperRoot}, {"paper_leaf_samples", row.paperLeaf},
                           {"spheres", cfm.sphereCount()}, {"stored_normals", cfm.poolSize()},
                           {"single_normal_spheres", single}, {"file_bytes", bytes.size()}, {"cfm_bytes", cfmBytes},
                           {"sphere_tree_bytes", treeBytes}, {"mesh_bytes", meshBytes}, {"paper_file_size_k", row.paperK}});
    csv << meshName << "," << mesh.triangleCount() << "," << row.stacks << "," << cfm.samplesAtLevel(0) << ","
        << cfm.samplesAtLevel(leafLevel) << "," << row.paperRoot << "," << row.paperLeaf << "," << bytes.size() << ","
        << cfmBytes << "," << treeBytes << "," << meshBytes << "," << row.paperK << "\n";
    text << "  " << std::left << std::setw(16) << meshName << std::right << " stacks " << std::setw(2) << row.stacks
         << ": root " << cfm.samplesAtLevel(0) << " (paper " << row.paperRoot << "), leaf " << cfm.samplesAtLevel(leafLevel)
         << " (paper " << row.paperLeaf << "), file " << bytes.size() << " bytes (CFM " << cfmBytes << ", tree "
         << treeBytes << ", mesh " << meshBytes << "; paper " << row.paperK << "k)\n";
  }
  doc["note"] = "the paper's 167 root samples at 16 stacks are not reproduced by the adaptive-polar rule (163)";
  result.csv = csv.str();
  result.text = text.str();
  return result;
}

ExperimentResult runAll(const ExperimentOptions& options);

// Later experiments (fidelity, landing, flat-contact, sizes, retrieval) plug in here.
constexpr Experiment kExperiments[] = {
    {"sampling", "CFM paper Tables 1-2: sample counts, neighbour-distance spread, lookup accuracy", runSampling},
    {"normals", "contact-normal angle error per sphere-tree level: D&O, average, CFM per scheme (shared meshes)", runNormals},
    {"sizes", "CFM paper Table 1: root/leaf samples at 10 and 16 stacks and bake file sizes (cube, bunny-1500)", runSizes},
    {"all", "every experiment above", runAll},
};

ExperimentResult runAll(const ExperimentOptions& options) {
  ExperimentResult all;
  all.document = nlohmann::json::object();
  for (const Experiment& e : kExperiments) {
    if (e.run == runAll) continue;
    ExperimentResult one = e.run(options);
    all.document[e.name] = std::move(one.document);
    all.csv += "# " + std::string(e.name) + "\n" + one.csv;
    all.text += one.text;
  }
  return all;
}

const Experiment& findExperiment(const std::string& name) {
  std::string valid;
  for (const Experiment& e : kExperiments) {
    if (name == e.name) return e;
    valid += (valid.empty() ? "" : ", ") + std::string(e.name);
  }
  throw Error(ErrorCode::kInvalidArgument, "unknown experiment '" + name + "' (valid: " + valid + ")");
}

int runExperiment(const ExperimentOptions& options) {
  const Experiment& experiment = findExperiment(options.name);
  const ExperimentResult result = experiment.run(options);
  if (!options.outDir.empty()) {
    const std::filesystem::path dir(options.outDir);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || !std::filesystem::is_directory(dir)) {
      throw Error(ErrorCode::kFileWriteFailed, "output directory '" + options.outDir + "': " +
                                                   (ec ? ec.message() : std::string("not a directory")));
    }
    writeFileAtomically(dir / (options.name + ".json"), result.document.dump(2) + "\n");
    writeFileAtomically(dir / (options.name + ".csv"), result.csv);
  }
  if (options.json) {
    printJson(result.document);
  } else {
    std::cout << result.text;
  }
  return 0;
}

const CommandRegistration kRegistration("experiment", [](CLI::App& app) {
  auto options = std::make_shared<ExperimentOptions>();
  std::string names;
  for (const Experiment& e : kExperiments) names += std::string("\n  ") + e.name + ": " + e.summary;
  CLI::App* sub = app.add_subcommand("experiment", "Reproduce a table or figure of the papers. Experiments:" + names);
  sub->add_option("name", options->name, "Experiment name")->required();
  sub->add_flag("--json", options->json, "Print the result as one JSON object (stable keys)");
  sub->add_option("-o,--output", options->outDir, "Also write NAME.json and NAME.csv into this directory (created if needed)");
  sub->add_option("--neighbours", options->neighbours, "sampling: neighbour definition of the rows (nearest-1, nearest-4, nearest-6)")
      ->capture_default_str();
  sub->add_option("--mesh-dir", options->meshDir,
                  "normals, sizes: directory of the shared test meshes (default $CLOD_MESH_DIR or ../shared/data/meshes)");
  sub->add_option("--queries", options->queries, "sampling: random directions per lookup-accuracy row")->capture_default_str();
  return [options] { return runExperiment(*options); };
});

}  // namespace
}  // namespace clod::cli
