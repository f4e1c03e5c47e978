// scaleCollisionBody (world.h): a uniformly scaled copy of a baked body, without baking again.
//
// Why no re-bake is needed: under x -> s x (s > 0) every distance scales by s and every direction
// and angle stays. So the sphere-tree's centres and radii scale (containment is kept), a closest
// feature map -- the normal of the feature nearest each sample direction of each sphere -- is
// unchanged (nearest stays nearest, normals keep their direction), and the contact tree's signed
// distances, cell geometry, half-space offsets and fit errors scale, while its error codes, stored
// relative to the cell radius, and its flat-surface bits, relative to the cell size, stay.
#include <cmath>
#include <memory>
#include <string>

#include "clod/error.h"
#include "clod/world.h"

namespace clod {

std::shared_ptr<const CollisionBody> scaleCollisionBody(const CollisionBody& shape, double scale) {
  if (!(scale > 0.0 && std::isfinite(scale)))
    throw Error(ErrorCode::kInvalidArgument, "scaleCollisionBody: scale must be > 0 and finite, got " + std::to_string(scale));
  TriangleMesh mesh = shape.mesh();
  for (Vec3& v : mesh.vertices) v *= scale;
  SphereTree tree = shape.sphereTree();
  for (auto* values : {&tree.centerX, &tree.centerY, &tree.centerZ, &tree.radius})
    for (double& x : *values) x *= scale;
  auto body = std::make_shared<CollisionBody>(std::move(mesh), std::move(tree));
  body->setName(shape.name());
  if (shape.hasClosestFeatureMap()) body->setClosestFeatureMap(shape.closestFeatureMap());
  if (shape.hasContactTree()) {
    ContactTree t = shape.contactTree();
    const float s = static_cast<float>(scale);
    t.origin *= scale;
    t.rootSize *= scale;
    t.meshDiagonal *= scale;
    t.errorAbs *= scale;
    t.bandAbs *= scale;
    for (float& x : t.rootCorners) x *= s;
    for (float& x : t.lattice) x *= s;
    for (float& x : t.gridCorners) x *= s;
    for (ContactHalfSpace& h : t.halfSpaces) {
      h.offset *= s;
      h.fitError *= s;
    }
    body->setContactTree(std::move(t));
  }
  return body;
}

}  // namespace clod
