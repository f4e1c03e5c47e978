#pragma once
// Vector types used across clod's public API. All geometry is double precision unless a
// structure says otherwise (compact hot-loop storage may use float where its error budget allows).

#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace clod {

using Vec3 = Eigen::Vector3d;
using Vec3f = Eigen::Vector3f;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

/// Axis-aligned bounding box. An empty box has min > max.
struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  bool empty() const { return (min.array() > max.array()).any(); }
  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void extend(const Aabb& b) {
    min = min.cwiseMin(b.min);
    max = max.cwiseMax(b.max);
  }
  Vec3 center() const { return 0.5 * (min + max); }
  Vec3 extent() const { return max - min; }
  /// Length of the diagonal; the unit of every relative tolerance in clod ("...Rel").
  double diagonal() const { return empty() ? 0.0 : (max - min).norm(); }
};

/// Rigid transform x -> rotation * x + translation. Named xfFrameFromFrame in code.
struct Pose {
  Quat rotation = Quat::Identity();
  Vec3 translation = Vec3::Zero();

  Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
  Vec3 applyInverse(const Vec3& p) const { return rotation.conjugate() * (p - translation); }
  Pose inverse() const { return {rotation.conjugate(), -(rotation.conjugate() * translation)}; }
  /// (this * other)(x) = this(other(x)).
  Pose operator*(const Pose& other) const {
    return {rotation * other.rotation, rotation * other.translation + translation};
  }
};

}  // namespace clod
