// A box standing over an edge of the body under it, and an open mesh on a closed body's floor: a table's edge (an open two-triangle floor),
// the end of a closed L-shaped body's floor, and a box on that floor flush with its side face.
// The overlap of the box's underside with the floor is a rectangle two of whose corners are no
// body's vertex: they lie where the box's underside crosses the floor's edge. With the box's
// inner corners alone the box turned about them and fell off, with cfm at every budget and exact
// at limited ones (and on the L at an unlimited budget). Oracle, by construction: the floor is
// the plane z = 0, so each corner of the overlap rectangle is a contact pushing the box straight
// up by its sink.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "clod/collision_body.h"
#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"
#include "support/floor_quad.h"
#include "support/l_shaped_body.h"

namespace clod {
namespace {

using test::settingsFor;

constexpr double kSunk = 0.002;
constexpr double kHalf = 0.25;  // the box's half side

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Overhang {
  std::string name;
  const CollisionBody* floor;
  Vec3 centre;                      // the box's centre, sunk kSunk into the floor's top (z = 0)
  std::array<Eigen::Vector2d, 4> corners;  // the overlap rectangle's corners (x, y)
};

// cfm at budgets from the roots' answer to unlimited, and exact where it answers from the spheres
// (1 test: every pair falls back to cfm) and where it finishes (between, some triangle pairs are
// tested and their partial patches are not this test's subject), both body orders: each contact
// pushes the box straight up by kSunk, and each corner of the overlap has one.
void expectOverlapCorners(const Overhang& o, const CollisionBody& box) {
  // Plane distances, ray hits and clip points from exact corners: rounding only.
  const double rounding = 1e-9 * (o.floor->diagonal() + box.diagonal());
  const Pose pose{Quat::Identity(), Vec3(o.centre.x(), o.centre.y(), kHalf - kSunk)};
  for (const ContactModel model : {ContactModel::kCfm, ContactModel::kExact}) {
    for (const std::uint64_t budget : {std::uint64_t(1), std::uint64_t(16), std::uint64_t(256), kUnlimitedTests}) {
      if (model == ContactModel::kExact && budget != 1 && budget != kUnlimitedTests) continue;
      for (const bool floorIsA : {true, false}) {
        const QueryResult r = floorIsA ? queryContacts(*o.floor, Pose{}, box, pose, settingsFor(model, budget))
                                       : queryContacts(box, pose, *o.floor, Pose{}, settingsFor(model, budget));
        const std::string what = o.name + ", " + std::string(contactModelName(model)) + " at " + std::to_string(budget) +
                                 (floorIsA ? ", floor is A" : ", floor is B");
        std::array<bool, 4> found{};
        for (const Contact& c : r.contacts) {
          const Vec3 up = floorIsA ? Vec3(-c.normal) : c.normal;  // the box's way out
          const Vec3& at = c.point;  // world frame
          EXPECT_LT(angleBetween(up, Vec3::UnitZ()), 1e-6) << what << ": contact at " << at.transpose();
          EXPECT_NEAR(c.depth, kSunk, rounding) << what << ": contact at " << at.transpose();
          for (std::size_t k = 0; k < 4; ++k)
            if ((Eigen::Vector2d(at.x(), at.y()) - o.corners[k]).norm() < rounding) found[k] = true;
        }
        for (std::size_t k = 0; k < 4; ++k)
          EXPECT_TRUE(found[k]) << what << ": no contact at the overlap's corner " << o.corners[k].transpose() << " ("
                                << r.contacts.size() << " contacts)";
      }
    }
  }
}

TEST(EdgeOverhang, BoxOverATwoTriangleFloorsEdgeGetsItsOverlapsCorners) {
  static const CollisionBody floor = test::octreeBodyForCfm(test::makeFloorQuad(1.0, 1.0));
  static const CollisionBody box = test::octreeBodyForCfm(makeBox(Vec3::Constant(kHalf)));
  // Over the edge y = 1 by 0.2; over the corner (1, 1) by 0.1 along x and 0.2 along y.
  expectOverlapCorners({"over an edge", &floor, Vec3(0.5, 0.95, 0.0), {Eigen::Vector2d(0.25, 0.7), Eigen::Vector2d(0.75, 0.7), Eigen::Vector2d(0.25, 1.0), Eigen::Vector2d(0.75, 1.0)}},
                       box);
  expectOverlapCorners({"over a corner", &floor, Vec3(0.85, 0.95, 0.0), {Eigen::Vector2d(0.6, 0.7), Eigen::Vector2d(1.0, 0.7), Eigen::Vector2d(0.6, 1.0), Eigen::Vector2d(1.0, 1.0)}},
                       box);
}

// A floor of 0.5 m squares (8 x 8 m, an octree of 1 m leaves): the box's inner corners lie over
// the leaf next to the one holding the floor's edge. The crossing followed the inner corner's
// leaf only and stopped at its border, 1 m inside the edge, and the overlap's corners on the edge
// got no contact (cfm; exact where it falls back to it).
TEST(EdgeOverhang, BoxOverATessellatedFloorsEdgeGetsItsOverlapsCornersFromAnotherLeaf) {
  static const CollisionBody floor = test::octreeBodyForCfm(test::makeFloorGrid(4.0, 4.0, 16));
  static const CollisionBody box = test::octreeBodyForCfm(makeBox(Vec3(0.6, kHalf, kHalf)));
  // Over the edge x = -4 by 0.1: x in [-4.1, -2.9], y in [0.3, 0.8] (between grid lines).
  expectOverlapCorners({"over a grid floor's edge", &floor, Vec3(-3.5, 0.55, 0.0), {Eigen::Vector2d(-4.0, 0.3), Eigen::Vector2d(-2.9, 0.3), Eigen::Vector2d(-4.0, 0.8), Eigen::Vector2d(-2.9, 0.8)}},
                       box);
}

TEST(EdgeOverhang, BoxOverTheEndOfAClosedBodysFloorGetsItsOverlapsCorners) {
  // The L's floor: x in [-2, 1] in front of its wall, y in [-2, 2], top z = 0 (l_shaped_body.h).
  static const CollisionBody l = test::octreeBodyForCfm(test::makeLShapedBody());
  static const CollisionBody box = test::octreeBodyForCfm(makeBox(Vec3::Constant(kHalf)));
  ASSERT_TRUE(l.isClosed());
  ASSERT_FALSE(l.isConvexPolyhedron());
  expectOverlapCorners({"over the floor's edge", &l, Vec3(-1.0, 1.95, 0.0), {Eigen::Vector2d(-1.25, 1.7), Eigen::Vector2d(-0.75, 1.7), Eigen::Vector2d(-1.25, 2.0), Eigen::Vector2d(-0.75, 2.0)}},
                       box);
  // Flush with the L's side face y = 2: the box's +y corners lie on that face, where the L's field
  // is 0 (they were not inside, and the box got no contact at all at 1-24 tests).
  expectOverlapCorners({"flush with the side face", &l, Vec3(-1.0, 1.75, 0.0), {Eigen::Vector2d(-1.25, 1.5), Eigen::Vector2d(-0.75, 1.5), Eigen::Vector2d(-1.25, 2.0), Eigen::Vector2d(-0.75, 2.0)}},
                       box);
}

// An open mesh (bunny-1500: holes in its base) sunk 1 cm into the floor of a closed body with a
// wall (the L), away from the wall: the pair got the hulls' answer, whose pocket is the floor, and
// was pushed down through it (dropped, the bunny fell 2-6 diagonals through a stair-like floor at
// 16-64 tests per frame, cfm and exact). Its vertices inside the L now hold it. Oracle: below the
// floor's top face and far from every other face, the L's field is that face's: each contact
// pushes straight up by its vertex's depth, the deepest by the sink.
TEST(EdgeOverhang, AnOpenMeshSunkIntoAClosedBodysFloorIsPushedStraightUp) {
  static const CollisionBody l = test::octreeBodyForCfm(test::makeLShapedBody());
  TriangleMesh bunny = test::loadUnitMesh("bunny-1500.obj");
  static const CollisionBody body = test::octreeBodyForCfm(bunny);
  ASSERT_FALSE(body.isClosed());
  double lowest = INFINITY;
  for (const Vec3& v : bunny.vertices) lowest = std::min(lowest, v.z());
  constexpr double kDeep = 0.01;
  const Pose pose{Quat::Identity(), Vec3(-1.0, 0.0, -lowest - kDeep)};
  const double rounding = 1e-9 * (l.diagonal() + body.diagonal());  // vertex transforms
  for (const ContactModel model : {ContactModel::kCfm, ContactModel::kExact}) {
    for (const std::uint64_t budget : {std::uint64_t(1), std::uint64_t(4), std::uint64_t(16), std::uint64_t(64)}) {
      if (model == ContactModel::kExact && budget > 16) continue;  // its triangle tests begin
      for (const bool floorIsA : {true, false}) {
        const QueryResult r = floorIsA ? queryContacts(l, Pose{}, body, pose, settingsFor(model, budget))
                                       : queryContacts(body, pose, l, Pose{}, settingsFor(model, budget));
        const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget) +
                                 (floorIsA ? ", the L is A" : ", the L is B");
        ASSERT_FALSE(r.contacts.empty()) << what;
        double deepest = 0.0;
        for (const Contact& c : r.contacts) {
          const Vec3 up = floorIsA ? Vec3(-c.normal) : c.normal;  // the bunny's way out
          EXPECT_LT(angleBetween(up, Vec3::UnitZ()), 1e-6) << what << ": contact at " << c.point.transpose();
          EXPECT_LE(c.depth, kDeep + rounding) << what;
          deepest = std::max(deepest, c.depth);
        }
        EXPECT_NEAR(deepest, kDeep, rounding) << what;
      }
    }
  }
}

}  // namespace
}  // namespace clod
