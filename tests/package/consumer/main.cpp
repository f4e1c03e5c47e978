// A program outside the clod tree: found through find_package(clod) or pkg-config, it bakes
// two unit boxes, asks the narrow phase for their contacts and prints the versions.
#include <cstdio>
#include <cstring>

#include "clod/bake.h"
#include "clod/collision_body.h"
#include "clod/primitives.h"
#include "clod/query.h"
#include "clod/version.h"

int main() {
  clod::BakeSettings settings;
  settings.sphereTree.depth = 2;  // small: this checks linking, not accuracy
  settings.measureFit = false;
  settings.buildContactTree = false;
  const clod::CollisionBody box = clod::CollisionBody::fromBake(
      clod::bakeMesh(clod::makeBox(clod::Vec3(0.5, 0.5, 0.5)), settings).contents);

  clod::Pose lower, upper;
  upper.translation = clod::Vec3(0.0, 0.0, 0.9);  // 0.1 of overlap along z
  const clod::QueryResult result = clod::queryContacts(box, upper, box, lower, clod::QuerySettings{});

  std::printf("clod headers %s, library %s\n", CLOD_VERSION_STRING, clod::version());
  std::printf("colliding %d, contacts %zu\n", int(result.colliding), result.contacts.size());
  if (std::strcmp(CLOD_VERSION_STRING, clod::version()) != 0) return 1;
  return result.colliding && !result.contacts.empty() ? 0 : 1;
}
