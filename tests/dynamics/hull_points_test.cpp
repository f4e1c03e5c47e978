// HullPoints (src/dynamics/hull_points.h) against brute force over every vertex of the mesh: the
// hull's box under a random turn and its farthest points along random directions. A box's hull is
// its whole convex body (exact, no slack); bunny-1500's is its support vertices, which reach the
// true hull to within their slack (CollisionBody::sphereSupportSlack).
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "dynamics/hull_points.h"
#include "world_test_support.h"

namespace clod {
namespace {

Mat3 randomTurn(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

void expectAgreesWithBruteForce(const CollisionBody& shape, const std::string& what) {
  const detail::HullPoints hull(shape);
  ASSERT_FALSE(hull.empty()) << what;
  const auto& vertices = shape.mesh().vertices;
  // Rounding of a dot product of coordinates of the size of the mesh: 1e-12 of its diagonal.
  const double tolerance = 1e-12 * shape.diagonal() + hull.slack();
  std::mt19937 rng(7);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 m = randomTurn(rng);
    const Vec3 t(n(rng), n(rng), n(rng));
    Aabb brute;
    for (const Vec3& v : vertices) brute.extend(m * v + t);
    const Aabb box = *hull.boxUnder(m, t);
    for (int k = 0; k < 3; ++k) {
      // The hull's box holds every vertex and reaches no farther than the slack past them.
      EXPECT_LE(box.min[k], brute.min[k] + 1e-12 * shape.diagonal()) << what;
      EXPECT_GE(box.min[k], brute.min[k] - tolerance) << what;
      EXPECT_GE(box.max[k], brute.max[k] - 1e-12 * shape.diagonal()) << what;
      EXPECT_LE(box.max[k], brute.max[k] + tolerance) << what;
    }
    std::array<Vec3, 5> directions;
    for (Vec3& d : directions) d = Vec3(n(rng), n(rng), n(rng)).normalized();
    const std::array<Vec3, 5> farthest = hull.farthestAlong(directions, 5);
    for (std::size_t k = 0; k < 5; ++k) {
      double reach = -std::numeric_limits<double>::infinity();
      for (const Vec3& v : vertices) reach = std::max(reach, directions[k].dot(v));
      const double found = directions[k].dot(farthest[k]);
      EXPECT_LE(found, reach + 1e-12 * shape.diagonal()) << what;  // a point of the mesh
      EXPECT_GE(found, reach - tolerance) << what;                  // and the farthest, to the slack
    }
  }
}

TEST(HullPoints, BoxAndFarthestPointsAgreeWithEveryVertex) {
  expectAgreesWithBruteForce(*test::bakeWorldShape(makeBox(Vec3(0.3, 0.5, 0.2))), "box");
  const TriangleMesh bunny = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/bunny-1500.obj").mesh;
  expectAgreesWithBruteForce(*test::bakeWorldShape(bunny), "bunny-1500");
}

}  // namespace
}  // namespace clod
