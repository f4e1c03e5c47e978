#include "clod/collision_body.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <mutex>
#include <string>

#include "clod/bake.h"
#include "clod/cell_support.h"
#include "clod/error.h"
#include "proximity/triangle_closest_point.h"
#include "patch_hull.h"
#include "proximity/triangle_bvh.h"

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

struct CollisionBody::LazyTriangleBvh {
  std::once_flag once;
  detail::TriangleBvh bvh;
};

const detail::TriangleBvh& CollisionBody::triangleBvh() const {
  std::call_once(triangleBvh_->once, [this] {
    std::vector<Aabb> boxes(mesh_.triangles.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
      for (std::uint32_t v : mesh_.triangles[i]) boxes[i].extend(mesh_.vertices[v]);
    triangleBvh_->bvh = detail::TriangleBvh(boxes, detail::BvhBuildSettings{});
  });
  return triangleBvh_->bvh;
}

CollisionBody::CollisionBody(TriangleMesh mesh, SphereTree tree)
    : mesh_(std::move(mesh)), tree_(std::move(tree)), triangleBvh_(std::make_shared<LazyTriangleBvh>()) {
  checkTree(tree_, mesh_);
  sphereLevel_.resize(tree_.sphereCount());
  for (std::uint32_t l = 0; l < tree_.levelCount(); ++l) {
    for (std::uint32_t i = tree_.levelBegin(l); i < tree_.levelEnd(l); ++i) sphereLevel_[i] = l;
  }
  diagonal_ = mesh_.bounds().diagonal();
  thinTriangle_.resize(mesh_.triangleCount());
  for (std::uint32_t t = 0; t < mesh_.triangleCount(); ++t)
    thinTriangle_[t] = detail::isThinTriangle(mesh_.corner(t, 0), mesh_.corner(t, 1), mesh_.corner(t, 2));

  faceNormalOffsets_.assign(1, 0);
  patchVertexOffsets_.assign(1, 0);
  supportVertexOffsets_.assign(1, 0);
  std::vector<Vec3> distinct;
  std::vector<std::uint32_t> vertices;
  std::vector<Vec3> edgeDirections;
  edgeDirectionOffsets_.assign(1, 0);
  // Edge -> triangle table (sorted by edge), for the coplanar neighbours of patch triangles.
  std::vector<EdgeRef> edges;
  edges.reserve(3 * std::size_t{mesh_.triangleCount()});
  for (std::uint32_t t = 0; t < mesh_.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = mesh_.triangles[t][k], w = mesh_.triangles[t][(k + 1) % 3];
      edges.push_back({std::min(u, w), std::max(u, w), t});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    if (x.v0 != y.v0) return x.v0 < y.v0;
    return x.v1 != y.v1 ? x.v1 < y.v1 : x.triangle < y.triangle;
  });
  // How many planes each vertex's triangles lie in (to ~1e-6 rad, as face normals are counted),
  // counted up to 3; a zero-area triangle counts as a second plane. One plane: the vertex lies
  // inside a flat region (when none of its edges is a border either; not counted as an inner
  // vertex). Three or more on a convex polyhedron: a corner (two: along an edge), and a patch of
  // the whole body lists only the corners.
  std::vector<std::uint8_t> planeCount(mesh_.vertices.size(), 0);
  {
    std::vector<std::array<Vec3, 3>> planes(mesh_.vertices.size(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
    for (std::uint32_t t = 0; t < mesh_.triangleCount(); ++t) {
      const Vec3 n = mesh_.triangleNormal(t);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = mesh_.triangles[t][k];
        std::uint8_t& count = planeCount[v];
        if (n.squaredNorm() == 0.0) {
          count = std::max<std::uint8_t>(count, 2);
          continue;
        }
        bool known = false;
        for (std::uint8_t j = 0; j < count; ++j) known = known || planes[v][j].dot(n) > 1.0 - 5e-13;
        if (!known && count < 3) planes[v][count++] = n;
      }
    }
  }
  std::vector<std::uint8_t> flatInside(mesh_.vertices.size());
  for (std::size_t v = 0; v < flatInside.size(); ++v) flatInside[v] = planeCount[v] <= 1;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].v0 == edges[i].v0 && edges[j].v1 == edges[i].v1) ++j;
    if (j - i != 2) flatInside[edges[i].v0] = flatInside[edges[i].v1] = 0;
    i = j;
  }
  classifyConvexPolyhedron(edges);
  innerVertexOffsets_.assign(1, 0);
  std::vector<std::uint32_t> inner;
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
    const bool faceted = !distinct.empty() && distinct.size() <= kMaxSphereFaceNormals;
    bool whole = false;
    if (faceted) {
      for (const Vec3& d : distinct) faceNormals_.push_back(d.cast<float>());
      vertices.clear();
      edgeDirections.clear();
      for (std::uint32_t t : tree_.triangles(i)) {
        for (int k = 0; k < 3; ++k) vertices.push_back(mesh_.triangles[t][k]);
        // The coplanar neighbours' far corners too: a face split into triangles ends at a
        // diagonal that is no edge of the body; a patch holding only one of the triangles would
        // otherwise look like a sliver where that diagonal passes over the other body's edge.
        const Vec3 n = mesh_.triangleNormal(t);
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t u = mesh_.triangles[t][k], w = mesh_.triangles[t][(k + 1) % 3];
          const auto range = std::equal_range(edges.begin(), edges.end(), EdgeRef{std::min(u, w), std::max(u, w), 0},
                                              [](const EdgeRef& x, const EdgeRef& y) {
                                                return x.v0 != y.v0 ? x.v0 < y.v0 : x.v1 < y.v1;
                                              });
          bool sharp = false;
          for (auto it = range.first; it != range.second; ++it) {
            if (it->triangle == t) continue;
            if (mesh_.triangleNormal(it->triangle).dot(n) <= 1.0 - 5e-13) {
              sharp = true;
              continue;
            }
            for (int q = 0; q < 3; ++q) vertices.push_back(mesh_.triangles[it->triangle][q]);
          }
          if (sharp || range.second - range.first == 1) {
            // A body edge (or a border): its direction is a separating-axis ingredient.
            const Vec3 e = (mesh_.vertices[w] - mesh_.vertices[u]).normalized();
            bool known = false;
            for (const Vec3& d : edgeDirections) known = known || std::abs(d.dot(e)) > 1.0 - 5e-13;
            if (!known && e.allFinite()) edgeDirections.push_back(e);
          }
        }
      }
      std::sort(vertices.begin(), vertices.end());
      vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
      whole = vertices.size() == usedVertexCount_;
      if (whole && convexPolyhedron_)
        vertices.erase(std::remove_if(vertices.begin(), vertices.end(), [&](std::uint32_t v) { return planeCount[v] < 3; }),
                       vertices.end());
      if (vertices.size() <= kMaxSpherePatchVertices) {
        patchVertices_.insert(patchVertices_.end(), vertices.begin(), vertices.end());
        if (edgeDirections.size() <= kMaxSphereEdgeDirections) {
          for (const Vec3& d : edgeDirections) edgeDirections_.push_back(d.cast<float>());
        }
      }
    }
    edgeDirectionOffsets_.push_back(static_cast<std::uint32_t>(edgeDirections_.size()));
    wholeBodyPatch_.push_back(whole && patchVertices_.size() > patchVertexOffsets_.back());  // and the patch was kept
    faceNormalOffsets_.push_back(static_cast<std::uint32_t>(faceNormals_.size()));
    patchVertexOffsets_.push_back(static_cast<std::uint32_t>(patchVertices_.size()));
    const bool hasPatch = patchVertexOffsets_[i + 1] > patchVertexOffsets_[i];
    supportSlack_.push_back(hasPatch ? 0.0 : detail::appendPatchSupportVertices(mesh_, tree_.triangles(i), supportVertices_));
    supportVertexOffsets_.push_back(static_cast<std::uint32_t>(supportVertices_.size()));
    // Inner vertices: those of the patch the support set leaves out, not inside a flat region.
    if (!hasPatch) {
      const std::span<const std::uint32_t> support = sphereSupportVertices(i);  // ascending
      inner.clear();
      for (std::uint32_t t : tree_.triangles(i)) {
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t v = mesh_.triangles[t][k];
          if (!flatInside[v] && !std::binary_search(support.begin(), support.end(), v)) inner.push_back(v);
        }
      }
      std::sort(inner.begin(), inner.end());
      inner.erase(std::unique(inner.begin(), inner.end()), inner.end());
      if (inner.size() <= kMaxSphereInnerVertices) innerVertices_.insert(innerVertices_.end(), inner.begin(), inner.end());
    }
    innerVertexOffsets_.push_back(static_cast<std::uint32_t>(innerVertices_.size()));
  }
  findNeighbours(edges);
  computeVertexNormals();
}

void CollisionBody::findNeighbours(std::span<const EdgeRef> sortedEdges) {
  neighbours_.assign(3 * std::size_t{mesh_.triangleCount()}, kNoNeighbour);
  auto edgeIndex = [this](std::uint32_t t, std::uint32_t v0, std::uint32_t v1) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = mesh_.triangles[t][k], w = mesh_.triangles[t][(k + 1) % 3];
      if (std::min(u, w) == v0 && std::max(u, w) == v1) return k;
    }
    return 0;  // not reached: the edge came from this triangle
  };
  for (std::size_t i = 0; i < sortedEdges.size();) {
    std::size_t j = i;
    while (j < sortedEdges.size() && sortedEdges[j].v0 == sortedEdges[i].v0 && sortedEdges[j].v1 == sortedEdges[i].v1) ++j;
    if (j - i == 2) {
      const EdgeRef& x = sortedEdges[i];
      const EdgeRef& y = sortedEdges[i + 1];
      neighbours_[3 * std::size_t{x.triangle} + edgeIndex(x.triangle, x.v0, x.v1)] = y.triangle;
      neighbours_[3 * std::size_t{y.triangle} + edgeIndex(y.triangle, y.v0, y.v1)] = x.triangle;
    }
    i = j;
  }
}

// Vertex normals weighted by the triangles' angles at the vertex (Thuermer and Wuethrich 1998:
// independent of how the faces are triangulated -- a tessellated box's corner faces its three
// faces alike), summed over every copy of a position: a mesh stored with one vertex copy per
// face would otherwise give an edge's vertex its own face's normal, and a box's side-face vertex
// pressed into a floor was pushed out sideways.
void CollisionBody::computeVertexNormals() {
  // Copies agree to rounding: positions on a lattice of 1e-9 of the diagonal count as one.
  const auto& p = mesh_.vertices;
  const double cell = 1e-9 * std::max(diagonal_, 1e-300);
  std::vector<std::array<std::int64_t, 3>> key(p.size());
  for (std::size_t v = 0; v < p.size(); ++v)
    for (int a = 0; a < 3; ++a) key[v][a] = static_cast<std::int64_t>(std::llround(p[v][a] / cell));
  std::vector<std::uint32_t> order(p.size());
  for (std::uint32_t v = 0; v < order.size(); ++v) order[v] = v;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
  std::vector<std::uint32_t> position(order.size());  // index of the position's first copy
  for (std::size_t i = 0; i < order.size(); ++i)
    position[order[i]] = (i > 0 && key[order[i]] == key[order[i - 1]]) ? position[order[i - 1]] : order[i];
  std::vector<Vec3> sums(p.size(), Vec3::Zero());
  for (std::uint32_t t = 0; t < mesh_.triangleCount(); ++t) {
    const Vec3 areaNormal = (mesh_.corner(t, 1) - mesh_.corner(t, 0)).cross(mesh_.corner(t, 2) - mesh_.corner(t, 0));
    const double area2 = areaNormal.norm();
    if (!(area2 > 0.0)) continue;
    for (int k = 0; k < 3; ++k) {
      const Vec3 e1 = mesh_.corner(t, (k + 1) % 3) - mesh_.corner(t, k);
      const Vec3 e2 = mesh_.corner(t, (k + 2) % 3) - mesh_.corner(t, k);
      sums[position[mesh_.triangles[t][k]]] += std::atan2(e1.cross(e2).norm(), e1.dot(e2)) * areaNormal / area2;
    }
  }
  vertexNormals_.resize(p.size());
  for (std::size_t v = 0; v < p.size(); ++v) {
    const Vec3& sum = sums[position[v]];
    const double length = sum.norm();
    vertexNormals_[v] = length > 0.0 ? Vec3f((sum / length).cast<float>()) : Vec3f::Zero();
  }
}

// A closed mesh all of whose vertices lie behind every triangle's plane is a convex polyhedron.
// O(vertices x triangles), so only meshes of at most kMaxConvexCheckTriangles triangles are
// checked (larger ones count as not convex: the cfm model then only keeps their error bounds).
void CollisionBody::classifyConvexPolyhedron(std::span<const EdgeRef> sortedEdges) {
  std::vector<std::uint32_t> used;
  for (const auto& t : mesh_.triangles) used.insert(used.end(), t.begin(), t.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  usedVertexCount_ = used.size();
  // Closed: every edge is shared by exactly two triangles.
  closed_ = mesh_.triangleCount() > 0;
  for (std::size_t i = 0; i < sortedEdges.size() && closed_;) {
    std::size_t j = i;
    while (j < sortedEdges.size() && sortedEdges[j].v0 == sortedEdges[i].v0 && sortedEdges[j].v1 == sortedEdges[i].v1) ++j;
    closed_ = j - i == 2;
    i = j;
  }
  if (!closed_ || mesh_.triangleCount() > kMaxConvexCheckTriangles) return;
  const double tolerance = 1e-9 * diagonal_;  // rounding of the vertex coordinates
  for (std::uint32_t t = 0; t < mesh_.triangleCount(); ++t) {
    const Vec3 n = mesh_.triangleNormal(t);
    if (n.squaredNorm() == 0.0) return;
    const double offset = n.dot(mesh_.corner(t, 0));
    for (std::uint32_t v : used) {
      if (n.dot(mesh_.vertices[v]) > offset + tolerance) return;
    }
  }
  convexPolyhedron_ = true;
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
  deriveCellSupports(*contactTree_, mesh_);
}

const ClosestFeatureMap& CollisionBody::closestFeatureMap() const noexcept {
  CLOD_ASSERT(map_.has_value());
  return *map_;
}

const ContactTree& CollisionBody::contactTree() const noexcept {
  CLOD_ASSERT(contactTree_.has_value());
  return *contactTree_;
}

TrianglePoint CollisionBody::closestPointOnTriangle(const Vec3& p, std::uint32_t t) const noexcept {
  const Vec3 &a = mesh_.corner(t, 0), &b = mesh_.corner(t, 1), &c = mesh_.corner(t, 2);
  return thinTriangle_[t] ? detail::closestPointOnThinTriangle(p, a, b, c) : detail::closestPointOnRegularTriangle(p, a, b, c);
}

}  // namespace clod
