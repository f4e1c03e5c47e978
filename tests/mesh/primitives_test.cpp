#include "clod/primitives.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

// Closed, consistently oriented, outward, genus 0, checked by brute force: every undirected edge
// is used exactly twice, every directed edge exactly once (so neighbours traverse shared edges in
// opposite directions), V - E + F = 2, and since the primitives are convex and centred at the
// origin every face normal points away from the origin.
void expectClosedOutwardConvex(const TriangleMesh& mesh) {
  const auto uses = test::countEdgeUses(mesh);
  for (const auto& [edge, count] : uses) EXPECT_EQ(count, 2) << "edge " << edge.first << "-" << edge.second;
  std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(directed.insert({t[k], t[(k + 1) % 3]}).second) << "directed edge used twice";
  EXPECT_EQ(std::int64_t(mesh.vertexCount()) - std::int64_t(uses.size()) + std::int64_t(mesh.triangleCount()), 2);
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
    const Vec3 centroid = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
    EXPECT_GT(mesh.triangleCross(t).dot(centroid), 0.0) << "triangle " << t << " faces inward";
    EXPECT_GT(mesh.triangleArea(t), 0.0) << "triangle " << t << " is degenerate";
  }
}

TEST(Primitives, BoxHasEightCornersAtItsHalfExtents) {
  const Vec3 half(0.5, 1.5, 2.0);
  const TriangleMesh box = makeBox(half);
  ASSERT_EQ(box.vertexCount(), 8u);
  ASSERT_EQ(box.triangleCount(), 12u);
  std::set<std::tuple<double, double, double>> corners;
  for (const Vec3& v : box.vertices) {
    EXPECT_EQ(std::abs(v.x()), half.x());
    EXPECT_EQ(std::abs(v.y()), half.y());
    EXPECT_EQ(std::abs(v.z()), half.z());
    corners.insert({v.x(), v.y(), v.z()});
  }
  EXPECT_EQ(corners.size(), 8u);
  expectClosedOutwardConvex(box);
}

TEST(Primitives, IcosphereHasTheExpectedCountsAndLiesOnTheSphere) {
  const double radius = 2.5;
  for (std::uint32_t s = 0; s <= 4; ++s) {
    const TriangleMesh sphere = makeIcosphere(radius, s);
    const std::uint32_t pow4 = 1u << (2 * s);
    EXPECT_EQ(sphere.triangleCount(), 20 * pow4);
    EXPECT_EQ(sphere.vertexCount(), 10 * pow4 + 2);
    // Projection onto the sphere is one normalisation and one scaling: a few ulps of the radius.
    for (const Vec3& v : sphere.vertices) EXPECT_NEAR(v.norm(), radius, 1e-14 * radius);
    expectClosedOutwardConvex(sphere);
  }
}

TEST(Primitives, CylinderRingsLieOnTheCircleAndCapsOnThePlanes) {
  const double radius = 0.75, halfHeight = 2.0;
  for (std::uint32_t segments : {3u, 4u, 17u, 64u}) {
    const TriangleMesh cylinder = makeCylinder(radius, halfHeight, segments);
    EXPECT_EQ(cylinder.vertexCount(), 2 * segments + 2);
    EXPECT_EQ(cylinder.triangleCount(), 4 * segments);
    std::uint32_t onRing = 0;
    for (const Vec3& v : cylinder.vertices) {
      EXPECT_EQ(std::abs(v.z()), halfHeight);
      const double r = std::hypot(v.x(), v.y());
      if (r > 0.0) {
        EXPECT_NEAR(r, radius, 1e-15 * 4 * radius);
        ++onRing;
      }
    }
    EXPECT_EQ(onRing, 2 * segments);
    expectClosedOutwardConvex(cylinder);
  }
}

TEST(Primitives, InvalidParametersThrowInvalidArgument) {
  auto expectInvalid = [](auto&& make) {
    try {
      make();
      ADD_FAILURE() << "no exception";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    }
  };
  expectInvalid([] { makeBox(Vec3(1, 0, 1)); });
  expectInvalid([] { makeBox(Vec3(1, std::nan(""), 1)); });
  expectInvalid([] { makeIcosphere(-1.0, 2); });
  expectInvalid([] { makeIcosphere(1.0, 11); });
  expectInvalid([] { makeCylinder(1.0, 1.0, 2); });
  expectInvalid([] { makeCylinder(1.0, 0.0, 8); });
  expectInvalid([] { makeCylinder(INFINITY, 1.0, 8); });
}

}  // namespace
}  // namespace clod
