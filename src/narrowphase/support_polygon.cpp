#include "narrowphase/support_polygon.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace clod::detail {
namespace {

// Contacts share the polygon's plane when their normals agree within 1 deg: a face lying on a face
// has one normal (the contact tree's differ by its normals' rounding, ~0.1 deg), while the
// contacts of a curved patch -- a nut's helical flank, a bunny's back -- turn from point to point,
// and each one's normal adds to the resultant the solver pushes along.
constexpr double kFacingCos = 0.99984769515639124;  // cos 1 deg

// A point this close to the polygon's rim (a fraction of its extent) lies on it: it would widen
// the support by at most that fraction. The contact tree's lattice samples next to a face's edge
// lie a cell inside it, beside the kept samples near the corners (which the rim extension then
// moves to the corners); the exact model's vertices in the middle of an edge lie on it.
constexpr double kRimToleranceRel = 1e-2;

// Depths within this fraction of the polygon's extent of its depth plane count as on it: above the
// contact tree's field noise on a flat face (~3e-6 of a box's diagonal, within its cells' bounds)
// and rounding, far below the slop the solver leaves (2e-3 of the diagonal). Not the contacts' own
// error bounds: a coarse sphere pair's (its spheres' radii) would call every interior contact flat.
constexpr double kDepthToleranceRel = 1e-4;

}  // namespace

SupportPolygon::SupportPolygon(const Vec3& normal, std::span<double> buffer)
    : normal_(normal), points_(buffer.data()), room_(buffer.size() / 3) {
  hull_ = points_ + 2 * room_;
  u_ = (std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(normal).normalized();
  v_ = normal.cross(u_);
}

void SupportPolygon::add(const Contact& c) {
  if (count_ == room_ || c.normal.dot(normal_) < kFacingCos) return;
  if (count_ == 0) origin_ = c.point;
  const double px = u_.dot(c.point - origin_), py = v_.dot(c.point - origin_);
  points_[2 * count_] = px;
  points_[2 * count_ + 1] = py;
  ++count_;
  moments_[0] += 1.0, moments_[1] += px, moments_[2] += py;
  moments_[3] += px * px, moments_[4] += px * py, moments_[5] += py * py;
  depthMoments_[0] += c.depth, depthMoments_[1] += c.depth * px, depthMoments_[2] += c.depth * py;
}

bool SupportPolygon::close() {
  closed_ = false;
  if (count_ < 3) return false;
  wrapHull();
  extent_ = 0.0;
  for (std::size_t i = 0; i < count_; ++i)
    for (std::size_t j = i + 1; j < count_; ++j) extent_ = std::max(extent_, std::hypot(x(j) - x(i), y(j) - y(i)));
  if (hullSize_ < 3 || !(twiceHullArea() > kRimToleranceRel * extent_ * extent_)) return false;
  closed_ = fitDepthPlane();
  return closed_;
}

double SupportPolygon::pickScore(const Contact& c, double spread) const {
  if (!closed_ || c.normal.dot(normal_) < kFacingCos) return spread;
  const double px = u_.dot(c.point - origin_), py = v_.dot(c.point - origin_);
  double outside = 0.0;  // the most c lies outside an edge (right of a -> b)
  for (std::size_t k = 0; k < hullSize_; ++k) {
    const std::size_t a = hullPoint(k), b = hullPoint((k + 1) % hullSize_);
    const double ex = x(b) - x(a), ey = y(b) - y(a);
    outside = std::max(outside, (ey * (px - x(a)) - ex * (py - y(a))) / std::hypot(ex, ey));
  }
  if (outside > kRimToleranceRel * extent_) return outside;
  const double planeDepth = plane_[0] + plane_[1] * px + plane_[2] * py;
  return c.depth > planeDepth + kDepthToleranceRel * extent_ ? spread : 0.0;
}

// Gift wrapping, counter-clockwise (a manifold has a handful of points). Of collinear points the
// farthest is taken, so no hull point lies in the middle of an edge.
void SupportPolygon::wrapHull() {
  std::size_t start = 0;
  for (std::size_t i = 1; i < count_; ++i) {
    if (x(i) < x(start) || (x(i) == x(start) && y(i) < y(start))) start = i;
  }
  hullSize_ = 0;
  std::size_t current = start;
  do {
    hull_[hullSize_++] = static_cast<double>(current);
    std::size_t next = current == 0 ? 1 : 0;
    for (std::size_t j = 0; j < count_; ++j) {
      if (j == current) continue;
      const double ax = x(next) - x(current), ay = y(next) - y(current);
      const double bx = x(j) - x(current), by = y(j) - y(current);
      const double cross = ax * by - ay * bx;
      if (cross < 0.0 || (cross == 0.0 && bx * bx + by * by > ax * ax + ay * ay)) next = j;
    }
    current = next;
  } while (current != start && hullSize_ < count_);
}

double SupportPolygon::twiceHullArea() const {
  double sum = 0.0;
  for (std::size_t k = 0; k < hullSize_; ++k) {
    const std::size_t a = hullPoint(k), b = hullPoint((k + 1) % hullSize_);
    sum += x(a) * y(b) - x(b) * y(a);
  }
  return sum;
}

bool SupportPolygon::fitDepthPlane() {
  Eigen::Matrix3d m;
  m << moments_[0], moments_[1], moments_[2], moments_[1], moments_[3], moments_[4], moments_[2], moments_[4],
      moments_[5];
  const Eigen::Vector3d rhs(depthMoments_[0], depthMoments_[1], depthMoments_[2]);
  const Eigen::Vector3d solution = m.fullPivLu().solve(rhs);
  if (!solution.allFinite()) return false;
  plane_ = {solution[0], solution[1], solution[2]};
  return true;
}

}  // namespace clod::detail
