// The manifold's support polygon (src/narrowphase/support_polygon.h) against analytic answers:
// a unit square of contacts 1 cm deep on the plane z = 0, normals +z.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "clod/contact.h"
#include "narrowphase/support_polygon.h"

namespace clod {
namespace {

Contact at(double x, double y, double depth, const Vec3& normal = Vec3::UnitZ()) {
  Contact c;
  c.point = Vec3(x, y, 0.0);
  c.normal = normal;
  c.depth = depth;
  return c;
}

// The square's four corners (and its centre, which the hull leaves inside), closed.
detail::SupportPolygon unitSquare(std::vector<double>& room) {
  room.assign(3 * 5, 0.0);
  detail::SupportPolygon polygon(Vec3::UnitZ(), room);
  for (const Contact& c : {at(0, 0, 0.01), at(1, 0, 0.01), at(0.5, 0.5, 0.01), at(1, 1, 0.01), at(0, 1, 0.01)})
    polygon.add(c);
  EXPECT_TRUE(polygon.close());
  return polygon;
}

TEST(SupportPolygon, ScoresAContactOutsideByHowFarOutsideItLies) {
  std::vector<double> room;
  const detail::SupportPolygon square = unitSquare(room);
  // 0.3 beyond the edge x = 1; 0.2 beyond y = 1 and 0.1 beyond x = 1: the larger counts.
  EXPECT_NEAR(square.pickScore(at(1.3, 0.5, 0.01), 99.0), 0.3, 1e-12);
  EXPECT_NEAR(square.pickScore(at(1.1, 1.2, 0.01), 99.0), 0.2, 1e-12);
}

TEST(SupportPolygon, AFlatContactInsideOrOnTheRimAddsNothing) {
  std::vector<double> room;
  const detail::SupportPolygon square = unitSquare(room);
  EXPECT_TRUE(square.addsNothing(at(0.3, 0.7, 0.01)));
  EXPECT_TRUE(square.addsNothing(at(1.0, 0.5, 0.01)));    // the middle of an edge
  EXPECT_TRUE(square.addsNothing(at(1.005, 0.5, 0.01)));  // 0.35 % of the extent (1.41) out: on the rim
  EXPECT_FALSE(square.addsNothing(at(1.03, 0.5, 0.01)));  // 2 % out: adds area
  // Depth: 1e-4 of the extent (1.4e-4) deeper is still on the depth plane; 1 mm deeper adds depth
  // and scores its spread; shallower adds nothing.
  EXPECT_TRUE(square.addsNothing(at(0.3, 0.7, 0.0101)));
  EXPECT_EQ(square.pickScore(at(0.3, 0.7, 0.011), 0.25), 0.25);
  EXPECT_TRUE(square.addsNothing(at(0.3, 0.7, 0.005)));
}

TEST(SupportPolygon, FollowsATiltedFacesDepthPlane) {
  // The same square tilted: depth 0.01 + 0.02 x. A contact inside on that plane adds nothing,
  // one 1 mm deeper than the plane adds depth, though both are shallower than the deepest corner.
  std::vector<double> room(15);
  detail::SupportPolygon polygon(Vec3::UnitZ(), room);
  for (const Contact& c : {at(0, 0, 0.01), at(1, 0, 0.03), at(1, 1, 0.03), at(0, 1, 0.01)}) polygon.add(c);
  ASSERT_TRUE(polygon.close());
  EXPECT_TRUE(polygon.addsNothing(at(0.5, 0.5, 0.02)));
  EXPECT_FALSE(polygon.addsNothing(at(0.5, 0.5, 0.021)));
}

TEST(SupportPolygon, HasNoSayOverContactsFacingAnotherWayOrWithoutAnArea) {
  std::vector<double> room;
  const detail::SupportPolygon square = unitSquare(room);
  // A wall's contact inside the floor's square, its normal 90 deg off; a curved patch's 2 deg off.
  EXPECT_EQ(square.pickScore(at(0.5, 0.5, 0.01, Vec3::UnitX()), 0.7), 0.7);
  EXPECT_EQ(square.pickScore(at(0.5, 0.5, 0.01, Vec3(std::sin(0.035), 0, std::cos(0.035))), 0.7), 0.7);
  // Contacts along one line span no area: nothing is inside.
  std::vector<double> lineRoom(9);
  detail::SupportPolygon line(Vec3::UnitZ(), lineRoom);
  for (const Contact& c : {at(0, 0, 0.01), at(0.5, 0, 0.01), at(1, 0, 0.01)}) line.add(c);
  EXPECT_FALSE(line.close());
  EXPECT_EQ(line.pickScore(at(0.5, 0, 0.01), 0.7), 0.7);
}

}  // namespace
}  // namespace clod
