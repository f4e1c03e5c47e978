#include "clod/sphere_tree_builder.h"

#include <string>

#include "clod/error.h"
#include "clod/proximity.h"
#include "medial_builder.h"
#include "octree_builder.h"

namespace clod {

const char* sphereTreeMethodName(SphereTreeMethod method) noexcept {
  switch (method) {
    case SphereTreeMethod::kOctree: return "octree";
    case SphereTreeMethod::kMedial: return "medial";
  }
  return "unknown";
}

SphereTreeMethod parseSphereTreeMethod(std::string_view name) {
  if (name == "octree") return SphereTreeMethod::kOctree;
  if (name == "medial") return SphereTreeMethod::kMedial;
  throw Error(ErrorCode::kInvalidArgument,
              "sphere-tree method '" + std::string(name) + "': expected 'octree' or 'medial'");
}

SphereTree buildSphereTree(const MeshDistance& mesh, const SphereTreeSettings& settings) {
  auto outOfRange = [](const char* what, std::uint32_t value, const char* range) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string("sphere-tree ") + what + " " + std::to_string(value) + " is out of range " + range);
  };
  if (settings.branching < 2 || settings.branching > 64) throw outOfRange("branching", settings.branching, "[2, 64]");
  if (settings.depth > 8) throw outOfRange("depth", settings.depth, "[0, 8]");
  if (settings.medialSamples < 100 || settings.medialSamples > 2000000)
    throw outOfRange("medialSamples", settings.medialSamples, "[100, 2000000]");
  switch (settings.method) {
    case SphereTreeMethod::kOctree: return detail::buildOctreeSphereTree(mesh.mesh(), settings);
    case SphereTreeMethod::kMedial: return detail::buildMedialSphereTree(mesh.mesh(), settings);
  }
  throw Error(ErrorCode::kInvalidArgument,
              "sphere-tree method " + std::to_string(static_cast<int>(settings.method)) + " is unknown");
}

}  // namespace clod
