// Manifold reduction against analytic answers.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "clod/contact.h"
#include "clod/error.h"

namespace clod {
namespace {

Contact at(double x, double y, double depth) {
  Contact c;
  c.point = Vec3(x, y, 0.0);
  c.normal = Vec3::UnitZ();
  c.depth = depth;
  return c;
}

TEST(ReduceManifold, KeepsTheDeepestThenTheCornersOfASquareGrid) {
  // An 11 x 11 grid on [0,1]^2; the deepest contact is the centre. Farthest-point sampling from
  // the centre picks the four corners next (all at distance sqrt(2)/2, the largest).
  std::vector<Contact> contacts;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) contacts.push_back(at(0.1 * i, 0.1 * j, (i == 5 && j == 5) ? 0.2 : 0.1));
  std::vector<double> scratch;
  const std::size_t n = reduceManifold(contacts, {5, 0.0}, scratch);
  ASSERT_EQ(n, 5u);
  EXPECT_EQ(contacts[0].point, Vec3(0.5, 0.5, 0.0));
  for (std::size_t i = 1; i < 5; ++i) {
    EXPECT_NEAR(std::abs(contacts[i].point.x() - 0.5), 0.5, 1e-12);
    EXPECT_NEAR(std::abs(contacts[i].point.y() - 0.5), 0.5, 1e-12);
  }
}

TEST(ReduceManifold, KeepsTheFourCornersOfARectangleWhoseDeepestContactLiesNearOne) {
  // A 0.7 x 1 overlap sampled every 5 cm, the deepest sample 3.6 cm from the corner (0, 0): the
  // four kept contacts lie at the four corners. (Farthest-point sampling alone kept the middle
  // of the long side x = 0.7, 0.3 from the corner (0.7, 0).)
  std::vector<Contact> contacts;
  for (int i = 0; i <= 14; ++i)
    for (int j = 0; j <= 20; ++j) contacts.push_back(at(0.05 * i, 0.05 * j, 0.1));
  contacts.push_back(at(0.03, 0.02, 0.2));
  std::vector<double> scratch;
  const std::size_t n = reduceManifold(contacts, {4, 0.0}, scratch);
  ASSERT_EQ(n, 4u);
  for (const Vec3& corner : {Vec3(0.0, 0.0, 0.0), Vec3(0.7, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), Vec3(0.7, 1.0, 0.0)}) {
    double nearest = 1e9;
    for (std::size_t i = 0; i < n; ++i) nearest = std::min(nearest, (contacts[i].point - corner).norm());
    EXPECT_LT(nearest, 0.04) << "corner " << corner.transpose();  // the deepest stands for (0, 0)
  }
}

TEST(ReduceManifold, KeepsBothEndsOfAnEdgeLyingFlatWhateverTheOrder) {
  // 29 vertices of an edge lying flat, all equally deep (a fandisk's bottom edge on a box), in
  // every rotation of their order: both ends are always kept. (Input order broke the depth tie
  // before: starting from the second vertex, farthest-point sampling never went back 1 cm to the
  // end, and two models finding the same vertices kept different supports.)
  std::vector<Contact> edge;
  for (int i = 0; i <= 28; ++i) edge.push_back(at(0.01 * i, 0.0, 0.001));
  std::vector<double> scratch;
  for (std::size_t shift = 0; shift < edge.size(); ++shift) {
    std::vector<Contact> contacts = edge;
    std::rotate(contacts.begin(), contacts.begin() + static_cast<std::ptrdiff_t>(shift), contacts.end());
    const std::size_t n = reduceManifold(contacts, {8, 0.0}, scratch);
    ASSERT_EQ(n, 8u);
    for (const double end : {0.0, 0.28}) {
      double nearest = 1e9;
      for (std::size_t i = 0; i < n; ++i) nearest = std::min(nearest, std::abs(contacts[i].point.x() - end));
      EXPECT_LT(nearest, 1e-12) << "end " << end << ", order rotated by " << shift;
    }
  }
}

TEST(ReduceManifold, MergesCoincidentContactsAndMeasuresInTheContactPlane) {
  // Five copies of two spots, stacked along the normal at different depths: two contacts remain.
  std::vector<Contact> contacts;
  for (int k = 0; k < 5; ++k) {
    Contact c = at(0.0, 0.0, 0.1 + 0.01 * k);
    c.point.z() = -0.01 * k;
    contacts.push_back(c);
    contacts.push_back(at(1.0, 0.0, 0.05));
  }
  std::vector<double> scratch;
  const std::size_t n = reduceManifold(contacts, {8, 1e-3}, scratch);
  ASSERT_EQ(n, 2u);
  EXPECT_DOUBLE_EQ(contacts[0].depth, 0.14);
  EXPECT_NEAR(contacts[1].point.x(), 1.0, 1e-15);
}

// A floor's contacts beside a deeper one on a wall (a cube on a slab with a block pressing its
// side, normals +z and -x): the floor's two corners at x = -1 and x = +1 lie on one line along
// the wall's normal, one spot in its plane, but they are opposite corners of the floor contact,
// 2 apart: both stay (before, the farther corner was merged away as a duplicate). Contacts
// stacked along the normal of a face they lie on still merge (the test above).
TEST(ReduceManifold, KeepsAFaceCornersThatLineUpAlongAPerpendicularDeeperNormal) {
  Contact wall = at(1.0, 0.0, 0.04);
  wall.point.z() = 0.5;
  wall.normal = -Vec3::UnitX();
  std::vector<Contact> contacts = {wall, at(1.0, 1.0, 0.01), at(-1.0, 1.0, 0.01)};
  std::vector<double> scratch;
  ASSERT_EQ(reduceManifold(contacts, {8, 1e-3}, scratch), 3u);
  EXPECT_EQ(contacts[0].normal, -Vec3::UnitX());
  EXPECT_NEAR(std::abs(contacts[1].point.x() - contacts[2].point.x()), 2.0, 1e-15);
}

// A face lying flat on a face, sampled as the contact tree samples it: a 0.83 x 0.27 lattice whose
// depths differ by field noise (+-2e-8 m around 3e-8), far below anything the solver can act on.
// Only the overlap's four corners are kept: the interior samples add no support area and no
// depth. Before, farthest-point picks filled the manifold's 8 places with interior samples chosen
// by that noise, which loaded the face unevenly (a box spinning on a floor drifted 12 cm).
TEST(ReduceManifold, KeepsOnlyTheCornersOfAFlatFaceWhoseDepthsDifferByNoise) {
  const double hx = 0.415, hy = 0.135;
  std::vector<Contact> contacts;
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 6; ++j) {
      const double noise = 2e-8 * std::sin(12.9898 * i + 78.233 * j);  // deterministic, |noise| <= 2e-8
      contacts.push_back(at(-hx + 2 * hx * i / 16, -hy + 2 * hy * j / 6, 3e-8 + noise));
    }
  std::vector<double> scratch;
  const std::size_t n = reduceManifold(contacts, {8, 1e-3}, scratch);
  ASSERT_EQ(n, 4u);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(std::abs(contacts[i].point.x()), hx, 1e-12);
    EXPECT_NEAR(std::abs(contacts[i].point.y()), hy, 1e-12);
  }
  // One corner each.
  std::vector<int> quadrants;
  for (std::size_t i = 0; i < n; ++i) quadrants.push_back((contacts[i].point.x() > 0) * 2 + (contacts[i].point.y() > 0));
  std::sort(quadrants.begin(), quadrants.end());
  EXPECT_EQ(quadrants, (std::vector<int>{0, 1, 2, 3}));
}

// The same face over two bumps: the deepest contact (2 mm above the face's depth) and a second
// bump (1.5 mm) inside the corners' polygon. The second adds depth -- the plane through the kept
// contacts' depths lies below it -- so it is kept beside the corners.
TEST(ReduceManifold, KeepsAnInteriorContactDeeperThanTheFacesPlane) {
  std::vector<Contact> contacts;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) contacts.push_back(at(0.1 * i, 0.1 * j, 0.001));
  contacts.push_back(at(0.3, 0.4, 0.003));
  contacts.push_back(at(0.7, 0.6, 0.0025));
  std::vector<double> scratch;
  const std::size_t n = reduceManifold(contacts, {8, 1e-3}, scratch);
  ASSERT_GE(n, 6u);
  EXPECT_EQ(contacts[0].point, Vec3(0.3, 0.4, 0.0));
  bool secondBump = false;
  int corners = 0;
  for (std::size_t i = 1; i < n; ++i) {
    secondBump = secondBump || contacts[i].point == Vec3(0.7, 0.6, 0.0);
    corners += std::abs(contacts[i].point.x() - 0.5) > 0.499 && std::abs(contacts[i].point.y() - 0.5) > 0.499;
  }
  EXPECT_TRUE(secondBump);
  EXPECT_EQ(corners, 4);
}

// Two unit squares overlapping with one turned 45 deg: the overlap is a regular octagon, sampled
// on a lattice plus its corners, all equally deep. Its eight corners are the support polygon and
// all eight are kept (each lies outside the polygon of the others).
TEST(ReduceManifold, KeepsTheEightCornersOfAnOctagonalOverlap) {
  const double r = 0.5 / std::cos(M_PI / 8);  // circumradius of the octagon of inradius 0.5
  std::vector<Contact> contacts;
  auto inside = [&](double x, double y) {
    return std::abs(x) <= 0.5 && std::abs(y) <= 0.5 && std::abs(x + y) <= 0.5 * std::sqrt(2.0) &&
           std::abs(x - y) <= 0.5 * std::sqrt(2.0);
  };
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j)
      if (inside(0.05 * i, 0.05 * j)) contacts.push_back(at(0.05 * i, 0.05 * j, 0.01));
  for (int k = 0; k < 8; ++k) contacts.push_back(at(r * std::cos(M_PI / 8 + k * M_PI / 4), r * std::sin(M_PI / 8 + k * M_PI / 4), 0.01));
  std::vector<double> scratch;
  const std::size_t n = reduceManifold(contacts, {8, 1e-3}, scratch);
  ASSERT_EQ(n, 8u);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(contacts[i].point.norm(), r, 1e-12) << i;
}

TEST(ReduceManifold, RejectsBadSettings) {
  std::vector<Contact> contacts{at(0, 0, 0)};
  std::vector<double> scratch;
  EXPECT_THROW(reduceManifold(contacts, {0, 0.0}, scratch), Error);
  EXPECT_THROW(reduceManifold(contacts, {4, -1.0}, scratch), Error);
  EXPECT_EQ(reduceManifold(std::span<Contact>(), {4, 0.0}, scratch), 0u);
}

TEST(ReduceManifold, PoolsNormalsOfTheContactsAKeptContactStandsForWithinTheCone) {
  // Two kept contacts: the deepest at the origin and the farthest at (1, 0). Not kept: one at
  // (0.05, 0) tilted 20 deg about x (pooled into the first: the depth-weighted mean of the two
  // normals, an analytic answer), and one at (0.95, 0) tilted 80 deg (a wall next to the floor:
  // outside the 60 deg cone of both kept contacts, so it changes nothing).
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  const Vec3 tilted20(0.0, -std::sin(20.0 * kDeg), std::cos(20.0 * kDeg));
  const Vec3 tilted80(0.0, -std::sin(80.0 * kDeg), std::cos(80.0 * kDeg));
  std::vector<Contact> contacts = {at(0.0, 0.0, 0.2), at(1.0, 0.0, 0.1), at(0.05, 0.0, 0.1), at(0.95, 0.0, 0.05)};
  contacts[2].normal = tilted20;
  contacts[3].normal = tilted80;
  std::vector<double> scratch;
  ManifoldSettings settings;
  settings.maxContacts = 2;
  settings.poolNormalsCos = 0.5;  // 60 deg
  ASSERT_EQ(reduceManifold(contacts, settings, scratch), 2u);
  EXPECT_EQ(contacts[0].point, Vec3(0.0, 0.0, 0.0));
  EXPECT_EQ(contacts[1].point, Vec3(1.0, 0.0, 0.0));
  const Vec3 expected = (0.2 * Vec3::UnitZ() + 0.1 * tilted20).normalized();
  EXPECT_LT((contacts[0].normal - expected).norm(), 1e-12);  // rounding only
  EXPECT_EQ(contacts[1].normal, Vec3::UnitZ());
  EXPECT_EQ(contacts[0].depth, 0.2);  // depths and points are not pooled
  // Off (the default): the kept normals are the contacts' own.
  contacts = {at(0.0, 0.0, 0.2), at(1.0, 0.0, 0.1), at(0.05, 0.0, 0.1), at(0.95, 0.0, 0.05)};
  contacts[2].normal = tilted20;
  settings.poolNormalsCos = 2.0;
  ASSERT_EQ(reduceManifold(contacts, settings, scratch), 2u);
  EXPECT_EQ(contacts[0].normal, Vec3::UnitZ());
}

}  // namespace
}  // namespace clod
