#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clod/proximity.h"
#include "oracle.h"

namespace {

using clod::FeatureType;
using clod::Vec3;

TEST(TriangleClosestPoint, ClassifiesTheSevenVoronoiRegionsOfARightTriangle) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    Vec3 p;
    FeatureType type;
    int local;
    Vec3 expected;
  };
  const Case cases[] = {
      {{0.2, 0.2, 1}, FeatureType::kFace, 0, {0.2, 0.2, 0}},
      {{-1, -1, 0.5}, FeatureType::kVertex, 0, a},
      {{2, -0.5, 0}, FeatureType::kVertex, 1, b},
      {{-0.5, 2, -3}, FeatureType::kVertex, 2, c},
      {{0.5, -1, 0}, FeatureType::kEdge, 0, {0.5, 0, 0}},
      {{1, 1, 0}, FeatureType::kEdge, 1, {0.5, 0.5, 0}},
      {{-2, 0.25, 1}, FeatureType::kEdge, 2, {0, 0.25, 0}},
  };
  for (const Case& k : cases) {
    const auto r = clod::closestPointOnTriangle(k.p, a, b, c);
    EXPECT_EQ(r.feature, k.type) << k.p.transpose();
    EXPECT_EQ(r.localIndex, k.local) << k.p.transpose();
    EXPECT_NEAR((r.point - k.expected).norm(), 0.0, 1e-15) << k.p.transpose();
    EXPECT_NEAR(r.distanceSquared, (k.p - k.expected).squaredNorm(), 1e-15);
  }
}

// Random triangles, including needles and exactly degenerate ones, against the independent
// projection-based oracle. Coordinates are O(1), so 1e-12 absolute is ~1e4 ulps of slack for
// the different operation orders of the two algorithms.
TEST(TriangleClosestPoint, MatchesProjectionOracleOnRandomAndDegenerateTriangles) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto rv = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  const int trials = oracle::sanitizerRun() ? 20000 : 200000;
  int featureMismatches = 0;
  for (int i = 0; i < trials; ++i) {
    Vec3 a = rv(), b = rv(), c = rv();
    switch (i % 6) {
      case 1: c = a + 1e-7 * rv(); break;                // needle: two corners nearly equal
      case 2: c = a + 0.37 * (b - a); break;              // collinear, third corner between
      case 3: c = a + 1.7 * (b - a); break;               // collinear, third corner outside
      case 4: b = a; break;                               // two corners equal
      case 5: b = a; c = a; break;                        // a point
      default: break;
    }
    const Vec3 p = 2.0 * rv();
    const auto r = clod::closestPointOnTriangle(p, a, b, c);
    const auto o = oracle::closestOnTriangle(p, a, b, c);
    ASSERT_TRUE(r.point.allFinite() && std::isfinite(r.distanceSquared)) << "trial " << i;
    ASSERT_NEAR(std::sqrt(r.distanceSquared), o.distance, 1e-12) << "trial " << i;
    ASSERT_NEAR((r.point - p).norm(), std::sqrt(r.distanceSquared), 1e-12);
    // The reported feature must itself be at the closest distance (ties allowed).
    const Vec3 corners[3] = {a, b, c};
    double featureDistance = 0.0;
    if (r.feature == FeatureType::kVertex) {
      featureDistance = (p - corners[r.localIndex]).norm();
    } else if (r.feature == FeatureType::kEdge) {
      featureDistance = oracle::closestOnSegment(p, corners[r.localIndex], corners[(r.localIndex + 1) % 3], 0).distance;
    } else {
      featureDistance = o.distance;
      ASSERT_EQ(o.type, FeatureType::kFace) << "trial " << i << ": face reported, oracle says otherwise";
    }
    ASSERT_NEAR(featureDistance, o.distance, 1e-12) << "trial " << i;
    if (r.feature != o.type || (r.feature != FeatureType::kFace && r.localIndex != o.local)) ++featureMismatches;
  }
  // Mismatches can only be ties (degenerate cases have coincident features); on general
  // triangles they are measure-zero events.
  EXPECT_LT(featureMismatches, trials / 4);
}

TEST(TriangleClosestPoint, NeverReturnsNaNForExtremeNeedles) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0.5, 1e-300, 0);
  for (const Vec3& p : {Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0), Vec3(-1, 0, 0), Vec3(0.5, 1e-300, 1e-300)}) {
    const auto r = clod::closestPointOnTriangle(p, a, b, c);
    EXPECT_TRUE(r.point.allFinite());
    EXPECT_TRUE(std::isfinite(r.distanceSquared));
    EXPECT_NEAR(std::sqrt(r.distanceSquared), oracle::closestOnTriangle(p, a, b, c).distance, 1e-15);
  }
}

TEST(FeatureNames, AreTheStableStrings) {
  EXPECT_STREQ(clod::featureTypeName(FeatureType::kVertex), "vertex");
  EXPECT_STREQ(clod::featureTypeName(FeatureType::kEdge), "edge");
  EXPECT_STREQ(clod::featureTypeName(FeatureType::kFace), "face");
  EXPECT_STREQ(clod::signMethodName(clod::SignMethod::kPseudonormal), "pseudonormal");
  EXPECT_STREQ(clod::signMethodName(clod::SignMethod::kWindingNumber), "winding_number");
}

}  // namespace
