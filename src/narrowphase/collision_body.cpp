#include "clod/collision_body.h"

#include <cmath>
#include <string>

#include "clod/bake.h"
#include "clod/error.h"

namespace clod {
namespace {

[[noreturn]] void fail(const std::string& message) { throw Error(ErrorCode::kInvalidArgument, message); }

// The narrow phase indexes these arrays without further checks in its hot loop, so everything
// it relies on is checked once here.
void checkTree(const SphereTree& tree, const TriangleMesh& mesh) {
  const std::uint32_t n = tree.sphereCount();
  if (n == 0 || tree.levelCount() == 0) fail("sphere-tree: empty");
  if (tree.centerX.size() != n || tree.centerY.size() != n || tree.centerZ.size() != n || tree.parent.size() != n ||
      tree.firstChild.size() != n || tree.childCount.size() != n || tree.triangleOffsets.size() != n + std::size_t{1}) {
    fail("sphere-tree: per-sphere arrays have inconsistent lengths");
  }
  if (tree.levelOffsets.front() != 0 || tree.levelOffsets.back() != n) fail("sphere-tree: level offsets do not span the spheres");
  for (std::uint32_t l = 0; l + 1 < tree.levelOffsets.size(); ++l) {
    if (tree.levelOffsets[l] >= tree.levelOffsets[l + 1]) fail("sphere-tree: level " + std::to_string(l) + " is empty");
  }
  if (tree.triangleOffsets.front() != 0 || tree.triangleOffsets.back() != tree.triangleList.size()) {
    fail("sphere-tree: triangle offsets do not span the triangle list");
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (tree.triangleOffsets[i] > tree.triangleOffsets[i + 1]) fail("sphere " + std::to_string(i) + ": triangle offsets decrease");
    if (!(tree.radius[i] >= 0.0) || !std::isfinite(tree.radius[i])) fail("sphere " + std::to_string(i) + ": bad radius");
    if (tree.childCount[i] > 0 &&
        (tree.firstChild[i] >= n || tree.childCount[i] > n - tree.firstChild[i] || tree.firstChild[i] <= i)) {
      fail("sphere " + std::to_string(i) + ": child range [" + std::to_string(tree.firstChild[i]) + ", +" +
           std::to_string(tree.childCount[i]) + ") outside the tree");
    }
  }
  for (std::size_t k = 0; k < tree.triangleList.size(); ++k) {
    if (tree.triangleList[k] >= mesh.triangleCount()) {
      fail("sphere-tree triangle reference " + std::to_string(k) + ": triangle " + std::to_string(tree.triangleList[k]) +
           " >= triangle count " + std::to_string(mesh.triangleCount()));
    }
  }
}

}  // namespace

CollisionBody::CollisionBody(TriangleMesh mesh, SphereTree tree) : mesh_(std::move(mesh)), tree_(std::move(tree)) {
  checkTree(tree_, mesh_);
  sphereLevel_.resize(tree_.sphereCount());
  for (std::uint32_t l = 0; l < tree_.levelCount(); ++l) {
    for (std::uint32_t i = tree_.levelBegin(l); i < tree_.levelEnd(l); ++i) sphereLevel_[i] = l;
  }
  diagonal_ = mesh_.bounds().diagonal();

  faceNormalOffsets_.assign(1, 0);
  std::vector<Vec3> distinct;
  for (std::uint32_t i = 0; i < tree_.sphereCount(); ++i) {
    distinct.clear();
    for (std::uint32_t t : tree_.triangles(i)) {
      const Vec3 n = mesh_.triangleNormal(t);
      if (n.squaredNorm() == 0.0) continue;
      bool known = false;
      for (const Vec3& d : distinct) known = known || d.dot(n) > 1.0 - 5e-13;  // ~1e-6 rad
      if (!known) distinct.push_back(n);
      if (distinct.size() > kMaxSphereFaceNormals) break;
    }
    if (distinct.size() <= kMaxSphereFaceNormals) {
      for (const Vec3& d : distinct) faceNormals_.push_back(d.cast<float>());
    }
    faceNormalOffsets_.push_back(static_cast<std::uint32_t>(faceNormals_.size()));
  }
}

CollisionBody CollisionBody::fromBake(const BakeContents& bake) {
  CollisionBody body(bake.mesh, bake.sphereTree);
  body.name_ = bake.sourceName;
  if (bake.closestFeatureMap) body.setClosestFeatureMap(*bake.closestFeatureMap);
  if (bake.contactTree) body.setContactTree(*bake.contactTree);
  return body;
}

void CollisionBody::setClosestFeatureMap(ClosestFeatureMap map) {
  if (map.sphereCount() != tree_.sphereCount() || map.levelCount() != tree_.levelCount()) {
    fail("closest feature map has " + std::to_string(map.sphereCount()) + " spheres in " +
         std::to_string(map.levelCount()) + " levels, the sphere-tree " + std::to_string(tree_.sphereCount()) + " in " +
         std::to_string(tree_.levelCount()));
  }
  map_ = std::move(map);
}

void CollisionBody::setContactTree(ContactTree tree) {
  if (tree.nodeCount() == 0) fail("contact tree has no nodes");
  contactTree_ = std::move(tree);
}

const ClosestFeatureMap& CollisionBody::closestFeatureMap() const noexcept {
  CLOD_ASSERT(map_.has_value());
  return *map_;
}

const ContactTree& CollisionBody::contactTree() const noexcept {
  CLOD_ASSERT(contactTree_.has_value());
  return *contactTree_;
}

}  // namespace clod
