// The exact model's traversal against brute force over all triangle pairs: the sphere-trees may
// only prune pairs that cannot intersect, so both find the same set of intersecting pairs.

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase/triangle_intersection.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

std::vector<std::array<std::uint32_t, 2>> bruteForce(const TriangleMesh& a, const Pose& xfWorldFromA,
                                                     const TriangleMesh& b, const Pose& xfWorldFromB) {
  std::vector<Vec3> wa(a.vertices.size()), wb(b.vertices.size());
  for (std::size_t i = 0; i < wa.size(); ++i) wa[i] = xfWorldFromA.apply(a.vertices[i]);
  for (std::size_t i = 0; i < wb.size(); ++i) wb[i] = xfWorldFromB.apply(b.vertices[i]);
  std::vector<std::array<std::uint32_t, 2>> hits;
  narrowphase::TriangleIntersection out;
  for (std::uint32_t i = 0; i < a.triangleCount(); ++i) {
    const Triangle& ta = a.triangles[i];
    for (std::uint32_t j = 0; j < b.triangleCount(); ++j) {
      const Triangle& tb = b.triangles[j];
      if (narrowphase::intersectTriangles(wa[ta[0]], wa[ta[1]], wa[ta[2]], wb[tb[0]], wb[tb[1]], wb[tb[2]], 1e-12, out)) {
        hits.push_back({i, j});
      }
    }
  }
  return hits;
}

TEST(ExactModel, FindsTheSameIntersectingTrianglePairsAsBruteForce) {
  // The bunny (1,499 triangles, scaled to unit size) against an icosphere and a box.
  const TriangleMesh bunny = test::loadUnitMesh("bunny-1500.obj");
  // The exact model needs neither closest feature maps nor contact trees.
  const CollisionBody bunnyBody = test::makeTestBody(bunny, 3, false, false);
  const CollisionBody sphere = test::makeTestBody(makeIcosphere(0.3, 3), 2, false, false);
  const CollisionBody cube = test::makeTestBody(makeBox(Vec3(0.3, 0.2, 0.25)), 2, false, false);
  std::mt19937_64 rng(5);
  const int poses = test::sanitizerRun() ? 3 : 12;
  int colliding = 0;
  for (int k = 0; k < poses; ++k) {
    const CollisionBody& other = (k % 2) ? sphere : cube;
    const Pose poseA = test::randomPose(rng, 0.1);
    const Pose poseB = test::randomPose(rng, 0.4);
    QuerySettings settings;
    settings.model = ContactModel::kExact;
    const QueryResult r = queryContacts(bunnyBody, poseA, other, poseB, settings);
    ASSERT_TRUE(r.finished);
    const auto expected = bruteForce(bunnyBody.mesh(), poseA, other.mesh(), poseB);
    EXPECT_EQ(r.colliding, !expected.empty()) << "pose " << k;
    EXPECT_EQ(r.intersectingTriangles, expected) << "pose " << k;
    EXPECT_LT(r.triangleTests, std::uint64_t{bunnyBody.mesh().triangleCount()} * other.mesh().triangleCount());
    colliding += expected.empty() ? 0 : 1;
  }
  EXPECT_GE(colliding, poses / 3);  // the poses exercise both answers
}

}  // namespace
}  // namespace clod
