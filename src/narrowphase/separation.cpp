// The exact closest distance between two placed meshes (separation.h).
#include "separation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "clod/proximity.h"
#include "narrowphase/containment.h"
#include "proximity/triangle_bvh.h"

namespace clod::detail {
namespace {

// Closest points of segments p1q1 and p2q2: parameters s, t in [0, 1] minimising
// |p1 + s d1 - (p2 + t d2)| (the standard clamped solution, e.g. Ericson, Real-Time Collision
// Detection, 5.1.9). Parallel and degenerate segments take s = 0 first and clamp from there,
// which still reaches the minimum distance.
void closestSegmentPoints(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Vec3& c1, Vec3& c2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a == 0.0 && e == 0.0) {
    // two points
  } else if (a == 0.0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e == 0.0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;  // >= 0; 0 for parallel segments
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

// Where segment pq crosses triangle abc (not in its plane), if it does: the segment's end points
// lie on opposite sides of the plane (or one on it) and the crossing point is inside the triangle
// (on its border counts). A degenerate triangle is never crossed (its edges are tested instead).
bool segmentCrossesTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& hit) {
  const Vec3 n = (b - a).cross(c - a);
  if (n.squaredNorm() == 0.0) return false;
  const double dp = n.dot(p - a), dq = n.dot(q - a);
  if ((dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq) return false;  // one side, or in the plane
  hit = p + (dp / (dp - dq)) * (q - p);
  return n.dot((b - a).cross(hit - a)) >= 0.0 && n.dot((c - b).cross(hit - b)) >= 0.0 &&
         n.dot((a - c).cross(hit - c)) >= 0.0;
}

constexpr std::uint32_t kRoot = 0xffffffffu;  // slot reference of a whole hierarchy

// A slot reference is node * 4 + slot of a TriangleBvh node, or kRoot.

Aabb refBox(const TriangleBvh& t, std::uint32_t ref) {
  if (ref != kRoot) return t.nodes()[ref >> 2].slotBox(int(ref & 3));
  Aabb box;
  for (int s = 0; s < 4; ++s)
    if (!t.nodes()[0].emptySlot(s)) box.extend(t.nodes()[0].slotBox(s));
  return box;
}

bool isLeafRef(const TriangleBvh& t, std::uint32_t ref) { return ref != kRoot && t.nodes()[ref >> 2].count[ref & 3] > 0; }

// Distance between box a (A's frame) and box b (B's frame) placed in A's frame by xf, a lower
// bound of the distance between anything inside them: b is enclosed in the axis-aligned box of
// its turned self.
// The bounding spheres of the two boxes give a second lower bound, tighter where b is turned
// (its axis-aligned box then grows by up to sqrt(3)); the larger of the two is used.
double boxLowerBound(const Aabb& a, const Aabb& b, const Pose& xfAFromB, const Mat3& absRotation) {
  const Vec3 cb = xfAFromB.apply(b.center());
  const Vec3 hb = absRotation * (0.5 * b.extent());
  const Vec3 gap = ((a.center() - cb).cwiseAbs() - 0.5 * a.extent() - hb).cwiseMax(0.0);
  const double spheres = (a.center() - cb).norm() - 0.5 * (a.diagonal() + b.diagonal());
  return std::max(gap.norm(), spheres);
}

// A lower bound of the distance between two triangles: their bounding spheres (centroid, farthest
// corner), which rejects most pairs of a leaf pair before the full triangle distance.
double triangleLowerBound(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1, const Vec3& b2) {
  const Vec3 ca = (a0 + a1 + a2) / 3.0, cb = (b0 + b1 + b2) / 3.0;
  const double ra = std::sqrt(std::max({(a0 - ca).squaredNorm(), (a1 - ca).squaredNorm(), (a2 - ca).squaredNorm()}));
  const double rb = std::sqrt(std::max({(b0 - cb).squaredNorm(), (b1 - cb).squaredNorm(), (b2 - cb).squaredNorm()}));
  return (ca - cb).norm() - ra - rb;
}

}  // namespace

TriangleDistance triangleDistance(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                                  const Vec3& b2) noexcept {
  const Vec3 a[3] = {a0, a1, a2}, b[3] = {b0, b1, b2};
  TriangleDistance best;
  // Crossing: two triangles that share a point but not a plane have an edge of one crossing the
  // other (the ends of their intersection segment lie on edges); coplanar ones that overlap have
  // crossing edges or a vertex inside the other, which the distances below find at 0.
  Vec3 hit;
  for (int i = 0; i < 3; ++i) {
    if (segmentCrossesTriangle(a[i], a[(i + 1) % 3], b0, b1, b2, hit) ||
        segmentCrossesTriangle(b[i], b[(i + 1) % 3], a0, a1, a2, hit)) {
      best.pointA = best.pointB = hit;
      return best;
    }
  }
  best.distanceSquared = std::numeric_limits<double>::infinity();
  auto consider = [&best](const Vec3& pa, const Vec3& pb) {
    const double d2 = (pa - pb).squaredNorm();
    if (d2 < best.distanceSquared) best = {d2, pa, pb};
  };
  for (int i = 0; i < 3; ++i) {
    consider(a[i], closestPointOnTriangle(a[i], b0, b1, b2).point);
    consider(closestPointOnTriangle(b[i], a0, a1, a2).point, b[i]);
  }
  Vec3 ca, cb;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      closestSegmentPoints(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3], ca, cb);
      consider(ca, cb);
    }
  return best;
}

Separation separationBetween(const CollisionBody& shapeA, const Pose& poseA, const CollisionBody& shapeB,
                             const Pose& poseB, double maxDistance, SeparationHeap& heap) {
  const TriangleBvh& ta = shapeA.triangleBvh();
  const TriangleBvh& tb = shapeB.triangleBvh();
  const TriangleMesh& ma = shapeA.mesh();
  const TriangleMesh& mb = shapeB.mesh();
  // Everything in A's frame: B's triangles are moved there as they are met.
  const Pose xf = poseA.inverse() * poseB;
  const Mat3 absRotation = xf.rotation.toRotationMatrix().cwiseAbs();

  double best2 = std::numeric_limits<double>::infinity();  // squared distance of the best pair
  double dropped = std::numeric_limits<double>::infinity(); // smallest bound left unexplored > maxDistance
  TriangleDistance bestPair;
  std::uint32_t bestA = 0, bestB = 0;
  heap.clear();
  auto greater = [](const SeparationItem& l, const SeparationItem& r) { return l.lowerBound > r.lowerBound; };
  auto push = [&](std::uint32_t ra, std::uint32_t rb) {
    const double bound = boxLowerBound(refBox(ta, ra), refBox(tb, rb), xf, absRotation);
    if (bound > maxDistance) {
      dropped = std::min(dropped, bound);
    } else if (bound * bound < best2) {
      heap.push_back({bound, ra, rb});
      std::push_heap(heap.begin(), heap.end(), greater);
    }
  };
  auto children = [](const TriangleBvh& t, std::uint32_t ref, auto&& each) {
    const std::uint32_t node = ref == kRoot ? 0 : t.nodes()[ref >> 2].child[ref & 3];
    for (int s = 0; s < 4; ++s)
      if (!t.nodes()[node].emptySlot(s)) each(node * 4 + std::uint32_t(s));
  };
  const double rootBound = boxLowerBound(refBox(ta, kRoot), refBox(tb, kRoot), xf, absRotation);
  push(kRoot, kRoot);
  while (!heap.empty() && best2 > 0.0) {
    std::pop_heap(heap.begin(), heap.end(), greater);
    const SeparationItem item = heap.back();
    heap.pop_back();
    if (item.lowerBound * item.lowerBound >= best2) break;  // the heap holds nothing nearer
    const bool leafA = isLeafRef(ta, item.a), leafB = isLeafRef(tb, item.b);
    if (leafA && leafB) {
      const Bvh4Node& na = ta.nodes()[item.a >> 2];
      const Bvh4Node& nb = tb.nodes()[item.b >> 2];
      for (std::uint32_t i = na.child[item.a & 3]; i < na.child[item.a & 3] + na.count[item.a & 3]; ++i) {
        const std::uint32_t triA = ta.order()[i];
        const auto& fa = ma.triangles[triA];
        for (std::uint32_t j = nb.child[item.b & 3]; j < nb.child[item.b & 3] + nb.count[item.b & 3]; ++j) {
          const std::uint32_t triB = tb.order()[j];
          const auto& fb = mb.triangles[triB];
          const Vec3 b0 = xf.apply(mb.vertices[fb[0]]), b1 = xf.apply(mb.vertices[fb[1]]), b2 = xf.apply(mb.vertices[fb[2]]);
          const double bound = triangleLowerBound(ma.vertices[fa[0]], ma.vertices[fa[1]], ma.vertices[fa[2]], b0, b1, b2);
          if (bound > 0.0 && bound * bound >= best2) continue;
          const TriangleDistance d = triangleDistance(ma.vertices[fa[0]], ma.vertices[fa[1]], ma.vertices[fa[2]], b0, b1, b2);
          if (d.distanceSquared < best2) {
            best2 = d.distanceSquared;
            bestPair = d;
            bestA = triA;
            bestB = triB;
          }
        }
      }
      continue;
    }
    // Split the side that is not a leaf; of two inner ones, the larger box.
    const bool splitA = leafB || (!leafA && refBox(ta, item.a).diagonal() >= refBox(tb, item.b).diagonal());
    if (splitA)
      children(ta, item.a, [&](std::uint32_t child) { push(child, item.b); });
    else
      children(tb, item.b, [&](std::uint32_t child) { push(item.a, child); });
  }

  Separation out;
  const double bestDistance = std::sqrt(best2);
  out.withinMax = bestDistance <= maxDistance;
  out.distance = out.withinMax ? bestDistance : std::min(bestDistance, dropped);
  if (out.withinMax) {
    out.pointA = poseA.apply(bestPair.pointA);
    out.pointB = poseA.apply(bestPair.pointB);
    out.triangleA = bestA;
    out.triangleB = bestB;
  }
  out.overlapping = out.withinMax && best2 == 0.0;
  if (!out.overlapping && rootBound == 0.0) {
    // Surfaces apart but boxes overlapping: one closed body may hold the other. Then all of the
    // inner body is inside (its surface does not meet the outer one), so one vertex tells.
    ContainmentScratch scratch;
    auto inside = [&scratch](const CollisionBody& outer, const TriangleMesh& inner, const Pose& xfOuterFromInner) {
      if (!outer.isClosed()) return false;
      const Vec3 p = xfOuterFromInner.apply(inner.vertices[inner.triangles[0][0]]);
      return exactBodyField(outer, p, scratch).distance < 0.0;
    };
    out.overlapping = inside(shapeB, ma, xf.inverse()) || inside(shapeA, mb, xf);
  }
  return out;
}

}  // namespace clod::detail
