#include "dynamics/hull_points.h"

#include <algorithm>
#include <cstdint>
#include <limits>

namespace clod::detail {

HullPoints::HullPoints(const CollisionBody& shape) {
  const bool patch = !shape.spherePatchVertices(0).empty();
  const auto indices = patch ? shape.spherePatchVertices(0) : shape.sphereSupportVertices(0);
  slack_ = patch ? 0.0 : shape.sphereSupportSlack(0);
  x_.reserve(indices.size());
  y_.reserve(indices.size());
  z_.reserve(indices.size());
  for (const std::uint32_t v : indices) {
    const Vec3& p = shape.mesh().vertices[v];
    x_.push_back(p.x());
    y_.push_back(p.y());
    z_.push_back(p.z());
  }
}

std::optional<Aabb> HullPoints::boxUnder(const Mat3& m, const Vec3& t) const {
  if (empty()) return std::nullopt;
  Aabb box;
  for (int k = 0; k < 3; ++k) {  // one row of m at a time: three flat loops the compiler vectorises
    const double mx = m(k, 0), my = m(k, 1), mz = m(k, 2);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < x_.size(); ++i) {
      const double c = mx * x_[i] + my * y_[i] + mz * z_[i];
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
    box.min[k] = lo + t[k] - slack_;
    box.max[k] = hi + t[k] + slack_;
  }
  return box;
}

std::array<Vec3, 5> HullPoints::farthestAlong(const std::array<Vec3, 5>& directions, std::size_t count) const {
  std::array<Vec3, 5> out;
  for (std::size_t k = 0; k < count; ++k) {
    const Vec3& d = directions[k];
    std::size_t best = 0;
    double reach = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < x_.size(); ++i)
      if (const double r = d.x() * x_[i] + d.y() * y_[i] + d.z() * z_[i]; r > reach) reach = r, best = i;
    out[k] = Vec3(x_[best], y_[best], z_[best]);
  }
  return out;
}

}  // namespace clod::detail
