#include "min_sphere.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace clod::detail {
namespace {

struct Ball {
  Vec3 center = Vec3::Zero();
  double radiusSquared = -1.0;  // negative: empty ball
};

bool contains(const Ball& ball, const Vec3& p) {
  // Relative slack so that support points themselves (on the boundary up to rounding) count
  // as inside; otherwise move-to-front can cycle on co-spherical input.
  return (p - ball.center).squaredNorm() <= ball.radiusSquared * (1.0 + 1e-12) + 1e-300;
}

Ball ballOfTwo(const Vec3& a, const Vec3& b) {
  Ball ball;
  ball.center = 0.5 * (a + b);
  ball.radiusSquared = (a - ball.center).squaredNorm();
  return ball;
}

Ball widestPair(const Vec3* s, int n) {
  Ball best = ballOfTwo(s[0], s[0]);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      Ball ball = ballOfTwo(s[i], s[j]);
      if (ball.radiusSquared > best.radiusSquared) best = ball;
    }
  return best;
}

Ball ballOfThree(const Vec3& a, const Vec3& b, const Vec3& c) {
  // Circumcircle: with u = a - c, v = b - c, centre = c + ((|u|^2 v - |v|^2 u) x (u x v)) / (2|u x v|^2).
  const Vec3 u = a - c;
  const Vec3 v = b - c;
  const Vec3 w = u.cross(v);
  const double w2 = w.squaredNorm();
  const double scale = u.squaredNorm() * v.squaredNorm();
  const std::array<Vec3, 3> pts{a, b, c};
  if (!(w2 > 1e-24 * scale)) return widestPair(pts.data(), 3);  // (nearly) collinear
  Ball ball;
  ball.center = c + (u.squaredNorm() * v - v.squaredNorm() * u).cross(w) / (2.0 * w2);
  ball.radiusSquared = (a - ball.center).squaredNorm();
  return ball;
}

Ball ballOfFour(const Vec3* s) {
  // Circumsphere: 2 (p_i - p_0) . x = |p_i - p_0|^2 for x = centre - p_0.
  Mat3 m;
  Vec3 rhs;
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = s[i + 1] - s[0];
    m.row(i) = 2.0 * d.transpose();
    rhs[i] = d.squaredNorm();
  }
  const double det = m.determinant();
  const double scale = m.row(0).norm() * m.row(1).norm() * m.row(2).norm();
  if (std::abs(det) > 1e-12 * scale) {
    Ball ball;
    ball.center = s[0] + m.partialPivLu().solve(rhs);
    ball.radiusSquared = (s[0] - ball.center).squaredNorm();
    return ball;
  }
  // (Nearly) co-planar support: the smallest ball through three of them that holds the fourth.
  Ball best;
  for (int skip = 0; skip < 4; ++skip) {
    std::array<Vec3, 3> t;
    int k = 0;
    for (int i = 0; i < 4; ++i)
      if (i != skip) t[k++] = s[i];
    Ball ball = ballOfThree(t[0], t[1], t[2]);
    if (contains(ball, s[skip]) && (best.radiusSquared < 0 || ball.radiusSquared < best.radiusSquared))
      best = ball;
  }
  return best.radiusSquared >= 0 ? best : widestPair(s, 4);
}

Ball ballOfSupport(const std::array<Vec3, 4>& s, int n) {
  switch (n) {
    case 0: return Ball{};
    case 1: return Ball{s[0], 0.0};
    case 2: return ballOfTwo(s[0], s[1]);
    case 3: return ballOfThree(s[0], s[1], s[2]);
    default: return ballOfFour(s.data());
  }
}

// Smallest ball of points[0, end) with `support` on its boundary. Recursion only grows the
// support set, so the depth is at most 4.
Ball moveToFront(std::vector<Vec3>& points, std::size_t end, std::array<Vec3, 4>& support, int supportCount) {
  Ball ball = ballOfSupport(support, supportCount);
  if (supportCount == 4) return ball;
  for (std::size_t i = 0; i < end; ++i) {
    if (ball.radiusSquared >= 0 && contains(ball, points[i])) continue;
    support[supportCount] = points[i];
    ball = moveToFront(points, i, support, supportCount + 1);
    std::rotate(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(i),
                points.begin() + static_cast<std::ptrdiff_t>(i) + 1);
  }
  return ball;
}

}  // namespace

double farthestDistance(const Vec3& center, std::span<const Vec3> points) {
  double r2 = 0.0;
  for (const Vec3& p : points) r2 = std::max(r2, (p - center).squaredNorm());
  return std::sqrt(r2);
}

Sphere minimumEnclosingSphere(std::span<const Vec3> points, std::vector<Vec3>& scratch) {
  if (points.empty()) return {};
  scratch.assign(points.begin(), points.end());
  // A fixed seed keeps builds deterministic; the shuffle gives the expected linear time.
  // minstd_rand: seeding a Mersenne twister per call cost more than the whole Welzl on the
  // small point sets the medial reduction fits millions of times.
  std::minstd_rand rng(0x5eed1234u);
  std::shuffle(scratch.begin(), scratch.end(), rng);
  std::array<Vec3, 4> support;
  Ball ball = moveToFront(scratch, scratch.size(), support, 0);
  Sphere sphere;
  sphere.center = ball.center;
  sphere.radius = farthestDistance(ball.center, points);
  return sphere;
}

}  // namespace clod::detail
