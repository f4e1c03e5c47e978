// Where two convex polyhedra touch at a corner or at crossing edges, the single contact lies at
// that corner or crossing (issue 18: a contact's point is where the penetration along its normal
// line is its depth). Oracle: the corner's and the edges' positions written down from the poses.
// Before, the point followed the bounding spheres' centre line: a cube standing on a corner 0.2
// off another cube's centre had its contact half way between the centre and the corner, so the
// one force holding it had half its true lever.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"
#include "support/grid_box.h"

namespace clod {
namespace {

using test::settingsFor;

constexpr double kPenetration = 0.01;

struct Cubes {
  CollisionBody plain = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
  // Faces split into 4 x 4 squares: the same convex polyhedron, many triangles per face.
  CollisionBody tessellated = test::makeTestBody(test::makeGridBox(Vec3::Constant(0.5), 4), 2);
};
const Cubes& cubes() {
  static const Cubes c;
  return c;
}

// Every model that answers two convex polyhedra from their faces, at a full and a small budget.
template <class Check>
void forEveryModel(const CollisionBody& cube, const Pose& poseA, const Pose& poseB, Check check) {
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree})
    for (std::uint64_t budget : {std::uint64_t(16), kUnlimitedTests}) {
      const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget);
      check(queryContacts(cube, poseA, cube, poseB, settingsFor(model, budget)), what);
    }
}

// Rounding only: the corner, the edges and the depth are exact in every model (error bound 0);
// 1e-9 of the diagonal.
constexpr double kRounding = 1e-9 * 1.7320508075688772;

// A cube (A) turned so that its corner (-1, -1, -1) / 2 points straight down stands on that corner
// p deep in the top face of the unit cube B at the origin, at several places on the face.
TEST(CornerEdgeContact, ACubeOnItsCornerGetsItsContactAtTheCorner) {
  const Quat cornerDown = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitZ());
  const double centreAboveCorner = 0.5 * std::sqrt(3.0);
  for (const CollisionBody* cube : {&cubes().plain, &cubes().tessellated})
    for (const Vec3& corner : {Vec3(0.2, 0.1, 0.0), Vec3(-0.35, 0.3, 0.0), Vec3(0.0, 0.0, 0.0), Vec3(0.45, -0.45, 0.0)}) {
      const Vec3 tip(corner.x(), corner.y(), 0.5 - kPenetration);
      const Pose poseA{cornerDown, tip + centreAboveCorner * Vec3::UnitZ()};
      ASSERT_LT((poseA.apply(Vec3(-0.5, -0.5, -0.5)) - tip).norm(), kRounding);
      forEveryModel(*cube, poseA, Pose{}, [&](const QueryResult& r, const std::string& what) {
        ASSERT_EQ(r.contacts.size(), 1u) << what;
        const Contact& c = r.contacts.front();
        EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kRounding) << what << ": normal " << c.normal.transpose();
        EXPECT_NEAR(c.depth, kPenetration, kRounding) << what;
        // Midway between the corner and the face it is pressed into, straight above the corner.
        EXPECT_LT((c.point - Vec3(tip.x(), tip.y(), 0.5 - 0.5 * kPenetration)).norm(), kRounding)
            << what << " at corner " << corner.transpose() << ": point " << c.point.transpose();
      });
    }
}

// B turned 45 degrees about y (its top edge along y at x = 0, z = sqrt(2)/2), A turned 45 degrees
// about x (its lowest edge along x at y = s_y), p deep: the edges cross at (0, s_y), the normal
// is their common perpendicular z.
TEST(CornerEdgeContact, CrossingEdgesGetTheirContactWhereTheyCross) {
  const Quat aboutX(Eigen::AngleAxisd(0.25 * M_PI, Vec3::UnitX()));
  const Quat aboutY(Eigen::AngleAxisd(0.25 * M_PI, Vec3::UnitY()));
  const double halfDiagonal = 0.5 * std::sqrt(2.0);
  for (const CollisionBody* cube : {&cubes().plain, &cubes().tessellated})
    for (const Vec3& shift : {Vec3(0.3, 0.2, 0.0), Vec3(-0.1, -0.4, 0.0), Vec3(0.0, 0.0, 0.0)}) {
      const Pose poseB{aboutY, Vec3::Zero()};
      const Pose poseA{aboutX, Vec3(shift.x(), shift.y(), 2.0 * halfDiagonal - kPenetration)};
      forEveryModel(*cube, poseA, poseB, [&](const QueryResult& r, const std::string& what) {
        ASSERT_EQ(r.contacts.size(), 1u) << what;
        const Contact& c = r.contacts.front();
        EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kRounding) << what << ": normal " << c.normal.transpose();
        EXPECT_NEAR(c.depth, kPenetration, kRounding) << what;
        EXPECT_LT((c.point - Vec3(0.0, shift.y(), halfDiagonal - 0.5 * kPenetration)).norm(), kRounding)
            << what << " at shift " << shift.transpose() << ": point " << c.point.transpose();
      });
    }
}

}  // namespace
}  // namespace clod
