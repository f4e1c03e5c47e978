#include <chrono>

#include "clod/bake.h"
#include "sphere_tree_section.h"

namespace clod {

namespace {
double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

BakeResult bakeMesh(const TriangleMesh& mesh, const BakeSettings& settings) {
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
    result.contents.contactTree = buildContactTree(distance, settings.contactTree, &result.contactTreeStats);
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
