// triangulatePolygon against oracles that do not share its code: the triangle count n - 2, the
// total (signed) area against the shoelace area of the polygon as drawn in 2D, and every
// triangle's centroid inside the polygon by a crossing-number test in the 2D drawing. The 2D
// polygons are embedded in 3D planes of arbitrary orientation and position, so the projection
// the triangulator chooses is never the one they were drawn in.
#include "mesh/polygon_triangulation.h"

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace clod::detail {
namespace {

struct Point {
  double x, y;
};
using Polygon2 = std::vector<Point>;

double shoelaceArea(const Polygon2& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Point& a = polygon[i];
    const Point& b = polygon[(i + 1) % polygon.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * twice;
}

// Crossing number: a ray towards +x crosses the boundary an odd number of times from inside.
bool insidePolygon(const Polygon2& polygon, Point p) {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Point& a = polygon[i];
    const Point& b = polygon[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) inside = !inside;
  }
  return inside;
}

// A plane in 3D: the 2D drawing's x and y axes, its normal, and an origin.
struct Plane {
  Vec3 origin, xAxis, yAxis, normal;
  Vec3 embed(Point p) const { return origin + p.x * xAxis + p.y * yAxis; }
  Point flatten(const Vec3& q) const { return {(q - origin).dot(xAxis), (q - origin).dot(yAxis)}; }
};

Plane randomPlane(std::mt19937& rng) {
  std::normal_distribution<double> gauss;
  const Quat rotation = Quat(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
  const Mat3 r = rotation.toRotationMatrix();
  return {Vec3(gauss(rng), gauss(rng), gauss(rng)) * 3.0, r.col(0), r.col(1), r.col(2)};
}

// `expectedCut`: kMonotone also accepts kConvexFan (random stars can come out convex).
void expectGoodTriangulation(const Polygon2& polygon, const std::string& name, std::mt19937& rng,
                             PolygonCut expectedCut = PolygonCut::kMonotone) {
  SCOPED_TRACE(name + " (" + std::to_string(polygon.size()) + " corners)");
  const Plane plane = randomPlane(rng);
  std::vector<Vec3> corners;
  for (const Point& p : polygon) corners.push_back(plane.embed(p));

  std::vector<Triangle> triangles;
  const PolygonCut cut = triangulatePolygon(corners, triangles);
  if (expectedCut == PolygonCut::kMonotone && cut == PolygonCut::kConvexFan) expectedCut = cut;
  EXPECT_EQ(cut, expectedCut);
  ASSERT_EQ(triangles.size(), polygon.size() - 2);

  double minX = polygon[0].x, maxX = minX, minY = polygon[0].y, maxY = minY;
  for (const Point& p : polygon) minX = std::min(minX, p.x), maxX = std::max(maxX, p.x), minY = std::min(minY, p.y), maxY = std::max(maxY, p.y);
  const double diagonal = std::hypot(maxX - minX, maxY - minY);
  const double reach = diagonal + plane.origin.norm();
  // Area tolerance: every coordinate carries a rounding error of a few ulps of its magnitude
  // (at most `reach`: the drawing's extent plus the plane's offset), from the embedding and from
  // the triangulator's own projection; each triangle's cross product then errs by a few ulps of
  // reach^2, and n - 2 of them add up. 64 n eps reach^2 bounds that with room to spare, and is
  // still far below the smallest triangle a missing or doubled piece would add or remove.
  const double tolerance = 64.0 * double(polygon.size()) * std::numeric_limits<double>::epsilon() * reach * reach;

  double signedArea = 0.0;
  std::size_t outside = 0, clockwise = 0, degenerate = 0;
  for (const Triangle& t : triangles) {
    for (std::uint32_t c : t) ASSERT_LT(c, polygon.size());
    const Vec3& a = corners[t[0]];
    const Vec3& b = corners[t[1]];
    const Vec3& c = corners[t[2]];
    const double area = 0.5 * (b - a).cross(c - a).dot(plane.normal);
    signedArea += area;
    if (area < -tolerance) ++clockwise;
    const Vec3 centroid = (a + b + c) / 3.0;
    if (std::abs(area) <= tolerance) ++degenerate;
    else if (!insidePolygon(polygon, plane.flatten(centroid))) ++outside;
  }
  EXPECT_NEAR(signedArea, shoelaceArea(polygon), tolerance);
  EXPECT_EQ(clockwise, 0u) << "triangles wound against the polygon";
  EXPECT_EQ(outside, 0u) << "triangles whose centroid is outside the polygon";
  // None of these polygons has a corner on a line through two others that a diagonal could
  // follow, so a zero-area triangle would be a mistake (e.g. a collinear corner cut off).
  EXPECT_EQ(degenerate, 0u) << "zero-area triangles";
}

Polygon2 regularPolygon(std::size_t n, double radius) {
  Polygon2 polygon;
  for (std::size_t i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * double(i) / double(n);
    polygon.push_back({radius * std::cos(angle), radius * std::sin(angle)});
  }
  return polygon;
}

// Star-shaped about the origin (every corner sees it): random radii at increasing angles.
Polygon2 randomStar(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> radius(0.2, 1.0);
  Polygon2 polygon;
  for (std::size_t i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * double(i) / double(n);
    const double r = radius(rng);
    polygon.push_back({r * std::cos(angle), r * std::sin(angle)});
  }
  return polygon;
}

// A comb: a base bar [0, teeth] x [0, 1] with `teeth` teeth [k, k + 0.5] x [1, 4] on top, each
// gap making two reflex corners. Exact coordinates: the tips, the gaps and the bar's left side
// have collinear corners on common lines, as real files do.
Polygon2 comb(std::size_t teeth) {
  Polygon2 polygon{{0, 0}, {double(teeth), 0}, {double(teeth), 1}};
  for (std::size_t k = teeth; k-- > 0;) {
    const double x = double(k);
    polygon.push_back({x + 0.5, 1.0});
    polygon.push_back({x + 0.5, 4.0});
    polygon.push_back({x, 4.0});
    polygon.push_back({x, 1.0});
  }
  return polygon;
}

// Teeth on both sides, pointing up and down, so the sweep meets split and merge corners in
// every direction whatever the projection.
Polygon2 doubleComb(std::size_t teeth) {
  Polygon2 polygon;
  for (std::size_t k = 0; k < teeth; ++k) {
    const double x = double(k);
    polygon.push_back({x, -1.0});
    polygon.push_back({x + 0.5, -3.0});
    polygon.push_back({x + 0.7, -1.0});
  }
  polygon.push_back({double(teeth), -1.0});
  for (std::size_t k = teeth; k-- > 0;) {
    const double x = double(k);
    polygon.push_back({x + 1.0, 1.0});
    polygon.push_back({x + 0.55, 3.0});  // not in line with the tooth below (see the oracle)
    polygon.push_back({x + 0.3, 1.0});
  }
  return polygon;
}

// A band wound `turns` times around the origin: out along the outer edge, back along the inner.
Polygon2 spiral(std::size_t samplesPerTurn, double turns) {
  const auto samples = static_cast<std::size_t>(samplesPerTurn * turns);
  auto at = [&](std::size_t i, double offset) {
    const double angle = 2.0 * std::numbers::pi * double(i) / double(samplesPerTurn);
    const double r = 1.0 + angle / (2.0 * std::numbers::pi) + offset;
    return Point{r * std::cos(angle), r * std::sin(angle)};
  };
  Polygon2 polygon;
  for (std::size_t i = 0; i <= samples; ++i) polygon.push_back(at(i, 0.0));    // outer edge, outwards
  for (std::size_t i = samples + 1; i-- > 0;) polygon.push_back(at(i, -0.5));  // inner edge, back in
  return polygon;
}

TEST(TriangulatePolygon, ConvexPolygonsAreFans) {
  std::mt19937 rng(1);
  for (std::size_t n : {4u, 5u, 17u, 1000u}) expectGoodTriangulation(regularPolygon(n, 2.0), "regular", rng, PolygonCut::kConvexFan);
  std::vector<Triangle> triangles;
  const std::vector<Vec3> square{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  EXPECT_EQ(triangulatePolygon(square, triangles), PolygonCut::kConvexFan);
  EXPECT_EQ(triangles, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}}));
}

TEST(TriangulatePolygon, StarShapedPolygonsStayInside) {
  std::mt19937 rng(2);
  for (std::size_t n : {5u, 12u, 100u, 5000u})
    for (int trial = 0; trial < 3; ++trial) expectGoodTriangulation(randomStar(n, rng), "random star", rng);
  Polygon2 fivePointed;
  for (std::size_t i = 0; i < 10; ++i) {
    const double angle = std::numbers::pi * double(i) / 5.0, r = i % 2 ? 0.4 : 1.0;
    fivePointed.push_back({r * std::cos(angle), r * std::sin(angle)});
  }
  expectGoodTriangulation(fivePointed, "five-pointed star", rng);
}

TEST(TriangulatePolygon, CombsWithManyReflexCornersStayInside) {
  std::mt19937 rng(3);
  for (std::size_t teeth : {1u, 2u, 7u, 300u}) {
    expectGoodTriangulation(comb(teeth), "comb", rng);
    expectGoodTriangulation(doubleComb(teeth), "double comb", rng);
  }
}

TEST(TriangulatePolygon, SpiralsStayInside) {
  std::mt19937 rng(4);
  expectGoodTriangulation(spiral(16, 1.5), "spiral", rng);
  expectGoodTriangulation(spiral(64, 5.0), "spiral", rng);
  expectGoodTriangulation(spiral(400, 12.0), "spiral", rng);
}

TEST(TriangulatePolygon, ClockwiseInputKeepsItsWinding) {
  // The same comb drawn clockwise: the triangles must be clockwise too (the face's winding is
  // what orients the mesh), i.e. counter-clockwise about the reversed normal.
  std::mt19937 rng(5);
  Polygon2 reversed = comb(5);
  std::reverse(reversed.begin(), reversed.end());
  Polygon2 mirrored;  // the reversed drawing seen from the other side is counter-clockwise again
  for (const Point& p : reversed) mirrored.push_back({-p.x, p.y});
  expectGoodTriangulation(mirrored, "mirrored comb", rng);
  std::vector<Vec3> corners;
  for (const Point& p : reversed) corners.push_back(Vec3(p.x, p.y, 0.0));
  std::vector<Triangle> triangles;
  triangulatePolygon(corners, triangles);
  for (const Triangle& t : triangles)
    EXPECT_LE((corners[t[1]] - corners[t[0]]).cross(corners[t[2]] - corners[t[0]]).z(), 0.0);
}

TEST(TriangulatePolygon, BadPolygonsStillGiveNMinusTwoTriangles) {
  auto countFor = [](const std::vector<Vec3>& corners) {
    std::vector<Triangle> triangles;
    triangulatePolygon(corners, triangles);
    for (const Triangle& t : triangles)
      for (std::uint32_t c : t) EXPECT_LT(c, corners.size());
    return triangles.size();
  };
  const std::vector<Vec3> bowTie{Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.5, 2, 0)};
  EXPECT_EQ(countFor(bowTie), 3u);
  const std::vector<Vec3> collinear{Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3)};
  EXPECT_EQ(countFor(collinear), 2u);
  const std::vector<Vec3> repeated{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(0, 0, 0)};
  EXPECT_EQ(countFor(repeated), 4u);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Vec3> withNan{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(nan, 1, 0), Vec3(0, 1, 0)};
  EXPECT_EQ(countFor(withNan), 2u);
  // A pentagram turns left at every corner but winds twice: not convex, not simple.
  std::vector<Vec3> pentagram;
  for (int i = 0; i < 5; ++i) {
    const double angle = 4.0 * std::numbers::pi * i / 5.0;
    pentagram.push_back(Vec3(std::cos(angle), std::sin(angle), 0.0));
  }
  EXPECT_EQ(countFor(pentagram), 3u);
  // Random self-intersecting walks: whatever comes out, n - 2 valid triangles and no crash.
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vec3> walk(4 + trial % 50);
    for (Vec3& p : walk) p = Vec3(coordinate(rng), coordinate(rng), 0.01 * coordinate(rng));
    EXPECT_EQ(countFor(walk), walk.size() - 2);
  }
}

}  // namespace
}  // namespace clod::detail
