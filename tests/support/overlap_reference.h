#pragma once
// An independent reference for the contact between two overlapping meshes, so that no contact
// model is judged against clod's own exact model alone: used by the narrow-phase accuracy harness
// (bench_narrowphase --accuracy --reference=volume) and tests/narrowphase/volume_reference_test.cpp.
//
// The reference normal is the gradient of the intersection volume V(t) = vol(A ∩ (B + t)) with
// respect to translating B:
//
//   dV/dt = ∫_{∂B inside A} n_B dS = -∫_{∂A inside B} n_A dS
//
// Moving B's surface outward along n_B sweeps new volume only where that surface lies inside A;
// the second form follows from the divergence theorem on A ∩ B (its boundary is the two pieces,
// and ∮ n dS = 0). Moving A along +dV/dt separates the bodies fastest, so it is the contact normal
// pointing from B to A. We take the mean of the two forms: for closed meshes they agree, and for
// an open mesh (the bunny's base) the mean is the symmetric choice. The reference point is the
// area centroid of both surface pieces; the reference depth is the deepest sampled point of either
// surface inside the other.
//
// Nothing here shares code with clod's narrow phase: inside/outside and distances come from
// MeshDistance (exact closest points, sign by pseudonormals or generalized winding numbers; tested
// against brute force in tests/proximity), and the surface integral is a midpoint rule over a
// recursive 4-way subdivision of each triangle, not triangle-triangle clipping. A (sub)triangle
// whose bounding sphere lies entirely on one side of the other surface (|signed distance at its
// centroid| > its radius) is taken whole; the rest are split, and a leaf counts as inside when its
// centroid is, once its bounding radius is at most `leafRadius` (world units): the size of the
// smallest feature of the overlap the reference resolves, so pick it well below the penetration.
// Caveat: for an open mesh the winding number can cross 1/2 away from the surface (across a
// hole), where the sphere test may take a triangle whole on the wrong side; the bunny's holes are
// in its base, away from most contacts.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "clod/math.h"
#include "clod/mesh.h"
#include "clod/proximity.h"

namespace clod::test {

struct OverlapReference {
  Vec3 gradientB = Vec3::Zero();  ///< ∫ n_B dS over B's surface inside A (world frame)
  Vec3 gradientA = Vec3::Zero();  ///< ∫ n_A dS over A's surface inside B (world frame)
  double area = 0.0;              ///< area of both pieces together
  Vec3 centroid = Vec3::Zero();   ///< area centroid of both pieces
  double depth = 0.0;             ///< deepest sampled point of either surface inside the other
  std::uint64_t distanceQueries = 0;

  /// Contact normal pointing from B to A; zero when nothing overlaps.
  Vec3 normal() const {
    const Vec3 g = gradientB - gradientA;
    return g.norm() > 0 ? Vec3(g.normalized()) : Vec3::Zero();
  }
  /// Angle (degrees) between the two forms of the gradient: 0 for closed meshes up to the
  /// quadrature error, so it measures the reference's own accuracy.
  double selfConsistencyDegrees() const {
    const double na = gradientA.norm(), nb = gradientB.norm();
    if (na == 0 || nb == 0) return 180.0;
    return std::acos(std::clamp(-gradientA.dot(gradientB) / (na * nb), -1.0, 1.0)) * 57.29577951308232;
  }
};

namespace detail {

// Integrates one side: the surface of `surface` placed by `surfacePose`, inside `other` placed by
// `otherPose`. Adds to `gradient`, `areaSum`, `centroidSum`, `depth`.
class SurfaceInsideIntegrator {
public:
  SurfaceInsideIntegrator(const MeshDistance& other, const Pose& otherPose, double leafRadius, OverlapReference& out,
                          Vec3& gradient, Vec3& centroidSum)
      : other_(other), otherPose_(otherPose), leafRadius_(leafRadius), out_(out), gradient_(gradient),
        centroidSum_(centroidSum) {}

  void triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 doubleAreaNormal = (b - a).cross(c - a);
    const double area = 0.5 * doubleAreaNormal.norm();
    if (area == 0) return;
    normal_ = doubleAreaNormal / (2.0 * area);
    split(a, b, c, area);
  }

private:
  double signedDistance(const Vec3& world) {
    ++out_.distanceQueries;
    return other_.signedDistance(otherPose_.applyInverse(world));
  }
  void addInside(const Vec3& g, double area, double depth) {
    gradient_ += area * normal_;
    centroidSum_ += area * g;
    out_.area += area;
    out_.depth = std::max(out_.depth, depth);
  }
  void split(const Vec3& a, const Vec3& b, const Vec3& c, double area) {
    const Vec3 g = (a + b + c) / 3.0;
    const double radius = std::sqrt(std::max({(a - g).squaredNorm(), (b - g).squaredNorm(), (c - g).squaredNorm()}));
    const double d = signedDistance(g);
    if (d > radius) return;  // the whole (sub)triangle is outside
    if (d < -radius) {       // the whole (sub)triangle is inside; its deepest point is a corner or g
      addInside(g, area, std::max({-d, -signedDistance(a), -signedDistance(b), -signedDistance(c)}));
      return;
    }
    if (radius <= leafRadius_) {
      if (d < 0) addInside(g, area, -d);
      return;
    }
    const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    const double quarter = 0.25 * area;
    split(a, ab, ca, quarter);
    split(ab, b, bc, quarter);
    split(ca, bc, c, quarter);
    split(ab, bc, ca, quarter);
  }

  const MeshDistance& other_;
  const Pose& otherPose_;
  double leafRadius_;
  OverlapReference& out_;
  Vec3& gradient_;
  Vec3& centroidSum_;
  Vec3 normal_ = Vec3::Zero();
};

inline void integrateSide(const MeshDistance& surface, const Pose& surfacePose, const MeshDistance& other,
                          const Pose& otherPose, double leafRadius, OverlapReference& out, Vec3& gradient,
                          Vec3& centroidSum) {
  // Cheap cull: triangles whose box misses the other mesh's world box cannot be inside it.
  Aabb otherBox;
  for (const Vec3& v : other.mesh().vertices) otherBox.extend(otherPose.apply(v));
  SurfaceInsideIntegrator integrator(other, otherPose, leafRadius, out, gradient, centroidSum);
  const TriangleMesh& mesh = surface.mesh();
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a = surfacePose.apply(mesh.vertices[t[0]]);
    const Vec3 b = surfacePose.apply(mesh.vertices[t[1]]);
    const Vec3 c = surfacePose.apply(mesh.vertices[t[2]]);
    Aabb box;
    box.extend(a);
    box.extend(b);
    box.extend(c);
    if ((box.min.array() > otherBox.max.array()).any() || (box.max.array() < otherBox.min.array()).any()) continue;
    integrator.triangle(a, b, c);
  }
}

}  // namespace detail

/// The volume-gradient reference for meshes A and B (given by their MeshDistance, which holds a
/// copy of each mesh) placed by poseA and poseB.
inline OverlapReference overlapReference(const MeshDistance& a, const Pose& poseA, const MeshDistance& b,
                                         const Pose& poseB, double leafRadius) {
  OverlapReference out;
  Vec3 centroidSum = Vec3::Zero();
  detail::integrateSide(b, poseB, a, poseA, leafRadius, out, out.gradientB, centroidSum);
  detail::integrateSide(a, poseA, b, poseB, leafRadius, out, out.gradientA, centroidSum);
  if (out.area > 0) out.centroid = centroidSum / out.area;
  return out;
}

}  // namespace clod::test
