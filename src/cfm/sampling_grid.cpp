// Cube-map grid of candidate lists: O(1) exact nearest-sample retrieval for any point set
// (used by the geodesic and Fibonacci schemes).
//
// Exactness by the triangle inequality on great-circle angles: if u lies in a cell of centre c
// and angular radius r, its nearest sample s* satisfies
//   d(c, s*) <= d(u, s*) + r <= d(u, s_c) + r <= d(c, s_c) + 2r = d_min(c) + 2r,
// where s_c is the sample nearest to c. So listing every sample within d_min(c) + 2r of c lists
// every sample that can be nearest to a direction of the cell.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "clod/error.h"
#include "clod/sphere_sampling.h"

namespace clod {
namespace {

// Extra angle (radians) added to every candidate-list bound. acos near 1 turns a 1e-16 error in
// a dot product into ~1e-8 in the angle; 1e-7 keeps the lists supersets at negligible cost.
constexpr double kAngleSlack = 1e-7;

double angleBetween(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)); }

}  // namespace

void SphereSampling::buildCandidateGrid() {
  // Samples sorted by z. The angle between two directions is at least the difference of their
  // polar angles, so every sample within angle w of a direction of polar angle phi has z in
  // [cos(phi + w), cos(phi - w)]: each cell scans a z window of O(sqrt(n)) samples, not all n.
  std::vector<std::uint32_t> byZ(size());
  for (std::uint32_t i = 0; i < size(); ++i) byZ[i] = i;
  std::sort(byZ.begin(), byZ.end(), [&](std::uint32_t a, std::uint32_t b) { return z_[a] < z_[b] || (z_[a] == z_[b] && a < b); });
  std::vector<double> sortedZ(size());
  for (std::uint32_t i = 0; i < size(); ++i) sortedZ[i] = z_[byZ[i]];
  auto window = [&](double phi, double w) {
    const double zLow = std::cos(std::min(M_PI, phi + w)) - 1e-12;
    const double zHigh = std::cos(std::max(0.0, phi - w)) + 1e-12;
    const auto first = std::lower_bound(sortedZ.begin(), sortedZ.end(), zLow) - sortedZ.begin();
    const auto last = std::upper_bound(sortedZ.begin(), sortedZ.end(), zHigh) - sortedZ.begin();
    return std::pair<const std::uint32_t*, const std::uint32_t*>{byZ.data() + first, byZ.data() + last};
  };
  const double spacing = std::sqrt(4.0 * M_PI / size());  // typical distance between samples

  // Cube-map grid with about 4 cells per sample, so each cell's list stays short.
  const auto side = static_cast<std::uint32_t>(2 * std::max(1, static_cast<int>(std::ceil(std::sqrt(size() / 6.0)))));
  gridSide_ = side;
  const std::uint32_t cellCount = 6 * side * side;
  std::vector<std::vector<std::uint32_t>> cellLists(cellCount);
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, cellCount), [&](const tbb::blocked_range<std::uint32_t>& range) {
    for (std::uint32_t cell = range.begin(); cell != range.end(); ++cell) {
      const std::uint32_t face = cell / (side * side);
      const std::uint32_t ci = (cell / side) % side, cj = cell % side;
      const int axis = static_cast<int>(face / 2);
      const double sign = (face % 2) ? -1.0 : 1.0;
      auto cellPoint = [&](double s, double t) {
        Vec3 p;
        p[axis] = sign;
        p[(axis + 1) % 3] = s;
        p[(axis + 2) % 3] = t;
        return p.normalized();
      };
      auto coord = [&](double c) { return -1.0 + 2.0 * c / side; };
      const Vec3 centre = cellPoint(coord(ci + 0.5), coord(cj + 0.5));
      // Over a cube-face cell the angle to the centre is largest at a corner: the set of points
      // of the face plane within an angle < 90 degrees of the centre is convex (a conic section).
      double cellRadius = 0.0;
      for (int corner = 0; corner < 4; ++corner) {
        cellRadius = std::max(cellRadius, angleBetween(centre, cellPoint(coord(ci + (corner & 1)), coord(cj + (corner >> 1)))));
      }
      const double phi = std::atan2(std::hypot(centre.x(), centre.y()), centre.z());
      // d_min(centre): scan a window that usually holds the nearest sample; if the best found is
      // farther than the window's half-width, rescan with that distance, which is then exact.
      double window0 = 2.0 * cellRadius + 2.0 * spacing + kAngleSlack;
      double bestDot = -2.0;
      for (int pass = 0; pass < 2; ++pass) {
        const auto [first, last] = window(phi, window0);
        for (const std::uint32_t* s = first; s != last; ++s) bestDot = std::max(bestDot, direction(*s).dot(centre));
        const double bestAngle = std::acos(std::clamp(bestDot, -1.0, 1.0));
        if (bestAngle <= window0) break;
        window0 = bestAngle + kAngleSlack;
      }
      const double limit = std::acos(std::clamp(bestDot, -1.0, 1.0)) + 2.0 * cellRadius + kAngleSlack;
      const double cosLimit = std::cos(std::min(limit, M_PI));
      auto& list = cellLists[cell];
      const auto [first, last] = window(phi, limit);
      for (const std::uint32_t* s = first; s != last; ++s) {
        if (direction(*s).dot(centre) >= cosLimit) list.push_back(*s);
      }
      std::sort(list.begin(), list.end());
    }
  });
  cellStart_.reserve(cellCount + 1);
  cellStart_.push_back(0);
  for (const auto& list : cellLists) {
    cellSamples_.insert(cellSamples_.end(), list.begin(), list.end());
    cellStart_.push_back(static_cast<std::uint32_t>(cellSamples_.size()));
  }
}

std::uint32_t SphereSampling::gridCell(const Vec3& u) const noexcept {
  const Vec3 a = u.cwiseAbs();
  const int axis = (a.x() >= a.y() && a.x() >= a.z()) ? 0 : (a.y() >= a.z() ? 1 : 2);
  const double inv = 1.0 / a[axis];
  const std::uint32_t face = 2 * static_cast<std::uint32_t>(axis) + (u[axis] < 0.0 ? 1 : 0);
  const double half = 0.5 * gridSide_;
  auto cellCoord = [&](double c) {
    const auto k = static_cast<std::int64_t>((c * inv + 1.0) * half);
    return static_cast<std::uint32_t>(std::clamp<std::int64_t>(k, 0, gridSide_ - 1));
  };
  return (face * gridSide_ + cellCoord(u[(axis + 1) % 3])) * gridSide_ + cellCoord(u[(axis + 2) % 3]);
}

std::uint32_t SphereSampling::nearestInGrid(const Vec3& u) const noexcept {
  const std::uint32_t cell = gridCell(u);
  return nearestAmong(std::span(cellSamples_).subspan(cellStart_[cell], cellStart_[cell + 1] - cellStart_[cell]), u);
}

}  // namespace clod
