// sizes: the CFM paper's Table 1 - root and leaf samples at 10 and 16 stacks and bake file sizes
// for a cube and bunny-1500 (sphere-tree of the paper's three levels: depth 2, 8-ary, medial;
// stacks halved per level down to 1 as in the paper, min_stacks 1; 16-bit normals). JSON keys:
//   rows[] {mesh, triangles, stacks, root_samples, leaf_samples, paper_root_samples,
//           paper_leaf_samples, spheres, stored_normals, single_normal_spheres, file_bytes,
//           cfm_bytes, sphere_tree_bytes, mesh_bytes, paper_file_size_k}
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "clod/error.h"
#include "experiment.h"
#include "clod/bake.h"
#include "clod/bake_file.h"
#include "clod/closest_feature_map.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"

namespace clod::cli {
namespace {

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

const ExperimentRegistration kRegistration({"sizes", "CFM paper Table 1: root/leaf samples at 10 and 16 stacks and bake file sizes (cube, bunny-1500)",
                                            "Closest feature maps, Table 1 (sizes)", runSizes, 20});

}  // namespace
}  // namespace clod::cli
