#pragma once
// Internal: generalized winding number pieces. Exact per-triangle solid angle, and the
// far-field Taylor expansion of a cluster of triangles (Barill, Dickson, Schmidt, Levin,
// Jacobson, "Fast winding numbers for soups and clouds", SIGGRAPH 2018).

#include "clod/math.h"

namespace clod::detail {

/// Signed solid angle of triangle (a, b, c) seen from q, in steradians, in (-2pi, 2pi):
/// positive when q is behind the triangle (on the side opposite (b-a)x(c-a)).
/// Van Oosterom & Strackee, "The solid angle of a plane triangle", IEEE TBME 30(2), 1983.
double triangleSolidAngle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) noexcept;

/// Raw area moments of a set of triangles; additive, so a node's moments are the sum of its
/// children's.
struct WindingRawMoments {
  double area = 0.0;
  Vec3 weightedCentroid = Vec3::Zero();  ///< sum of area * centroid
  Vec3 normal = Vec3::Zero();            ///< sum of area * unit normal
  Mat3 centroidNormal = Mat3::Zero();    ///< sum of area * centroid * normal^T

  void addTriangle(const Vec3& a, const Vec3& b, const Vec3& c);
  void add(const WindingRawMoments& other);
};

/// Far-field expansion of one cluster, to second order, about its area-weighted centroid.
struct WindingFarField {
  Vec3 center = Vec3::Zero();
  Vec3 normal = Vec3::Zero();       ///< N = sum of area * n
  Mat3 secondMoment = Mat3::Zero(); ///< C = sum of area * (centroid - center) n^T
  double farRadiusSquared = 0.0;    ///< expansion used only beyond this squared distance

  /// `boundsMin`/`boundsMax` enclose every triangle of the cluster; `beta` is the accuracy
  /// parameter (the expansion is used when |q - center| > beta * cluster radius).
  static WindingFarField fromMoments(const WindingRawMoments& m, const Vec3& boundsMin, const Vec3& boundsMax,
                                     double beta);

  /// 4pi times the cluster's winding-number contribution at q (the sum of its solid angles),
  /// valid when (q - center).squaredNorm() > farRadiusSquared.
  double solidAngle(const Vec3& q) const noexcept;
};

}  // namespace clod::detail
