// The contact tree at an unlimited budget finds the bodies' interpenetration wherever the exact
// model does. Its finished answers sample an inner cell pair only where a support point of one
// cell comes near the other body (docs/contact-tree.md, "A finished answer's inner pairs are
// gated by support points"), a heuristic that must not lose a contact region. Oracle: the exact
// model's triangle intersection (`colliding`) and the meshes' exact signed distance
// (MeshDistance), which share no code with the contact tree.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::settingsFor;

TEST(ContactTreeFullBudget, FindsTheInterpenetrationOfCurvedMeshesWhereverExactDoes) {
  const int poses = test::sanitizerRun() ? 2 : 40;
  const TriangleMesh bunnyMesh = test::loadUnitMesh("bunny-1500.obj");
  const TriangleMesh spotMesh = test::loadUnitMesh("spot.obj");
  const TriangleMesh boxMesh = makeBox(Vec3::Constant(0.5));
  const std::uint32_t depth = test::curvedMeshTestDepth();
  const CollisionBody bunny = test::makeTestBody(bunnyMesh, depth);
  const CollisionBody spot = test::makeTestBody(spotMesh, depth);
  const CollisionBody box = test::makeTestBody(boxMesh, depth);
  const MeshDistance bunnyField(bunnyMesh), spotField(spotMesh), boxField(boxMesh);
  struct PairCase {
    std::string name;
    const CollisionBody* a;
    const CollisionBody* b;
    const MeshDistance* fieldA;
    const MeshDistance* fieldB;
  };
  const std::vector<PairCase> pairs = {{"bunny-1500", &bunny, &bunny, &bunnyField, &bunnyField},
                                       {"spot", &spot, &spot, &spotField, &spotField},
                                       {"spot/bunny-1500", &spot, &bunny, &spotField, &bunnyField},
                                       {"box/bunny-1500", &box, &bunny, &boxField, &bunnyField}};
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  QueryScratch scratch;
  QueryResult result;
  for (const PairCase& pair : pairs) {
    const double diagonal = std::max(pair.a->diagonal(), pair.b->diagonal());
    for (int k = 0; k < poses; ++k) {
      // B turned at random and moved along a random direction to where the two touch (bisection
      // on the exact model), then 0.2-3 % of the diagonal deeper: a contact region from a spot to
      // a wide patch.
      const Pose turn = test::randomPose(rng, 0.0);
      const Vec3 dir = test::randomPose(rng, 1.0).translation.normalized();
      const QuerySettings exact = settingsFor(ContactModel::kExact, kUnlimitedTests);
      double lo = 0.0, hi = 2.0 * diagonal;
      for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        queryContacts(*pair.a, Pose{}, *pair.b, Pose{turn.rotation, mid * dir}, exact, scratch, result);
        (result.colliding ? lo : hi) = mid;
      }
      const Pose poseB{turn.rotation, (lo - (0.002 + 0.028 * unit(rng)) * diagonal) * dir};
      queryContacts(*pair.a, Pose{}, *pair.b, poseB, exact, scratch, result);
      ASSERT_TRUE(result.colliding) << pair.name << " pose " << k;
      queryContacts(*pair.a, Pose{}, *pair.b, poseB, settingsFor(ContactModel::kContactTree, kUnlimitedTests), scratch,
                    result);
      const std::string what = pair.name + " pose " + std::to_string(k);
      ASSERT_TRUE(result.finished) << what;
      const auto deepest = std::max_element(result.contacts.begin(), result.contacts.end(),
                                            [](const Contact& x, const Contact& y) { return x.depth < y.depth; });
      ASSERT_NE(deepest, result.contacts.end()) << what << ": no contact";
      EXPECT_GT(deepest->depth, 0.0) << what;
      // The deepest contact's point is where the bodies overlap: inside both within its error
      // bound plus the tree's field error (errorRel 2e-3 of the diagonal in the test bodies,
      // narrowphase_test_support.h), so 4e-3 of the diagonal beyond its bound.
      const double slack = deepest->errorBound + 4e-3 * diagonal;
      EXPECT_LT(pair.fieldA->signedDistance(deepest->point), slack) << what;
      EXPECT_LT(pair.fieldB->signedDistance(poseB.applyInverse(deepest->point)), slack) << what;
    }
  }
}

}  // namespace
}  // namespace clod
