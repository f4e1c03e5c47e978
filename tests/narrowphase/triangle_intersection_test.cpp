// Triangle-triangle intersection (exact model) against an independent oracle: two triangles in
// general position intersect exactly when an edge of one crosses the other (segment-triangle
// test with barycentric coordinates, written here from scratch).

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "narrowphase/triangle_intersection.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using narrowphase::intersectTriangles;
using narrowphase::TriangleIntersection;

// Segment pq against triangle abc (Cramer's rule on p + t(q-p) = a + u(b-a) + v(c-a)).
bool segmentHitsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  Eigen::Matrix3d m;
  m.col(0) = p - q;
  m.col(1) = b - a;
  m.col(2) = c - a;
  const double det = m.determinant();
  if (std::abs(det) < 1e-14) return false;
  const Vec3 x = m.inverse() * (p - a);  // (t, u, v)
  return x[0] >= 0 && x[0] <= 1 && x[1] >= 0 && x[2] >= 0 && x[1] + x[2] <= 1;
}

bool oracle(const Vec3* a, const Vec3* b) {
  for (int i = 0; i < 3; ++i) {
    if (segmentHitsTriangle(a[i], a[(i + 1) % 3], b[0], b[1], b[2])) return true;
    if (segmentHitsTriangle(b[i], b[(i + 1) % 3], a[0], a[1], a[2])) return true;
  }
  return false;
}

double distanceToTriangle(const Vec3& p, const Vec3* t) {
  // Brute force over a fine barycentric grid is too slow; use the plane + edge distances.
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  const Vec3 proj = p - n.dot(p - t[0]) * n;
  auto inside = [&](const Vec3& x) {
    for (int i = 0; i < 3; ++i) {
      if (n.dot((t[(i + 1) % 3] - t[i]).cross(x - t[i])) < -1e-12) return false;
    }
    return true;
  };
  if (inside(proj)) return std::abs(n.dot(p - t[0]));
  double best = 1e300;
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = t[(i + 1) % 3] - t[i];
    const double s = std::clamp(e.dot(p - t[i]) / e.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - (t[i] + s * e)).norm());
  }
  return best;
}

TEST(TriangleIntersection, AgreesWithEdgeCrossingOracleOnRandomPairs) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int pairs = test::sanitizerRun() ? 20000 : 200000;
  int hits = 0;
  TriangleIntersection out;
  for (int k = 0; k < pairs; ++k) {
    Vec3 a[3], b[3];
    for (int i = 0; i < 3; ++i) {
      a[i] = Vec3(u(rng), u(rng), u(rng));
      b[i] = Vec3(u(rng), u(rng), u(rng)) + Vec3(0.5, 0, 0);
    }
    const bool expected = oracle(a, b);
    const bool got = intersectTriangles(a[0], a[1], a[2], b[0], b[1], b[2], 1e-12, out);
    ASSERT_EQ(got, expected) << "pair " << k;
    if (!got) continue;
    ++hits;
    ASSERT_EQ(out.count, 2u);
    // The segment's end points lie on both triangles (up to rounding, relative to size ~2).
    for (std::uint32_t i = 0; i < 2; ++i) {
      EXPECT_LT(distanceToTriangle(out.points[i], a), 1e-9);
      EXPECT_LT(distanceToTriangle(out.points[i], b), 1e-9);
    }
  }
  EXPECT_GT(hits, pairs / 20);  // the sample exercises both answers
}

TEST(TriangleIntersection, CoplanarOverlapGivesTheOverlapPolygon) {
  // Two right triangles in z = 0 whose overlap is the unit square's lower-left half clipped:
  // A = (0,0),(2,0),(0,2); B (facing down, as a face resting on a face) = (1,-1),(1,3),(-1,1).
  const Vec3 a0(0, 0, 0), a1(2, 0, 0), a2(0, 2, 0);
  const Vec3 b0(1, -1, 0), b1(-1, 1, 0), b2(1, 3, 0);
  TriangleIntersection out;
  ASSERT_TRUE(intersectTriangles(a0, a1, a2, b0, b1, b2, 1e-12, out));
  EXPECT_TRUE(out.coplanar);
  // Overlap: A (x >= 0, y >= 0, x + y <= 2) within B (x <= 1, x + y >= 0, y - x <= 2) is the
  // trapezoid (0,0), (1,0), (1,1), (0,2) of area 1.5.
  ASSERT_GE(out.count, 3u);
  double area = 0.0;
  for (std::uint32_t i = 0; i < out.count; ++i) {
    const Vec3& p = out.points[i];
    const Vec3& q = out.points[(i + 1) % out.count];
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
    EXPECT_NEAR(p.z(), 0.0, 1e-15);
  }
  EXPECT_NEAR(std::abs(area), 1.5, 1e-12);
  // Apart in the plane: no overlap.
  EXPECT_FALSE(intersectTriangles(a0, a1, a2, b0 + Vec3(5, 0, 0), b1 + Vec3(5, 0, 0), b2 + Vec3(5, 0, 0), 1e-12, out));
}

TEST(TriangleIntersection, TouchingAndParallelCases) {
  TriangleIntersection out;
  const Vec3 a0(0, 0, 0), a1(1, 0, 0), a2(0, 1, 0);
  // B's corner touches A's interior from above: one point, touching (B has no corner below A).
  EXPECT_TRUE(intersectTriangles(a0, a1, a2, Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 1), Vec3(0.5, 0.1, 1), 1e-12, out));
  EXPECT_LT((out.points[0] - Vec3(0.2, 0.2, 0)).norm(), 1e-12);
  EXPECT_LT((out.points[1] - Vec3(0.2, 0.2, 0)).norm(), 1e-12);
  EXPECT_TRUE(out.touching);
  // B standing on A with an edge in A's plane: a segment, touching; pushed 0.1 through: crossing.
  EXPECT_TRUE(intersectTriangles(a0, a1, a2, Vec3(0.1, 0.2, 0), Vec3(0.6, 0.2, 0), Vec3(0.3, 0.2, 1), 1e-12, out));
  EXPECT_TRUE(out.touching);
  EXPECT_TRUE(intersectTriangles(a0, a1, a2, Vec3(0.1, 0.2, -0.1), Vec3(0.6, 0.2, -0.1), Vec3(0.3, 0.2, 1), 1e-12, out));
  EXPECT_FALSE(out.touching);
  // Parallel planes 1e-3 apart: nothing.
  EXPECT_FALSE(intersectTriangles(a0, a1, a2, a0 + Vec3(0, 0, 1e-3), a1 + Vec3(0, 0, 1e-3), a2 + Vec3(0, 0, 1e-3), 1e-12, out));
  // Degenerate triangle: never.
  EXPECT_FALSE(intersectTriangles(a0, a1, a2, Vec3(0.1, 0.1, -1), Vec3(0.1, 0.1, 1), Vec3(0.1, 0.1, 2), 1e-12, out));
  // A face pushed 0.1 through another: penetration measured on the corners below.
  ASSERT_TRUE(intersectTriangles(Vec3(0.1, 0.1, -0.1), Vec3(0.1, 0.1, 1), Vec3(0.3, 0.1, 1), a0, a1, a2, 1e-12, out));
  EXPECT_NEAR(out.penetrationBelowB, 0.1, 1e-12);
  // Two perpendicular faces, each straddling the other's plane, whose parts on the planes' common
  // line (x = 0.25, y = 1) meet in one point, (0.25, 1, 0): a box's side face above a step's top
  // edge and the step's side face below it. One point, touching (read as crossing, the pair got a
  // penetration volume of its own and a sideways contact 0.36 m deep).
  const Vec3 side0(0.25, 0.7, 0.0), side1(0.25, 1.2, 0.0), side2(0.25, 0.7, 0.5);  // plane x = 0.25, z >= 0
  const Vec3 step0(-1.0, 1.0, 0.0), step1(1.0, 1.0, 0.0), step2(0.0, 1.0, -0.5);   // plane y = 1, z <= 0
  ASSERT_TRUE(intersectTriangles(side0, side1, side2, step0, step1, step2, 1e-12, out));
  EXPECT_LT((out.points[0] - Vec3(0.25, 1.0, 0.0)).norm(), 1e-12);
  EXPECT_LT((out.points[1] - Vec3(0.25, 1.0, 0.0)).norm(), 1e-12);
  EXPECT_TRUE(out.touching);
  // The step's face raised 0.1: they cross along a segment 0.1 long.
  const Vec3 up(0.0, 0.0, 0.1);
  ASSERT_TRUE(intersectTriangles(side0, side1, side2, step0 + up, step1 + up, step2 + up, 1e-12, out));
  EXPECT_NEAR((out.points[1] - out.points[0]).norm(), 0.1, 1e-12);  // z in [0, 0.1] on the line
  EXPECT_FALSE(out.touching);
}

}  // namespace
}  // namespace clod
