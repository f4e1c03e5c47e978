// clod generate SET -o OUTDIR: writes a set of generated part meshes as OBJ files (metres).
//   mujoco-demo  the parts of scenes/mujoco/ (part_meshes.h, demoPartMeshes): ring.obj,
//                ring_peg.obj, bowl.obj, holed_block.obj, hole_peg.obj
//   nut-bolt     the M16 x 2 bolt and nut of the nut-on-bolt scenes (thread_meshes.h,
//                nutBoltMeshes): bolt.obj, nut.obj
// The files are what the scenes load; tests/mujoco checks that the committed ones equal this
// command's output. An unknown set is bad usage (exit 2).
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "clod/atomic_file.h"
#include "clod/error.h"
#include "clod/part_meshes.h"
#include "clod/thread_meshes.h"
#include "command.h"

namespace clod::cli {
namespace {

struct GenerateOptions {
  std::string set;
  std::string outDir;
};

int runGenerate(const GenerateOptions& o) {
  std::vector<NamedMesh> parts;
  if (o.set == "mujoco-demo")
    parts = demoPartMeshes();
  else if (o.set == "nut-bolt")
    parts = nutBoltMeshes();
  else
    throw Error(ErrorCode::kInvalidArgument, "generate: unknown set '" + o.set + "' (sets: mujoco-demo, nut-bolt)");
  const std::filesystem::path out(o.outDir);
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw Error(ErrorCode::kFileWriteFailed, o.outDir + ": cannot create directory: " + ec.message());
  for (const NamedMesh& part : parts) {
    writeFileAtomically(out / (part.name + ".obj"),
                        encodeObj(part.mesh, "clod generate " + o.set + ": " + part.name + " (metres)"));
    std::cout << part.name << ".obj: " << part.mesh.vertexCount() << " vertices, " << part.mesh.triangleCount()
              << " triangles\n";
  }
  return 0;
}

const CommandRegistration kRegistration("generate", [](CLI::App& app) {
  auto options = std::make_shared<GenerateOptions>();
  CLI::App* sub = app.add_subcommand("generate", "Write generated part meshes (OBJ): mujoco-demo, nut-bolt");
  sub->add_option("set", options->set, "Which parts: mujoco-demo, nut-bolt")->required();
  sub->add_option("-o,--output", options->outDir, "Output directory")->required();
  return [options] { return runGenerate(*options); };
});

}  // namespace
}  // namespace clod::cli
