#include <algorithm>
#include <chrono>
#include <string>

#include "clod/bake.h"
#include "clod/error.h"
#include "sphere_tree_section.h"

namespace clod {

namespace {
double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// BakeSettings::maxMemoryBytes: refused before anything is built when the triangles alone need
// more; else the contact tree gets the rest as a node limit.
ContactTreeSettings contactTreeWithinMemory(const TriangleMesh& mesh, const BakeSettings& settings) {
  ContactTreeSettings tree = settings.contactTree;
  if (settings.maxMemoryBytes == 0) return tree;
  const std::uint64_t triangles = mesh.triangles.size();
  const std::uint64_t meshBytes = triangles * kBakeBytesPerTriangle;
  if (meshBytes >= settings.maxMemoryBytes) {
    throw Error(ErrorCode::kResourceLimit,
                "bake: " + std::to_string(triangles) + " triangles need about " + std::to_string(meshBytes >> 20) +
                    " MB, more than BakeSettings::maxMemoryBytes (" + std::to_string(settings.maxMemoryBytes >> 20) +
                    " MB; clod bake --max-memory-mb); raise it or simplify the mesh");
  }
  const std::uint64_t nodes = std::max<std::uint64_t>(1, (settings.maxMemoryBytes - meshBytes) / kBakeBytesPerContactTreeNode);
  tree.maxNodes = tree.maxNodes == 0 ? nodes : std::min(tree.maxNodes, nodes);
  return tree;
}

}  // namespace

BakeResult bakeMesh(const TriangleMesh& mesh, const BakeSettings& settings) {
  const ContactTreeSettings contactTreeSettings = contactTreeWithinMemory(mesh, settings);
  BakeResult result;
  auto start = std::chrono::steady_clock::now();
  const MeshDistance distance(mesh, settings.distance);
  result.timings.distanceSeconds = secondsSince(start);
  result.signMethod = distance.signMethod();

  start = std::chrono::steady_clock::now();
  // Put on the file's grid first, so the maps, the fit figures and the bake in memory are those
  // of the tree a load returns (each sphere grows by < 0.1 % of its parent's radius).
  result.contents.sphereTree = detail::quantisedSphereTree(buildSphereTree(distance, settings.sphereTree));
  result.timings.sphereTreeSeconds = secondsSince(start);
  if (settings.buildClosestFeatureMap) {
    start = std::chrono::steady_clock::now();
    result.contents.closestFeatureMap = buildClosestFeatureMap(distance, result.contents.sphereTree, settings.closestFeatureMap);
    result.timings.cfmSeconds = secondsSince(start);
  }
  if (settings.buildContactTree) {
    start = std::chrono::steady_clock::now();
    result.contents.contactTree = buildContactTree(distance, contactTreeSettings, &result.contactTreeStats);
    result.timings.contactTreeSeconds = secondsSince(start);
  }
  result.timings.buildSeconds = result.timings.distanceSeconds + result.timings.sphereTreeSeconds +
                                result.timings.cfmSeconds + result.timings.contactTreeSeconds;

  if (settings.measureFit) {
    start = std::chrono::steady_clock::now();
    result.levelFit = measureSphereTreeFit(result.contents.sphereTree, distance);
    result.timings.fitSeconds = secondsSince(start);
  }
  result.contents.mesh = mesh;
  result.contents.meshHash = meshContentHash(mesh);
  result.contents.sourceName = settings.sourceName;
  result.contents.sphereTreeSettings = settings.sphereTree;
  return result;
}

}  // namespace clod
