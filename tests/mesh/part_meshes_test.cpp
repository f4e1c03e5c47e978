#include "clod/part_meshes.h"

#include <cmath>
#include <numbers>
#include <set>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/mesh_validation.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

using test::expectClosedOrientedGenus;

TEST(PartMeshes, TorusVolumeIsThePrismSumExactly) {
  const double big = 0.03, small = 0.006;
  const std::uint32_t n = 48, m = 12;
  const TriangleMesh torus = makeTorus(big, small, n, m);
  EXPECT_EQ(torus.vertexCount(), n * m);
  EXPECT_EQ(torus.triangleCount(), 2 * n * m);
  const double volume = expectClosedOrientedGenus(torus, 1);
  // Each of the n segments is the minor polygon (area m/2 r^2 sin(2 pi/m), centroid at the major
  // radius) swept linearly between two cross-sections 2 pi/n apart: volume sin(2 pi/n) A R.
  const double expected = n * std::sin(2 * std::numbers::pi / n) * 0.5 * m * small * small *
                          std::sin(2 * std::numbers::pi / m) * big;
  EXPECT_NEAR(volume, expected, 1e-12 * expected);  // rounding of ~1,000 triple products
  const Aabb box = torus.bounds();
  EXPECT_NEAR(box.max.x(), big + small, 1e-15);
  EXPECT_NEAR(box.min.z(), -small * std::sin(2 * std::numbers::pi * 3 / m), 1e-15);  // vertex j = 9 of 12
}

TEST(PartMeshes, HoledBlockVolumeIsBoxMinusPolygonalHole) {
  for (const Vec3& half : {Vec3(0.03, 0.03, 0.02), Vec3(0.04, 0.025, 0.01)}) {
    const double radius = 0.01;
    const std::uint32_t n = 64;
    const TriangleMesh block = makeHoledBlock(half, radius, n);
    EXPECT_EQ(block.vertexCount(), 4 * n);
    EXPECT_EQ(block.triangleCount(), 8 * n);
    const double volume = expectClosedOrientedGenus(block, 1);
    const double hole = 2 * half.z() * 0.5 * n * radius * radius * std::sin(2 * std::numbers::pi / n);
    const double expected = 8 * half.x() * half.y() * half.z() - hole;
    EXPECT_NEAR(volume, expected, 1e-12 * expected);
    // The block's bounds are the box's: every corner is a rim vertex.
    EXPECT_NEAR((block.bounds().max - half).norm(), 0.0, 1e-15);
    EXPECT_NEAR((block.bounds().min + half).norm(), 0.0, 1e-15);
    // Top annulus faces up, bottom faces down (no flipped triangle in a non-square block).
    for (std::uint32_t t = 0; t < block.triangleCount(); ++t) {
      const Vec3 n3 = block.triangleNormal(t);
      const double z = (block.corner(t, 0).z() + block.corner(t, 1).z() + block.corner(t, 2).z()) / 3;
      if (z == half.z()) {
        EXPECT_GT(n3.z(), 0.999) << "triangle " << t;
      } else if (z == -half.z()) {
        EXPECT_LT(n3.z(), -0.999) << "triangle " << t;
      }
    }
  }
}

TEST(PartMeshes, BowlIsAClosedShellBelowItsRim) {
  const double outer = 0.1, thickness = 0.01;
  const std::uint32_t segments = 48, rings = 12;
  const TriangleMesh bowl = makeBowl(outer, thickness, segments, rings);
  EXPECT_EQ(bowl.vertexCount(), 2 * (segments * rings + 1));
  EXPECT_EQ(bowl.triangleCount(), 4 * segments * rings);
  const double volume = expectClosedOrientedGenus(bowl, 0);
  const double inner = outer - thickness;
  const double shell = 2.0 / 3.0 * std::numbers::pi * (std::pow(outer, 3) - std::pow(inner, 3));
  // Inscribed: below the shell's volume, by about the polygon deficit 1 - sin(2 pi/s) s / (2 pi)
  // (0.29 % at 48) plus the rings' chord deficit (about as much): 1 % is a generous ceiling.
  EXPECT_LT(volume, shell);
  EXPECT_GT(volume, 0.99 * shell);
  EXPECT_NEAR(bowl.bounds().max.z(), 0.0, 1e-15);
  EXPECT_NEAR(bowl.bounds().min.z(), -outer, 1e-15);
}

TEST(PartMeshes, BadParametersNameTheParameter) {
  auto expectInvalid = [](auto make, const char* needle) {
    try {
      make();
      ADD_FAILURE() << "no error for " << needle;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectInvalid([] { makeTorus(0.01, 0.02, 16, 8); }, "minor radius");
  expectInvalid([] { makeTorus(0.03, 0.01, 2, 8); }, "major segments");
  expectInvalid([] { makeTorus(NAN, 0.01, 16, 8); }, "major radius");
  expectInvalid([] { makeBowl(0.1, 0.1, 16, 4); }, "thickness");
  expectInvalid([] { makeBowl(0.1, 0.01, 16, 1); }, "rings");
  expectInvalid([] { makeHoledBlock(Vec3(0.02, 0.02, 0.01), 0.02, 32); }, "does not fit");
  expectInvalid([] { makeHoledBlock(Vec3(0.02, 0.02, 0.01), 0.01, 36); }, "multiple of 8");
  expectInvalid([] { makeHoledBlock(Vec3(0.02, -1, 0.01), 0.01, 32); }, "half extent y");
}

}  // namespace
}  // namespace clod
