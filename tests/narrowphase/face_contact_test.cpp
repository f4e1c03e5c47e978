// Face-on-face contact between boxes: the manifold must span the overlap of the two faces (its
// corners), carry the face normal and the penetration, and never push along a flush side face --
// at every budget of the sphere models and in the exact model. Oracle: the analytic overlap
// rectangle of two axis-aligned boxes (and, for a box turned about the vertical, the analytic
// intersection of a square and a turned square's corners inside it).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::settingsFor;

constexpr double kDegree = 3.14159265358979323846 / 180.0;

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Boxes {
  // Unit cubes (half extent 0.5): two 12-triangle convex polyhedra.
  CollisionBody a = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
  CollisionBody b = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
};

const Boxes& boxes() {
  static const Boxes b;
  return b;
}

// Rounding of unit-box coordinates, with margin: 1e-9 of the diagonal (sqrt(3)).
constexpr double kRounding = 1e-9;

TEST(FaceContact, BoxesShiftedAlongOneAxisGetTheOverlapRectangleAndTheFaceNormal) {
  const Boxes& b = boxes();
  const double penetration = 0.01;
  // Shifted along x only: the faces at +-y are flush (coplanar, facing the same way); also along
  // both axes, and not at all.
  const std::vector<Vec3> shifts = {{0.3, 0.0, 0.0}, {0.0, -0.45, 0.0}, {0.3, 0.2, 0.0}, {0.0, 0.0, 0.0}};
  int checked = 0;
  for (const Vec3& shift : shifts) {
    const Pose poseA{Quat::Identity(), Vec3(shift.x(), shift.y(), 1.0 - penetration)};
    // The overlap rectangle of the two unit squares, and its corners.
    const double x0 = std::max(-0.5, shift.x() - 0.5), x1 = std::min(0.5, shift.x() + 0.5);
    const double y0 = std::max(-0.5, shift.y() - 0.5), y1 = std::min(0.5, shift.y() + 0.5);
    for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact}) {
      for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(16), std::uint64_t(256), kUnlimitedTests}) {
        const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget) +
                                 " shift " + std::to_string(shift.x()) + "," + std::to_string(shift.y());
        const QueryResult r = queryContacts(b.a, poseA, b.b, Pose{}, settingsFor(model, budget));
        // The rectangle's corners (merged across the frontier pairs that find them), and at
        // coarse levels possibly a contact inside it from a pair whose patches meet along an
        // edge, not face to face.
        ASSERT_GE(r.contacts.size(), 4u) << what;
        bool corner[2][2] = {{false, false}, {false, false}};
        for (const Contact& c : r.contacts) {
          ++checked;
          EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 0.01 * kDegree) << what << " " << c.normal.transpose() << " depth " << c.depth << " bound " << c.errorBound << " at " << c.point.transpose() << " level " << c.level;
          EXPECT_LE(std::abs(c.depth - penetration), c.errorBound + kRounding) << what;
          // The rectangle's corners come from the facing faces of two convex polyhedra: exact.
          const bool isCorner = (std::abs(c.point.x() - x0) < kRounding || std::abs(c.point.x() - x1) < kRounding) &&
                                (std::abs(c.point.y() - y0) < kRounding || std::abs(c.point.y() - y1) < kRounding);
          if (isCorner || model == ContactModel::kExact) {
            EXPECT_EQ(c.errorBound, 0.0) << what;
          }
          EXPECT_LE(std::abs(c.point.z() - (0.5 - 0.5 * penetration)), c.errorBound + kRounding) << what;  // midway
          const bool atX0 = std::abs(c.point.x() - x0) < kRounding, atX1 = std::abs(c.point.x() - x1) < kRounding;
          const bool atY0 = std::abs(c.point.y() - y0) < kRounding, atY1 = std::abs(c.point.y() - y1) < kRounding;
          EXPECT_TRUE(c.point.x() > x0 - kRounding && c.point.x() < x1 + kRounding && c.point.y() > y0 - kRounding &&
                      c.point.y() < y1 + kRounding)
              << what << " point " << c.point.transpose();
          if ((atX0 || atX1) && (atY0 || atY1)) corner[atX1][atY1] = true;
        }
        EXPECT_TRUE(corner[0][0] && corner[0][1] && corner[1][0] && corner[1][1]) << what;
      }
    }
  }
  EXPECT_GE(checked, 4 * 2 * 4 * 4);
}

// A box turned 30 degrees about the vertical on a box: the contact polygon is the overlap of the
// two squares, whose corners are the turned square's corners inside the lower square and the
// points where the two outlines cross. Checked: every contact lies in both squares and on the
// contact plane, the manifold's spread covers the overlap (its farthest contacts are as far
// apart as the overlap's diameter allows, 0.9 of it at least: at most 8 of its corners are kept),
// and the normal is the face normal.
TEST(FaceContact, TwistedBoxOnABoxSpansTheOverlapPolygon) {
  const Boxes& b = boxes();
  const double penetration = 0.005;
  const double angle = 30.0 * kDegree;
  const Quat turn(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
  const Pose poseA{turn, Vec3(0.1, 0.0, 1.0 - penetration)};
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact}) {
    for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(64), kUnlimitedTests}) {
      const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget);
      const QueryResult r = queryContacts(b.a, poseA, b.b, Pose{}, settingsFor(model, budget));
      ASSERT_GE(r.contacts.size(), 4u) << what;
      double spread = 0.0;
      for (const Contact& c : r.contacts) {
        EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 0.01 * kDegree) << what;
        EXPECT_NEAR(c.depth, penetration, kRounding) << what;
        EXPECT_NEAR(c.point.z(), 0.5 - 0.5 * penetration, kRounding) << what;
        // Inside the lower square, and inside the turned one (in its own frame).
        EXPECT_LE(std::max(std::abs(c.point.x()), std::abs(c.point.y())), 0.5 + kRounding) << what;
        const Vec3 local = turn.conjugate() * (c.point - poseA.translation);
        EXPECT_LE(std::max(std::abs(local.x()), std::abs(local.y())), 0.5 + kRounding) << what;
        for (const Contact& d : r.contacts) spread = std::max(spread, (c.point - d.point).norm());
      }
      // The overlap reaches from the lower square's corner (-0.5, -0.5)... at least across the
      // lower square's width: 1.0 (the turned square covers its centre line along x).
      EXPECT_GE(spread, 1.0) << what;
    }
  }
}

}  // namespace
}  // namespace clod
