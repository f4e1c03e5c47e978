#include "winding_number.h"

#include <cmath>

namespace clod::detail {

double triangleSolidAngle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  const Vec3 x = a - q, y = b - q, z = c - q;
  const double lx = x.norm(), ly = y.norm(), lz = z.norm();
  const double numerator = x.dot(y.cross(z));
  const double denominator = lx * ly * lz + x.dot(y) * lz + x.dot(z) * ly + y.dot(z) * lx;
  // atan2(0, 0) is 0 in IEEE arithmetic: q on a vertex or a degenerate triangle adds nothing.
  return 2.0 * std::atan2(numerator, denominator);
}

void WindingRawMoments::addTriangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 areaNormal = 0.5 * (b - a).cross(c - a);  // area * unit normal
  const double triangleArea = areaNormal.norm();
  const Vec3 centroid = (a + b + c) / 3.0;
  area += triangleArea;
  weightedCentroid += triangleArea * centroid;
  normal += areaNormal;
  // The normal is constant over a flat triangle, so the integral of (y - center) n^T over it is
  // exactly area * (centroid - center) n^T: the moments below are exact, not sampled.
  centroidNormal += centroid * areaNormal.transpose();
}

void WindingRawMoments::add(const WindingRawMoments& other) {
  area += other.area;
  weightedCentroid += other.weightedCentroid;
  normal += other.normal;
  centroidNormal += other.centroidNormal;
}

WindingFarField WindingFarField::fromMoments(const WindingRawMoments& m, const Vec3& boundsMin,
                                             const Vec3& boundsMax, double beta) {
  WindingFarField f;
  f.center = m.area > 0.0 ? Vec3(m.weightedCentroid / m.area) : Vec3(0.5 * (boundsMin + boundsMax));
  f.normal = m.normal;
  f.secondMoment = m.centroidNormal - f.center * m.normal.transpose();
  // Cluster radius about the centre, bounded by the farthest corner of the cluster's box.
  const Vec3 far = (f.center - boundsMin).cwiseAbs().cwiseMax((boundsMax - f.center).cwiseAbs());
  f.farRadiusSquared = beta * beta * far.squaredNorm();
  return f;
}

// Taylor expansion of the solid-angle kernel f(y) = (y - q) / |y - q|^3 about the centre:
// f(y) ~ f(c) + J (y - c), J = I / |r|^3 - 3 r r^T / |r|^5, r = c - q. Integrating f . n over
// the cluster gives r.N / |r|^3 + J : C (J is symmetric).
double WindingFarField::solidAngle(const Vec3& q) const noexcept {
  const Vec3 r = center - q;
  const double d2 = r.squaredNorm();
  const double inv = 1.0 / std::sqrt(d2);
  const double inv3 = inv * inv * inv;
  const double inv5 = inv3 / d2;
  const double order1 = r.dot(normal) * inv3;
  const double order2 = secondMoment.trace() * inv3 - 3.0 * r.dot(secondMoment * r) * inv5;
  return order1 + order2;
}

}  // namespace clod::detail
