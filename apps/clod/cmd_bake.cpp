// clod bake MESH -o OUT.clod [--sphere-tree octree|medial] [--branching B] [--levels L] [--json]:
// build everything a bake file holds for a mesh and write it atomically.
//
// The JSON keys are a stable contract (external checks use them): levels (one entry per
// sphere-tree level, root first, each with spheres, fit_mean, fit_max in units of the
// bounding-box diagonal), build_seconds, file_bytes; plus extras (mesh_hash, vertices,
// triangles, sign_method, method, branching, depth, per-stage seconds, sections, warnings).
// Closest feature maps (--sampling, --stacks; default adaptive-polar, 10 stacks, the paper's):
// each levels entry also has samples_per_sphere_max / samples_per_sphere_min (sample points of
// that level's spheres' maps, the paper's Table 1 "samples"), stacks, stored_normals_min/max and
// single_normal_spheres; top level: sampling, stacks, min_stacks, normal_codec, cfm_normals.
// Contact tree (--sdf-error E relative to the bbox diagonal, default 1e-3; --sdf-depth D;
// --no-sdf skips it): sdf_cells (octree nodes), sdf_leaves, sdf_bytes (size of the 'CTRE'
// section in the file), sdf_seconds (build time); with --no-sdf the counts are 0 and
// sdf_seconds is null. Extras: sdf_error, sdf_depth, sdf_depth_reached, sdf_surface_cells,
// sdf_leaves_above_error.
// Nothing is printed until the file is written, so an error leaves stdout empty, and a failed
// bake leaves neither OUT.clod nor a temporary file behind.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "clod/atomic_file.h"
#include "clod/bake.h"
#include "clod/error.h"
#include "clod/mesh_io.h"
#include "clod/sphere_sampling.h"
#include "command.h"

namespace clod::cli {
namespace {

struct BakeOptions {
  std::string meshPath;
  std::string outputPath;
  std::string method = sphereTreeMethodName(SphereTreeSettings{}.method);
  std::uint32_t branching = SphereTreeSettings{}.branching;
  std::uint32_t levels = SphereTreeSettings{}.depth;
  std::uint32_t medialSamples = SphereTreeSettings{}.medialSamples;
  // Closest feature maps (--sampling, --stacks, --min-stacks, --normal-codec).
  std::string sampling = std::string(samplingSchemeName(ClosestFeatureMapSettings{}.scheme));
  int stacks = ClosestFeatureMapSettings{}.rootStacks;
  int minStacks = ClosestFeatureMapSettings{}.minStacks;
  std::string normalCodec = std::string(normalCodecName(ClosestFeatureMapSettings{}.codec));
  // Contact tree (--sdf-error, --sdf-depth, --no-sdf).
  double sdfError = ContactTreeSettings{}.errorRel;
  std::uint32_t sdfDepth = ContactTreeSettings{}.maxDepth;
  bool noSdf = false;
  std::uint64_t maxMemoryMb = BakeSettings{}.maxMemoryBytes >> 20;  // --max-memory-mb, 0: no limit
  MeshLoadOptions limits;  // --max-vertices, --max-triangles, --max-polygon-vertices
  bool json = false;
};

std::vector<std::string> samplingSchemeNames() {
  std::vector<std::string> names;
  for (SamplingScheme scheme : allSamplingSchemes()) names.emplace_back(samplingSchemeName(scheme));
  return names;
}

std::string hex64(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

int runBake(const BakeOptions& options) {
  BakeSettings settings;
  settings.sphereTree.method = parseSphereTreeMethod(options.method);
  settings.sphereTree.branching = options.branching;
  settings.sphereTree.depth = options.levels;
  settings.sphereTree.medialSamples = options.medialSamples;
  settings.sourceName = std::filesystem::path(options.meshPath).filename().string();
  settings.closestFeatureMap.scheme = parseSamplingScheme(options.sampling);
  settings.closestFeatureMap.rootStacks = options.stacks;
  settings.closestFeatureMap.minStacks = std::min(options.minStacks, options.stacks);
  settings.closestFeatureMap.codec = parseNormalCodec(options.normalCodec);
  settings.buildContactTree = !options.noSdf;
  settings.contactTree.errorRel = options.sdfError;
  settings.contactTree.maxDepth = options.sdfDepth;
  settings.maxMemoryBytes = options.maxMemoryMb << 20;

  LoadedMesh loaded = loadMesh(options.meshPath, options.limits);
  const BakeResult result = bakeMesh(loaded.mesh, settings);

  const auto writeStart = std::chrono::steady_clock::now();
  const std::vector<std::byte> bytes = encodeBake(result.contents);
  writeFileAtomically(options.outputPath, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  const double writeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - writeStart).count();

  const BakeContents& contents = result.contents;
  const SphereTree& tree = contents.sphereTree;
  const BakeFileReader file(bytes);
  std::uint64_t sdfBytes = 0;
  for (const BakeSectionEntry& e : file.entries()) {
    if (e.tag == kBakeContactTreeTag) sdfBytes = e.size;
  }
  std::uint32_t sdfLeaves = 0;
  if (contents.contactTree) {
    for (std::uint32_t n = 0; n < contents.contactTree->nodeCount(); ++n) sdfLeaves += contents.contactTree->isLeaf(n) ? 1u : 0u;
  }

  if (options.json) {
    nlohmann::json out;
    out["mesh"] = options.meshPath;
    out["file"] = options.outputPath;
    out["vertices"] = contents.mesh.vertexCount();
    out["triangles"] = contents.mesh.triangleCount();
    out["mesh_hash"] = hex64(contents.meshHash);  // a string: JSON numbers cannot carry 64 bits exactly
    out["sign_method"] = signMethodName(result.signMethod);
    out["method"] = sphereTreeMethodName(settings.sphereTree.method);
    out["branching"] = settings.sphereTree.branching;
    out["depth"] = settings.sphereTree.depth;
    if (settings.sphereTree.method == SphereTreeMethod::kMedial) out["medial_samples"] = settings.sphereTree.medialSamples;
    nlohmann::json levels = nlohmann::json::array();
    for (std::uint32_t l = 0; l < result.levelFit.size(); ++l) {
      const SphereTreeLevelFit& fit = result.levelFit[l];
      nlohmann::json level = {{"level", l}, {"spheres", fit.spheres}, {"fit_mean", fit.fitMean}, {"fit_max", fit.fitMax}};
      if (contents.closestFeatureMap) {
        // samples_per_sphere_*: sample points of the sphere's map (the paper's Table 1 "samples");
        // stored_normals_*: normals actually stored (1 for a single-normal sphere).
        const ClosestFeatureMap& cfm = *contents.closestFeatureMap;
        std::uint32_t storedMin = ~0u, storedMax = 0, single = 0;
        for (std::uint32_t i = tree.levelBegin(l); i < tree.levelEnd(l); ++i) {
          storedMin = std::min(storedMin, cfm.storedNormalCount(i));
          storedMax = std::max(storedMax, cfm.storedNormalCount(i));
          single += cfm.isSingleNormal(i) ? 1u : 0u;
        }
        level["stacks"] = cfm.stacksAtTreeLevel(l);
        level["samples_per_sphere_max"] = cfm.samplesAtLevel(l);
        level["samples_per_sphere_min"] = cfm.samplesAtLevel(l);
        level["stored_normals_min"] = storedMin;
        level["stored_normals_max"] = storedMax;
        level["single_normal_spheres"] = single;
      }
      levels.push_back(level);
    }
    out["levels"] = levels;
    out["spheres"] = tree.sphereCount();
    out["build_seconds"] = result.timings.buildSeconds;
    out["distance_seconds"] = result.timings.distanceSeconds;
    out["sphere_tree_seconds"] = result.timings.sphereTreeSeconds;
    out["fit_seconds"] = result.timings.fitSeconds;
    out["cfm_seconds"] = result.timings.cfmSeconds;
    if (contents.closestFeatureMap) {
      out["sampling"] = samplingSchemeName(contents.closestFeatureMap->settings().scheme);
      out["stacks"] = contents.closestFeatureMap->settings().rootStacks;
      out["min_stacks"] = contents.closestFeatureMap->settings().minStacks;
      out["normal_codec"] = normalCodecName(contents.closestFeatureMap->settings().codec);
      out["cfm_normals"] = contents.closestFeatureMap->poolSize();
    }
    const ContactTree* sdf = contents.contactTree ? &*contents.contactTree : nullptr;
    out["sdf_cells"] = sdf ? sdf->nodeCount() : 0u;
    out["sdf_leaves"] = sdfLeaves;
    out["sdf_bytes"] = sdfBytes;
    out["sdf_seconds"] = sdf ? nlohmann::json(result.timings.contactTreeSeconds) : nlohmann::json(nullptr);
    out["sdf_error"] = sdf ? nlohmann::json(settings.contactTree.errorRel) : nlohmann::json(nullptr);
    out["sdf_depth"] = sdf ? nlohmann::json(settings.contactTree.maxDepth) : nlohmann::json(nullptr);
    out["sdf_depth_reached"] = sdf ? nlohmann::json(sdf->depthCount() - 1) : nlohmann::json(nullptr);
    out["sdf_surface_cells"] = sdf ? sdf->halfSpaces.size() : 0u;
    out["sdf_leaves_above_error"] = result.contactTreeStats.leavesAboveError;
    out["write_seconds"] = writeSeconds;
    out["file_bytes"] = bytes.size();
    nlohmann::json sections = nlohmann::json::array();
    for (const BakeSectionEntry& e : file.entries()) {
      sections.push_back({{"tag", bakeSectionTagName(e.tag)}, {"version", e.version}, {"bytes", e.size}});
    }
    out["sections"] = sections;
    out["warnings"] = loaded.warnings;
    printJson(out);
    return 0;
  }

  for (const std::string& w : loaded.warnings) std::cerr << "clod: warning: " << w << "\n";
  std::ostringstream text;
  text << "baked " << options.meshPath << " -> " << options.outputPath << " (" << bytes.size() << " bytes) in "
       << result.timings.buildSeconds << " s\n"
       << "  mesh: " << contents.mesh.vertexCount() << " vertices, " << contents.mesh.triangleCount()
       << " triangles, hash " << hex64(contents.meshHash) << ", sign " << signMethodName(result.signMethod) << "\n"
       << "  sphere-tree: " << sphereTreeMethodName(settings.sphereTree.method) << ", branching "
       << settings.sphereTree.branching << ", " << tree.levelCount() << " levels, " << tree.sphereCount()
       << " spheres\n";
  for (std::uint32_t l = 0; l < result.levelFit.size(); ++l) {
    const SphereTreeLevelFit& fit = result.levelFit[l];
    text << "    level " << l << ": " << fit.spheres << " spheres, fit mean " << fit.fitMean << ", max " << fit.fitMax
         << " (of the bbox diagonal)";
    if (contents.closestFeatureMap) {
      text << ", " << contents.closestFeatureMap->samplesAtLevel(l) << " CFM samples per sphere";
    }
    text << "\n";
  }
  if (contents.contactTree) {
    const ContactTree& sdf = *contents.contactTree;
    text << "  contact tree: " << sdf.nodeCount() << " cells, " << sdfLeaves << " leaves, depth "
         << sdf.depthCount() - 1 << " of " << sdf.maxDepth << ", error " << settings.contactTree.errorRel
         << " of the bbox diagonal, " << sdfBytes << " bytes, " << result.timings.contactTreeSeconds << " s\n";
  } else {
    text << "  contact tree: not built (--no-sdf)\n";
  }
  std::cout << text.str();
  return 0;
}

const CommandRegistration kRegistration("bake", [](CLI::App& app) {
  auto options = std::make_shared<BakeOptions>();
  CLI::App* sub = app.add_subcommand(
      "bake", "Build the sphere-tree, closest feature maps and contact tree of a mesh and write a .clod bake file");
  sub->add_option("mesh", options->meshPath, "Mesh file (OBJ, STL, PLY, OFF, glTF/GLB)")->required();
  sub->add_option("-o,--output", options->outputPath, "Bake file to write (written atomically)")->required();
  sub->add_option("--sphere-tree", options->method, "Sphere-tree builder")
      ->check(CLI::IsMember({"octree", "medial"}))
      ->capture_default_str();
  sub->add_option("--branching", options->branching, "Maximum children per sphere, 2..64")->capture_default_str();
  sub->add_option("--levels", options->levels,
                  "Levels below the root (SphereTreeSettings::depth), 0..8; the tree and the JSON 'levels' "
                  "array have L+1 levels, root first")
      ->capture_default_str();
  sub->add_option("--medial-samples", options->medialSamples,
                  "Surface samples for the medial-axis builder, 100..2000000")
      ->capture_default_str();
  sub->add_option("--sampling", options->sampling,
                  "Closest feature map sampling scheme (sphere_sampling.h)")
      ->check(CLI::IsMember(samplingSchemeNames()))
      ->capture_default_str();
  sub->add_option("--stacks", options->stacks, "Closest feature map stacks at the root, halved per level (1..)")
      ->check(CLI::Range(1, maxSamplingResolution(SamplingScheme::kPolar)))
      ->capture_default_str();
  sub->add_option("--min-stacks", options->minStacks, "Fewest stacks on any level (capped at --stacks)")
      ->check(CLI::Range(1, maxSamplingResolution(SamplingScheme::kPolar)))
      ->capture_default_str();
  sub->add_option("--normal-codec", options->normalCodec, "Encoding of stored normals: oct16 or oct32")
      ->check(CLI::IsMember({"oct16", "oct32"}))
      ->capture_default_str();
  sub->add_option("--sdf-error", options->sdfError,
                  "Contact tree: largest interpolation error near the surface, relative to the bbox diagonal (> 0)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--sdf-depth", options->sdfDepth, "Contact tree: deepest octree level (root = 0), 1..20")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  sub->add_flag("--no-sdf", options->noSdf, "Do not build the contact tree (no 'CTRE' section)");
  sub->add_option("--max-memory-mb", options->maxMemoryMb,
                  "Memory the bake may use, in MiB (0: no limit); past it: error [resource_limit]")
      ->check(CLI::Range(std::uint64_t{0}, std::uint64_t{1} << 40))
      ->capture_default_str();
  addMeshLimitOptions(sub, &options->limits);
  sub->add_flag("--json", options->json,
                "Print one JSON object: levels[{level, spheres, fit_mean, fit_max}] (fit in units of the "
                "bbox diagonal), build_seconds, file_bytes, mesh_hash, vertices, triangles, sign_method, "
                "method, branching, ...");
  return [options] { return runBake(*options); };
});

}  // namespace
}  // namespace clod::cli
