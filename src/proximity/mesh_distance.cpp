#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include <tbb/parallel_for.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

#include "clod/error.h"
#include "clod/proximity.h"
#include "pseudonormals.h"
#include "triangle_closest_point.h"
#include "triangle_bvh.h"
#include "winding_number.h"

namespace clod {
namespace {

using detail::Bvh4Node;

// A point whose winding number is this close to 1/2 is "on" an open surface; the sign there
// is a coin toss either way, so >= is as good as any.
constexpr double kInsideWinding = 0.5;

struct PackedTriangle {
  Vec3 a, b, c;
  bool thin;  // needle or flat: see detail::isThinTriangle
};

void validate(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) throw Error(ErrorCode::kNoTriangles, "mesh has no triangles");
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    if (!mesh.vertices[v].allFinite()) {
      throw Error(ErrorCode::kNonFiniteVertex, "vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  bool anyArea = false;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.triangles[t][k] >= mesh.vertexCount()) {
        throw Error(ErrorCode::kIndexOutOfRange, "triangle " + std::to_string(t) + ": vertex index " +
                                                     std::to_string(mesh.triangles[t][k]) + " >= vertex count " +
                                                     std::to_string(mesh.vertexCount()));
      }
    }
    if (!anyArea && mesh.triangleArea(t) > 0.0) anyArea = true;
  }
  if (!anyArea) throw Error(ErrorCode::kAllTrianglesDegenerate, "every triangle of the mesh has zero area");
}

// Every edge's two triangles traverse it in opposite directions; with `borders`, an edge of one
// triangle (an open mesh's border) passes too.
bool consistentlyOriented(const TriangleMesh& mesh, const MeshTopology& topology, bool borders = false) {
  for (std::uint32_t e = 0; e < topology.edgeCount(); ++e) {
    if (borders && topology.edgeTriangles(e).size() == 1) continue;
    int forward = 0, backward = 0;
    for (std::uint32_t t : topology.edgeTriangles(e)) {
      for (int k = 0; k < 3; ++k) {
        if (topology.triangleEdge(t, k) != e) continue;
        (mesh.triangles[t][k] == topology.edges()[e].v0 ? forward : backward)++;
      }
    }
    if (forward != backward) return false;
  }
  return true;
}

// True when the triangles around every vertex form one fan. Two cones touching at a vertex
// (a "pinched" vertex) have closed edges but break the pseudonormal sign test there.
bool verticesManifold(const TriangleMesh& mesh, const MeshTopology& topology) {
  // Union-find over triangle corners: corners of one vertex are joined across each edge.
  std::vector<std::uint32_t> parent(std::size_t(mesh.triangleCount()) * 3);
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<std::uint32_t>(i);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto cornerOf = [&](std::uint32_t t, std::uint32_t v) {
    for (std::uint32_t k = 0; k < 3; ++k) {
      if (mesh.triangles[t][k] == v) return t * 3 + k;
    }
    return t * 3;
  };
  for (std::uint32_t e = 0; e < topology.edgeCount(); ++e) {
    const auto triangles = topology.edgeTriangles(e);
    for (std::size_t i = 1; i < triangles.size(); ++i) {
      for (std::uint32_t v : {topology.edges()[e].v0, topology.edges()[e].v1}) {
        parent[find(cornerOf(triangles[0], v))] = find(cornerOf(triangles[i], v));
      }
    }
  }
  std::vector<std::uint32_t> root(mesh.vertexCount(), 0xffffffffu);
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh.triangles[t][k];
      const std::uint32_t r = find(t * 3 + k);
      if (root[v] == 0xffffffffu) root[v] = r;
      if (root[v] != r) return false;
    }
  }
  return true;
}

}  // namespace

struct MeshDistance::Impl {
  TriangleMesh mesh;
  std::optional<MeshTopology> topology;
  detail::Pseudonormals normals;
  detail::TriangleBvh bvh;
  std::vector<PackedTriangle> packed;    // triangles in BVH order
  std::vector<std::uint32_t> triangleOf; // BVH position -> mesh triangle
  std::vector<detail::WindingFarField> farFields;  // per node slot: node * 4 + slot
  SignMethod signMethod = SignMethod::kWindingNumber;
  // A sheet signed by its pseudonormals (sheetPseudonormals): its border vertices, where points
  // beyond the border are outside (beyondSheetBorder). Empty otherwise.
  std::vector<std::uint8_t> borderVertex;

  struct Nearest {
    TrianglePoint point;
    std::uint32_t position;  // BVH position of the triangle
  };
  Nearest nearest(const Vec3& p) const;
  double windingSolidAngle(const Vec3& p) const;
  ClosestPoint toClosestPoint(const Vec3& p, const TrianglePoint& tp, std::uint32_t triangle) const;
  void buildFarFields(double beta);
  bool beyondSheetBorder(const Vec3& p, const ClosestPoint& closest) const;
};

namespace {

float floatBelow(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float floatAbove(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

}  // namespace

// Best-first descent with a fixed-size stack: children are pushed farthest first so the nearest
// is expanded next, and anything whose box is farther than the best triangle so far is dropped.
//
// Exactness with float boxes: the boxes contain the triangles (rounded outward) and p is
// bracketed by [pLo, pHi] in float, so each per-axis gap computed from them is at most the
// true gap up to one rounding. The float squared distance then carries at most a few
// roundings (relative 2^-24 each, or 2^-149 absolute in the subnormal range); it is shrunk by
// a margin covering them and compared with the best squared distance rounded up to float. So a
// box is dropped only if it truly cannot hold a closer point: the answer equals brute force.
// (Float overflow gives +inf on both sides of the comparison, which keeps the box: safe.)
MeshDistance::Impl::Nearest MeshDistance::Impl::nearest(const Vec3& p) const {
  struct Entry {
    float lowerBound;
    std::uint32_t child;
    std::uint32_t count;
  };
  constexpr float kShrink = 1.0f - 1.0f / (1 << 20);
  constexpr float kSubnormalSlack = 1e-44f;
  Entry stack[3 * detail::TriangleBvh::kMaxDepth + 4];
  int top = 0;
  const Bvh4Node* nodes = bvh.nodes().data();

  const float pLoS[3] = {floatBelow(p.x()), floatBelow(p.y()), floatBelow(p.z())};
  const float pHiS[3] = {floatAbove(p.x()), floatAbove(p.y()), floatAbove(p.z())};
#if defined(__SSE2__)
  const __m128 pLoX = _mm_set1_ps(pLoS[0]), pLoY = _mm_set1_ps(pLoS[1]), pLoZ = _mm_set1_ps(pLoS[2]);
  const __m128 pHiX = _mm_set1_ps(pHiS[0]), pHiY = _mm_set1_ps(pHiS[1]), pHiZ = _mm_set1_ps(pHiS[2]);
  const __m128 zero = _mm_setzero_ps(), shrink = _mm_set1_ps(kShrink), slack = _mm_set1_ps(kSubnormalSlack);
#endif

  Nearest best{{p, std::numeric_limits<double>::infinity(), FeatureType::kFace, 0}, 0xffffffffu};
  float bestBound = std::numeric_limits<float>::infinity();  // best squared distance, rounded up
  stack[top++] = {0.0f, 0, 0};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.lowerBound > bestBound) continue;
    if (entry.count > 0) {
      for (std::uint32_t i = entry.child; i < entry.child + entry.count; ++i) {
        const PackedTriangle& tri = packed[i];
        // (A per-triangle float box cull here measured 10-20% slower: the exact test is cheap.)
        const TrianglePoint tp = tri.thin ? detail::closestPointOnThinTriangle(p, tri.a, tri.b, tri.c)
                                          : detail::closestPointOnRegularTriangle(p, tri.a, tri.b, tri.c);
        if (tp.distanceSquared < best.point.distanceSquared || best.position == 0xffffffffu) {
          best = {tp, i};
          bestBound = floatAbove(tp.distanceSquared);
        }
      }
      continue;
    }
    const Bvh4Node& node = nodes[entry.child];
    alignas(16) float bound[4];
#if defined(__SSE2__)
    const __m128 dx = _mm_max_ps(_mm_max_ps(_mm_sub_ps(_mm_load_ps(node.minX), pHiX), _mm_sub_ps(pLoX, _mm_load_ps(node.maxX))), zero);
    const __m128 dy = _mm_max_ps(_mm_max_ps(_mm_sub_ps(_mm_load_ps(node.minY), pHiY), _mm_sub_ps(pLoY, _mm_load_ps(node.maxY))), zero);
    const __m128 dz = _mm_max_ps(_mm_max_ps(_mm_sub_ps(_mm_load_ps(node.minZ), pHiZ), _mm_sub_ps(pLoZ, _mm_load_ps(node.maxZ))), zero);
    const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    _mm_store_ps(bound, _mm_sub_ps(_mm_mul_ps(d2, shrink), slack));
#else
    for (int s = 0; s < 4; ++s) {
      const float dx = std::max(std::max(node.minX[s] - pHiS[0], pLoS[0] - node.maxX[s]), 0.0f);
      const float dy = std::max(std::max(node.minY[s] - pHiS[1], pLoS[1] - node.maxY[s]), 0.0f);
      const float dz = std::max(std::max(node.minZ[s] - pHiS[2], pLoS[2] - node.maxZ[s]), 0.0f);
      bound[s] = (dx * dx + dy * dy + dz * dz) * kShrink - kSubnormalSlack;
    }
#endif
    // Insertion-sort the surviving slots by bound, largest first, then push in that order.
    Entry children[4];
    int n = 0;
    for (int s = 0; s < 4; ++s) {
      if (node.child[s] == Bvh4Node::kEmpty || bound[s] > bestBound) continue;
      const Entry e{bound[s], node.child[s], node.count[s]};
      int j = n++;
      while (j > 0 && children[j - 1].lowerBound < e.lowerBound) {
        children[j] = children[j - 1];
        --j;
      }
      children[j] = e;
    }
    for (int i = 0; i < n; ++i) {
      stack[top++] = children[i];
#if defined(__SSE2__) && !defined(NO_PREFETCH)
      // Queries are bound by memory latency (profiled: the first touch of a node or a
      // triangle dominates), so start fetching every child that survived the cull now.
      const char* address = children[i].count > 0 ? reinterpret_cast<const char*>(&packed[children[i].child])
                                                  : reinterpret_cast<const char*>(&nodes[children[i].child]);
      const std::size_t bytes = children[i].count > 0 ? children[i].count * sizeof(PackedTriangle) : sizeof(Bvh4Node);
      for (std::size_t offset = 0; offset < bytes; offset += 64) _mm_prefetch(address + offset, _MM_HINT_T0);
#endif
    }
  }
  return best;
}

double MeshDistance::Impl::windingSolidAngle(const Vec3& p) const {
  std::uint32_t stack[3 * detail::TriangleBvh::kMaxDepth + 4];
  int top = 0;
  stack[top++] = 0;
  double sum = 0.0;
  const Bvh4Node* nodes = bvh.nodes().data();
  while (top > 0) {
    const std::uint32_t index = stack[--top];
    const Bvh4Node& node = nodes[index];
    for (int s = 0; s < 4; ++s) {
      if (node.child[s] == Bvh4Node::kEmpty) continue;
      const detail::WindingFarField& far = farFields[std::size_t(index) * 4 + s];
      if ((p - far.center).squaredNorm() > far.farRadiusSquared) {
        sum += far.solidAngle(p);
      } else if (node.count[s] > 0) {
        for (std::uint32_t i = node.child[s]; i < node.child[s] + node.count[s]; ++i) {
          sum += detail::triangleSolidAngle(p, packed[i].a, packed[i].b, packed[i].c);
        }
      } else {
        stack[top++] = node.child[s];
      }
    }
  }
  return sum;
}

void MeshDistance::Impl::buildFarFields(double beta) {
  const auto nodes = bvh.nodes();
  std::vector<detail::WindingRawMoments> raw(nodes.size() * 4);
  farFields.resize(nodes.size() * 4);
  // Children come after their parents, so a reverse sweep sees every child node first.
  for (std::size_t index = nodes.size(); index-- > 0;) {
    const Bvh4Node& node = nodes[index];
    for (int s = 0; s < 4; ++s) {
      if (node.child[s] == Bvh4Node::kEmpty) continue;
      detail::WindingRawMoments& m = raw[index * 4 + s];
      if (node.count[s] > 0) {
        for (std::uint32_t i = node.child[s]; i < node.child[s] + node.count[s]; ++i) {
          m.addTriangle(packed[i].a, packed[i].b, packed[i].c);
        }
      } else {
        for (int c = 0; c < 4; ++c) {
          if (nodes[node.child[s]].child[c] != Bvh4Node::kEmpty) m.add(raw[std::size_t(node.child[s]) * 4 + c]);
        }
      }
      farFields[index * 4 + s] = detail::WindingFarField::fromMoments(
          m, Vec3(node.minX[s], node.minY[s], node.minZ[s]), Vec3(node.maxX[s], node.maxY[s], node.maxZ[s]),
          beta);
    }
  }
}

ClosestPoint MeshDistance::Impl::toClosestPoint(const Vec3& p, const TrianglePoint& tp, std::uint32_t t) const {
  ClosestPoint out;
  out.point = tp.point;
  out.distance = std::sqrt(tp.distanceSquared);
  out.triangle = t;
  switch (tp.feature) {
    case FeatureType::kFace:
      out.feature = {FeatureType::kFace, t};
      out.normal = normals.face[t];
      break;
    case FeatureType::kEdge: {
      const std::uint32_t e = topology->triangleEdge(t, tp.localIndex);
      out.feature = {FeatureType::kEdge, e};
      out.normal = normals.edge[e];
      break;
    }
    case FeatureType::kVertex: {
      const std::uint32_t v = mesh.triangles[t][tp.localIndex];
      out.feature = {FeatureType::kVertex, v};
      out.normal = normals.vertex[v];
      break;
    }
  }
  (void)p;
  return out;
}

MeshDistance::MeshDistance(TriangleMesh mesh, const MeshDistanceSettings& settings) : impl_(std::make_unique<Impl>()) {
  if (settings.leafSize == 0 || settings.leafSize > 64) {
    throw Error(ErrorCode::kInvalidArgument,
                "MeshDistanceSettings::leafSize " + std::to_string(settings.leafSize) + " is outside 1..64");
  }
  if (!(settings.windingBeta >= 1.0) || !std::isfinite(settings.windingBeta)) {
    throw Error(ErrorCode::kInvalidArgument,
                "MeshDistanceSettings::windingBeta " + std::to_string(settings.windingBeta) + " must be finite and >= 1");
  }
  validate(mesh);
  Impl& impl = *impl_;
  impl.mesh = std::move(mesh);
  const TriangleMesh& m = impl.mesh;
  impl.topology.emplace(m);
  impl.normals = detail::computePseudonormals(m, *impl.topology);

  std::vector<Aabb> boxes(m.triangleCount());
  tbb::parallel_for(std::uint32_t(0), m.triangleCount(), [&](std::uint32_t t) {
    for (int k = 0; k < 3; ++k) boxes[t].extend(m.corner(t, k));
  });
  impl.bvh = detail::TriangleBvh(boxes, {settings.leafSize});
  const auto order = impl.bvh.order();
  impl.triangleOf.assign(order.begin(), order.end());
  impl.packed.resize(order.size());
  tbb::parallel_for(std::size_t(0), order.size(), [&](std::size_t i) {
    const Vec3 &a = m.corner(order[i], 0), &b = m.corner(order[i], 1), &c = m.corner(order[i], 2);
    impl.packed[i] = {a, b, c, detail::isThinTriangle(a, b, c)};
  });
  impl.buildFarFields(settings.windingBeta);

  const bool pseudonormalsValid =
      (impl.topology->closed() || settings.sheetPseudonormals) &&
      consistentlyOriented(m, *impl.topology, settings.sheetPseudonormals) && verticesManifold(m, *impl.topology);
  impl.signMethod = pseudonormalsValid && !settings.forceWindingNumber ? SignMethod::kPseudonormal
                                                                       : SignMethod::kWindingNumber;
  if (impl.signMethod == SignMethod::kPseudonormal && !impl.topology->closed()) {
    impl.borderVertex.assign(m.vertices.size(), 0);
    for (std::uint32_t e = 0; e < impl.topology->edgeCount(); ++e) {
      if (impl.topology->edgeTriangles(e).size() != 1) continue;
      impl.borderVertex[impl.topology->edges()[e].v0] = 1;
      impl.borderVertex[impl.topology->edges()[e].v1] = 1;
    }
  }
}

// For a sheet: p's closest point is on the border and p lies beyond it (off the line along the
// feature's normal through it), not behind the sheet. The solid a user means by a floor or a
// terrain is what lies behind its faces -- below its footprint. Signed by the side of the plane
// alone, the points just under the plane beyond a floor quad's edge read inside, as deep as they
// were far from the edge: a box standing over the edge was pushed back 10 % of its size, and one
// falling past the edge would be caught there (docs/contact-tree.md, "Sheets").
bool MeshDistance::Impl::beyondSheetBorder(const Vec3& p, const ClosestPoint& closest) const {
  if (borderVertex.empty()) return false;
  bool border = false;
  switch (closest.feature.type) {
    case FeatureType::kFace: return false;
    case FeatureType::kEdge: border = topology->edgeTriangles(closest.feature.index).size() == 1; break;
    case FeatureType::kVertex: border = borderVertex[closest.feature.index] != 0; break;
  }
  if (!border) return false;
  const Vec3 off = p - closest.point;
  const Vec3 across = off - off.dot(closest.normal) * closest.normal;
  // 1e-6 of the distance: a point straight behind the border (on the solid's wall) stays inside.
  return across.squaredNorm() > 1e-12 * off.squaredNorm();
}

MeshDistance::~MeshDistance() = default;
MeshDistance::MeshDistance(MeshDistance&&) noexcept = default;
MeshDistance& MeshDistance::operator=(MeshDistance&&) noexcept = default;

ClosestPoint MeshDistance::closestPoint(const Vec3& p) const {
  CLOD_ASSERT(p.allFinite());
  const Impl::Nearest best = impl_->nearest(p);
  return impl_->toClosestPoint(p, best.point, impl_->triangleOf[best.position]);
}

double MeshDistance::windingNumber(const Vec3& p) const {
  CLOD_ASSERT(p.allFinite());
  return impl_->windingSolidAngle(p) / (4.0 * std::numbers::pi);
}

MeshDistance::Signed MeshDistance::signedQuery(const Vec3& p) const {
  Signed out{closestPoint(p), 0.0};
  const double d = out.closest.distance;
  if (d == 0.0) return out;
  bool inside;
  const double side = (p - out.closest.point).dot(out.closest.normal);
  if (impl_->signMethod == SignMethod::kPseudonormal && side != 0.0) {
    inside = side < 0.0 && !impl_->beyondSheetBorder(p, out.closest);
  } else {
    // Winding numbers for open meshes, and as the fallback where a degenerate feature has no
    // pseudonormal (zero normal) to decide with.
    inside = windingNumber(p) >= kInsideWinding;
  }
  out.signedDistance = inside ? -d : d;
  return out;
}

double MeshDistance::signedDistance(const Vec3& p) const { return signedQuery(p).signedDistance; }

ClosestPoint MeshDistance::closestPointAmong(const Vec3& p, std::span<const std::uint32_t> triangles) const {
  CLOD_ASSERT(!triangles.empty());
  const TriangleMesh& m = impl_->mesh;
  TrianglePoint best{};
  std::uint32_t bestTriangle = 0;
  bool first = true;
  for (std::uint32_t t : triangles) {
    CLOD_ASSERT(t < m.triangleCount());
    const TrianglePoint tp = closestPointOnTriangle(p, m.corner(t, 0), m.corner(t, 1), m.corner(t, 2));
    if (first || tp.distanceSquared < best.distanceSquared) {
      best = tp;
      bestTriangle = t;
      first = false;
    }
  }
  return impl_->toClosestPoint(p, best, bestTriangle);
}

Vec3 MeshDistance::featureNormal(MeshFeature feature) const {
  const detail::Pseudonormals& n = impl_->normals;
  switch (feature.type) {
    case FeatureType::kFace: CLOD_ASSERT(feature.index < n.face.size()); return n.face[feature.index];
    case FeatureType::kEdge: CLOD_ASSERT(feature.index < n.edge.size()); return n.edge[feature.index];
    case FeatureType::kVertex: CLOD_ASSERT(feature.index < n.vertex.size()); return n.vertex[feature.index];
  }
  return Vec3::Zero();
}

SignMethod MeshDistance::signMethod() const { return impl_->signMethod; }
const TriangleMesh& MeshDistance::mesh() const { return impl_->mesh; }
const MeshTopology& MeshDistance::topology() const { return *impl_->topology; }

}  // namespace clod
