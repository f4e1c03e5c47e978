#include "containment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "clod/proximity.h"
#include "proximity/triangle_bvh.h"

namespace clod::detail {
namespace {

// Best-first search of the body's triangle BVH (CollisionBody::triangleBvh, 4 triangles per
// leaf slot) for the closest point to p. A slot's box holds its triangles, so the distance to the
// box is <= the distance to any of them: stopping at a box no nearer than the best distance found
// is exact. (The sphere-tree's leaves hold ~100 triangles each at the bakes' depth 3: the
// 200-body bin measured 600 closest-point tests per field query, and those queries were two
// thirds of its time.)
struct Closest {
  double distanceSquared = std::numeric_limits<double>::infinity();
  std::uint32_t triangle = 0;
  TrianglePoint point{};
};

// Squared distance from p to slot s's box: a lower bound for its triangles (the float boxes are
// rounded outward, so they hold them).
double slotDistanceSquared(const detail::Bvh4Node& node, int s, const Vec3& p) {
  const double dx = std::max({double(node.minX[s]) - p.x(), p.x() - double(node.maxX[s]), 0.0});
  const double dy = std::max({double(node.minY[s]) - p.y(), p.y() - double(node.maxY[s]), 0.0});
  const double dz = std::max({double(node.minZ[s]) - p.z(), p.z() - double(node.maxZ[s]), 0.0});
  return dx * dx + dy * dy + dz * dz;
}

// What the rounding of slotDistanceSquared may add (relative): a box is passed over only when it
// is farther than the limit by more than that.
constexpr double kBoxBoundSlack = 1.0 - 1e-12;

// Only triangles nearer than maxDistance are looked for (infinity: all); none found leaves the
// distance at infinity.
Closest closestOnBody(const CollisionBody& body, const Vec3& p, ContainmentScratch& s,
                      double maxDistance = std::numeric_limits<double>::infinity(), const FlushFaces* flush = nullptr) {
  const detail::TriangleBvh& bvh = body.triangleBvh();
  const std::span<const detail::Bvh4Node> nodes = bvh.nodes();
  const std::span<const std::uint32_t> order = bvh.order();
  const TriangleMesh& mesh = body.mesh();
  Closest best;
  const double reach = maxDistance * maxDistance;
  s.stack.clear();
  s.stack.push_back({0.0, 0, 0});  // the root node
  while (!s.stack.empty()) {
    const ContainmentScratch::BoxEntry e = s.stack.back();
    s.stack.pop_back();
    if (e.lowerBound * kBoxBoundSlack >= std::min(best.distanceSquared, reach)) continue;
    if (e.count > 0) {
      for (std::uint32_t i = e.child; i < e.child + e.count; ++i) {
        const std::uint32_t t = order[i];
        const TrianglePoint tp = body.closestPointOnTriangle(p, t);
        if (!(tp.distanceSquared < best.distanceSquared && tp.distanceSquared < reach)) continue;
        if (flush && std::abs(mesh.triangleNormal(t).dot(p - mesh.corner(t, 0))) <= flush->onSurface &&
            flush->isFlush(flush->context, t))
          continue;
        best = {tp.distanceSquared, t, tp};
      }
      continue;
    }
    // The nearest slot is popped first: push the slots farthest first.
    const detail::Bvh4Node& node = nodes[e.child];
    const std::size_t first = s.stack.size();
    for (int k = 0; k < 4; ++k) {
      if (node.emptySlot(k)) continue;
      const double bound = slotDistanceSquared(node, k, p);
      if (bound * kBoxBoundSlack >= std::min(best.distanceSquared, reach)) continue;
      s.stack.push_back({bound, node.child[k], node.count[k]});
    }
    std::sort(s.stack.begin() + static_cast<std::ptrdiff_t>(first), s.stack.end(),
              [](const auto& x, const auto& y) { return x.lowerBound > y.lowerBound; });
  }
  return best;
}

// Angle at corner k of triangle t.
double cornerAngle(const TriangleMesh& mesh, std::uint32_t t, int k) {
  const Vec3& o = mesh.corner(t, k);
  const Vec3 e1 = mesh.corner(t, (k + 1) % 3) - o;
  const Vec3 e2 = mesh.corner(t, (k + 2) % 3) - o;
  return std::atan2(e1.cross(e2).norm(), e1.dot(e2));
}

// Pseudonormal of the closest feature (Baerentzen & Aanaes 2005): the face normal, the sum of
// the normals of an edge's triangles, or the angle-weighted sum around a vertex. The triangles
// around the feature all contain the closest point q, so every leaf holding one of them within
// reach has |p - c| - r <= |p - q|: a sweep of those leaves finds them all.
Vec3 featurePseudonormal(const CollisionBody& body, const Vec3& p, const Closest& c, ContainmentScratch& s) {
  const TriangleMesh& mesh = body.mesh();
  if (c.point.feature == FeatureType::kFace) return mesh.triangleNormal(c.triangle);
  const Triangle& t0 = mesh.triangles[c.triangle];
  const std::uint32_t v0 = t0[c.point.localIndex];
  const std::uint32_t v1 = c.point.feature == FeatureType::kEdge ? t0[(c.point.localIndex + 1) % 3] : v0;
  const double reach = std::sqrt(c.distanceSquared) * (1.0 + 1e-9) + 1e-12 * body.diagonal();
  const detail::TriangleBvh& bvh = body.triangleBvh();
  s.triangles.clear();
  s.stack.clear();
  s.stack.push_back({0.0, 0, 0});
  while (!s.stack.empty()) {
    const ContainmentScratch::BoxEntry e = s.stack.back();
    s.stack.pop_back();
    if (e.count > 0) {
      for (std::uint32_t i = e.child; i < e.child + e.count; ++i) {
        const std::uint32_t t = bvh.order()[i];
        const Triangle& tri = mesh.triangles[t];
        const bool has0 = tri[0] == v0 || tri[1] == v0 || tri[2] == v0;
        const bool has1 = tri[0] == v1 || tri[1] == v1 || tri[2] == v1;
        if (has0 && has1) s.triangles.push_back(t);
      }
      continue;
    }
    const detail::Bvh4Node& node = bvh.nodes()[e.child];
    for (int k = 0; k < 4; ++k) {
      if (node.emptySlot(k)) continue;
      if (slotDistanceSquared(node, k, p) * kBoxBoundSlack > reach * reach) continue;
      s.stack.push_back({0.0, node.child[k], node.count[k]});
    }
  }
  std::sort(s.triangles.begin(), s.triangles.end());  // one summation order, whatever the BVH's
  Vec3 sum = Vec3::Zero();
  for (std::uint32_t t : s.triangles) {
    double weight = 1.0;
    if (c.point.feature == FeatureType::kVertex) {
      const Triangle& tri = mesh.triangles[t];
      const int k = tri[0] == v0 ? 0 : (tri[1] == v0 ? 1 : 2);
      weight = cornerAngle(mesh, t, k);
    }
    sum += weight * mesh.triangleNormal(t);
  }
  const double len = sum.norm();
  return len > 0.0 ? Vec3(sum / len) : mesh.triangleNormal(c.triangle);
}

}  // namespace

FieldValue exactBodyField(const CollisionBody& body, const Vec3& pLocal, ContainmentScratch& scratch) {
  FieldValue f;
  exactBodyFieldWithin(body, pLocal, std::numeric_limits<double>::infinity(), scratch, f);
  return f;
}

bool exactBodyFieldWithin(const CollisionBody& body, const Vec3& pLocal, double maxDistance, ContainmentScratch& scratch,
                          FieldValue& f, const FlushFaces* flush) {
  const Closest c = closestOnBody(body, pLocal, scratch, maxDistance, flush);
  if (!std::isfinite(c.distanceSquared)) return false;
  const double d = std::sqrt(c.distanceSquared);
  const Vec3 pseudo = featurePseudonormal(body, pLocal, c, scratch);
  const Vec3 away = pLocal - c.point.point;
  const bool inside = away.dot(pseudo) < 0.0;
  f.distance = inside ? -d : d;
  // The gradient of the distance field: from the closest point toward p outside, from p toward
  // the closest point inside (both: toward larger signed distance). On the surface, the feature's
  // pseudonormal.
  f.gradient = d > 1e-12 * body.diagonal() ? Vec3((inside ? -away : away) / d) : pseudo;
  f.errorBound = 0.0;
  return true;
}

namespace {

// The vertices of the inner body that stand for it: its root sphere's patch or support vertices
// (the extreme vertices of 256 directions for a curved body, all vertices of a faceted one up to
// 32), else all of its vertices.
template <typename F>
void forEachSupportVertex(const CollisionBody& body, F&& f) {
  std::span<const std::uint32_t> ids = body.spherePatchVertices(0);
  if (ids.empty()) ids = body.sphereSupportVertices(0);
  if (!ids.empty()) {
    for (std::uint32_t id : ids) f(id);
    return;
  }
  for (std::uint32_t id = 0; id < body.mesh().vertexCount(); ++id) f(id);
}

// Inner inside outer? Frames: inner's points to outer's frame by xfOuterFromInner; contacts to
// the output frame (A's) by xfOutFromInner and rotOutFromOuter; `sign` +1 when the inner body is
// A (A moves along the outer gradient), -1 when it is B (normal from B toward A).
std::uint32_t innerContacts(const CollisionBody& inner, const CollisionBody& outer, const Pose& xfOuterFromInner,
                            const Pose& xfOutFromInner, const Quat& rotOutFromOuter, double sign,
                            std::uint32_t maxContacts, bool rootSphereRule, ContainmentScratch& s,
                            std::vector<Contact>& out, bool& found) {
  found = false;
  const TriangleMesh& mesh = inner.mesh();
  if (mesh.triangles.empty()) return 0;
  const SphereTree& outerTree = outer.sphereTree();
  const SphereTree& innerTree = inner.sphereTree();
  const Vec3 centreOuter = xfOuterFromInner.apply(innerTree.center(0));
  std::uint32_t queries = 0;
  FieldValue atSeed, atCentre;
  bool centreQueried = false;
  if (rootSphereRule) {
    // The model found contacts: they stand unless the inner body's root sphere lies wholly inside
    // the outer body (then the surfaces cannot meet: the contacts came from loose sphere pairs).
    // A root sphere not inside the outer root sphere cannot be inside the body: no query.
    if ((centreOuter - outerTree.center(0)).norm() + innerTree.radius[0] >= outerTree.radius[0]) return 0;
    ++queries;
    atCentre = exactBodyField(outer, centreOuter, s);
    centreQueried = true;
    if (!(atCentre.distance < -innerTree.radius[0])) return queries;
    atSeed = atCentre;
  } else {
    const Vec3 seedOuter = xfOuterFromInner.apply(mesh.vertices[mesh.triangles[0][0]]);
    // A point outside the outer body's root sphere is outside the body: no query.
    if ((seedOuter - outerTree.center(0)).norm() >= outerTree.radius[0]) return 0;
    ++queries;
    atSeed = exactBodyField(outer, seedOuter, s);
    if (!(atSeed.distance < 0.0)) return queries;
  }
  // Only a closed body has an inside.
  if (!outer.isClosed()) return queries;

  // One normal for all contacts: the outer field's gradient at the inner body's root-sphere
  // centre (inside the outer body, as the seed is), else at the seed. Each point's own gradient
  // would push a body centred in a symmetric container in opposite directions at once.
  if (!centreQueried) {
    ++queries;
    atCentre = exactBodyField(outer, centreOuter, s);
  }
  const Vec3 gradOuter = atCentre.distance < 0.0 ? atCentre.gradient : atSeed.gradient;
  const Vec3 normalOut = (sign * (rotOutFromOuter * gradOuter)).normalized();
  // The way the inner body must move, in its own frame.
  const Vec3 exitInner = xfOuterFromInner.rotation.conjugate() * gradOuter;

  // Well-spread points: the vertex trailing along the exit direction (the deepest, the last to
  // leave), then the extremes across it.
  Vec3 t1 = exitInner.unitOrthogonal();
  Vec3 t2 = exitInner.cross(t1);
  const std::array<Vec3, 9> dirs{-exitInner, t1, -t1, t2, -t2, t1 + t2, -t1 - t2, t1 - t2, t2 - t1};
  const std::uint32_t wanted = std::min<std::uint32_t>(std::max<std::uint32_t>(maxContacts, 1u), 8u);
  std::array<std::uint32_t, 9> chosen{};
  std::uint32_t count = 0;
  for (const Vec3& dir : dirs) {
    if (count == wanted) break;
    // Slightly toward the trail, so ties across the exit direction take the deeper vertex.
    const Vec3 d = dir - 1e-3 * exitInner;
    double bestDot = -std::numeric_limits<double>::infinity();
    std::uint32_t best = UINT32_MAX;
    forEachSupportVertex(inner, [&](std::uint32_t id) {
      const double v = d.dot(mesh.vertices[id]);
      if (v > bestDot) {
        bestDot = v;
        best = id;
      }
    });
    if (best == UINT32_MAX || std::find(chosen.begin(), chosen.begin() + count, best) != chosen.begin() + count) continue;
    chosen[count++] = best;
  }
  for (std::uint32_t i = 0; i < count; ++i) {
    const Vec3& v = mesh.vertices[chosen[i]];
    ++queries;
    const FieldValue fv = exactBodyField(outer, xfOuterFromInner.apply(v), s);
    Contact c;
    c.point = xfOutFromInner.apply(v);
    c.normal = normalOut;
    c.depth = -fv.distance;  // the distance the point is inside the outer surface
    c.errorBound = fv.errorBound;
    c.level = 0;
    out.push_back(c);
  }
  found = count > 0;
  return queries;
}

}  // namespace

std::uint32_t containmentContacts(const CollisionBody& a, const CollisionBody& b, const Pose& xfAFromB,
                                  std::uint32_t maxContacts, bool haveContacts, ContainmentScratch& scratch,
                                  std::vector<Contact>& out, bool& found) {
  found = false;
  const SphereTree& ta = a.sphereTree();
  const SphereTree& tb = b.sphereTree();
  if (ta.sphereCount() == 0 || tb.sphereCount() == 0) return 0;
  const double gap = (ta.center(0) - xfAFromB.apply(tb.center(0))).norm() - ta.radius[0] - tb.radius[0];
  if (gap >= 0.0) return 0;  // the root spheres are apart: so are the bodies
  const Pose xfBFromA = xfAFromB.inverse();
  // A inside B: points of A, B's field; A moves along B's gradient (normal B -> A = +gradient).
  std::uint32_t queries = innerContacts(a, b, xfBFromA, Pose{}, xfAFromB.rotation, 1.0, maxContacts, haveContacts,
                                        scratch, out, found);
  if (found) return queries;
  // B inside A: B moves along A's gradient, i.e. normal (B -> A) = -gradient.
  queries += innerContacts(b, a, xfAFromB, xfAFromB, Quat::Identity(), -1.0, maxContacts, haveContacts, scratch, out,
                           found);
  return queries;
}

}  // namespace clod::detail
