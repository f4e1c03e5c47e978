// clod export BAKE.clod -o OUTDIR [--layers L] [--max-cfm-samples N] [--max-cells N]: writes,
// atomically, OUTDIR/scene.glb (the bake's mesh as one node at the origin, no animation) and
// OUTDIR/layers.json (bodies[0] with the bake's sphere-tree levels, closest-feature-map samples
// and contact-tree cells, whichever the bake holds), for the web viewer and any glTF viewer.
// Folder contract: docs/viewer-format.md. Exit codes: 1 for a bad bake (the loader's message),
// 2 for bad arguments.
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "clod/atomic_directory.h"
#include "clod/atomic_file.h"
#include "clod/bake.h"
#include "clod/debug_layers.h"
#include "clod/error.h"
#include "clod/gltf_export.h"
#include "command.h"

namespace clod::cli {
namespace {

struct ExportOptions {
  std::string bake;
  std::string outDir;
  std::string layers = "spheres,cfm,ctree";
  std::uint32_t maxCfmSamples = kDefaultMaxCfmSamples;
  std::uint32_t maxCells = kDefaultMaxContactTreeCells;
};

int runExport(const ExportOptions& o) {
  bool spheres = false, cfm = false, ctree = false;
  if (o.layers != "none") {
    std::stringstream in(o.layers);
    std::string item;
    while (std::getline(in, item, ',')) {
      if (item == "spheres") spheres = true;
      else if (item == "cfm") cfm = true;
      else if (item == "ctree") ctree = true;
      else
        throw Error(ErrorCode::kInvalidArgument,
                    "--layers: unknown layer '" + item + "' (expected spheres, cfm, ctree, or none)");
    }
  }
  const BakeContents bake = loadBake(o.bake);
  const std::filesystem::path out(o.outDir);
  checkOutputDirectory(out);  // a file or device as OUTDIR: refused before the work

  const std::string name =
      bake.sourceName.empty() ? std::filesystem::path(o.bake).stem().string() : bake.sourceName;
  GltfScene scene;
  GltfBody body;
  body.name = name;
  body.mesh = &bake.mesh;
  body.isStatic = true;  // nothing moves in a bake export
  scene.bodies.push_back(body);

  DebugLayers layers;
  BodyDebugLayers& b = layers.bodies.emplace_back();
  b.name = name;
  b.node = 0;
  if (spheres) b.sphereTree = makeSphereTreeLayer(bake.sphereTree);
  if (cfm && bake.closestFeatureMap) b.cfmSamples = makeCfmSampleLayer(*bake.closestFeatureMap, bake.sphereTree, o.maxCfmSamples);
  if (ctree && bake.contactTree) b.contactTree = makeContactTreeLayer(*bake.contactTree, o.maxCells);

  const std::string glb = encodeGlb(scene);
  const std::string json = encodeDebugLayers(layers);
  // Both as one unit (atomic_directory.h): the viewer never reads a new scene with old layers.
  static const std::string kOwned[] = {"scene.glb", "layers.json"};
  replaceDirectoryAtomically(out, kOwned, [&](const std::filesystem::path& staging) {
    writeFileAtomically(staging / "scene.glb", glb);
    writeFileAtomically(staging / "layers.json", json);
  });
  std::size_t samples = 0;
  if (b.cfmSamples)
    for (const CfmSampleLevel& l : *b.cfmSamples) samples += l.points.size() / 3;
  std::cout << "exported " << name << ": " << bake.mesh.triangleCount() << " triangles, "
            << (b.sphereTree ? b.sphereTree->levels.size() : 0) << " sphere-tree levels, "
            << (b.cfmSamples ? b.cfmSamples->size() : 0) << " CFM levels (" << samples << " samples), "
            << (b.contactTree ? std::to_string(b.contactTree->cellCount()) + " contact-tree cells (depths 0-" +
                                    std::to_string(b.contactTree->depthsIncluded - 1) + ")"
                              : std::string("no contact tree"))
            << " -> "
            << o.outDir << " (scene.glb " << glb.size() << " bytes, layers.json " << json.size() << " bytes)\n";
  return 0;
}

const CommandRegistration kRegistration("export", [](CLI::App& app) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* sub = app.add_subcommand("export", "Write a bake as scene.glb + layers.json for the viewer");
  sub->add_option("bake", options->bake, "Bake file (.clod)")->required();
  sub->add_option("-o,--output", options->outDir, "Output directory")->required();
  sub->add_option("--layers", options->layers, "Comma list of spheres, cfm, ctree, or none (default: all three)");
  sub->add_option("--max-cfm-samples", options->maxCfmSamples,
                  "Cap on CFM samples (whole levels from the root while the total fits)")
      ->check(CLI::Range(1u, 100'000'000u));
  sub->add_option("--max-cells", options->maxCells,
                  "Cap on contact-tree cells (whole depths from the root while the total fits)")
      ->check(CLI::Range(1u, 100'000'000u));
  return [options] { return runExport(*options); };
});

}  // namespace
}  // namespace clod::cli
