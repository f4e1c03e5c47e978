// The faces that bound a soup's solid (solid_boundary.h), and the contact tree built over them,
// on two overlapping boxes: every answer is analytic.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "clod/contact_tree.h"
#include "clod/contact_tree_builder.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/solid_boundary.h"
#include "support/test_scale.h"

namespace clod {
namespace {

double boxDistance(const Vec3& p, const Vec3& centre, const Vec3& half) {
  const Vec3 q = (p - centre).cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

// A = [-0.5, 0.5]^3 and B = [0, 1] x [-0.25, 0.25]^2 as one triangle soup (24 triangles, two
// closed parts): B's face at x = 0 lies inside A, a wall with the solid on both sides. Every
// other face bounds the union somewhere (B's sides leave A at x = 0.5, A's face at x = 0.5 is
// covered by B only in its middle).
struct TwoBoxes {
  const Vec3 halfA{0.5, 0.5, 0.5}, centreB{0.5, 0.0, 0.0}, halfB{0.5, 0.25, 0.25};
  TriangleMesh soup;
  TwoBoxes() {
    soup = makeBox(halfA);
    const TriangleMesh b = makeBox(halfB);
    const auto offset = static_cast<std::uint32_t>(soup.vertices.size());
    for (const Vec3& v : b.vertices) soup.vertices.push_back(v + centreB);
    for (Triangle t : b.triangles) soup.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  // Exact outside the union (the nearer box's surface is the union's there).
  double outsideDistance(const Vec3& p) const {
    return std::min(boxDistance(p, Vec3::Zero(), halfA), boxDistance(p, centreB, halfB));
  }
};

// How deep a point of the soup's surface lies inside the other box (0 on the union's boundary:
// on one box's face and not inside the other).
double depthInsideOtherBox(const TwoBoxes& boxes, const Vec3& p) {
  return std::max(0.0, -std::min(boxDistance(p, Vec3::Zero(), boxes.halfA), boxDistance(p, boxes.centreB, boxes.halfB)));
}

double area(const TriangleMesh& mesh) {
  double twice = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) twice += mesh.triangleCross(t).norm();
  return 0.5 * twice;
}

TEST(SolidBoundary, KeepsTheUnionsSurfaceAndDropsTheWallsInside) {
  const TwoBoxes boxes;
  const double r = 0.01;
  const SolidBoundary boundary = solidBoundary(MeshDistance(boxes.soup), r, 0.1);
  ASSERT_TRUE(boundary.changed());
  EXPECT_EQ(boundary.droppedTriangles, 2u);  // B's face at x = 0
  // The union's surface: A's 6 faces less the 0.5 x 0.5 square B covers, and B's 4 sides and
  // end beyond x = 0.5. Wall pieces are left only along the crossing (B's 2 m perimeter at
  // x = 0.5, on A's face and on B's sides): at most r wide on each side of it.
  const double unionArea = 6.0 - 0.25 + 4 * 0.25 + 0.25;
  EXPECT_NEAR(area(boundary.mesh), unionArea, 2 * 2.0 * r);
  for (std::uint32_t t = 0; t < boundary.mesh.triangleCount(); ++t) {
    const Vec3 centroid = (boundary.mesh.corner(t, 0) + boundary.mesh.corner(t, 1) + boundary.mesh.corner(t, 2)) / 3.0;
    ASSERT_LE(depthInsideOtherBox(boxes, centroid), r) << centroid.transpose();
  }
}

TEST(SolidBoundary, KeepsEveryFaceOfAClosedMeshAndOfAnOpenOne) {
  TriangleMesh box = makeBox(Vec3(1.0, 0.5, 0.25));
  EXPECT_FALSE(solidBoundary(MeshDistance(box, MeshDistanceSettings{.forceWindingNumber = true}), 0.01, 0.1).changed());
  box.triangles.pop_back();  // a hole: every face still has the outside on one side
  EXPECT_FALSE(solidBoundary(MeshDistance(box), 0.01, 0.1).changed());
}

TEST(SolidBoundary, ACoarseContactTreeOfASoupBuilds) {
  // eps_s of 5 % of the diagonal is coarser than the boundary's sample spacing (1/64).
  ContactTreeSettings coarse;
  coarse.errorRel = 0.05;
  coarse.bandRel = 0.05;
  coarse.cubeMarginRel = 0.1;
  const ContactTree tree = buildContactTree(MeshDistance(TwoBoxes().soup), coarse);
  EXPECT_GT(tree.nodeCount(), 1u);
}

TEST(SolidBoundary, RejectsAResolutionOutOfRange) {
  const MeshDistance box(makeBox(Vec3::Ones()));
  EXPECT_THROW(solidBoundary(box, 0.0, 0.1), Error);
  EXPECT_THROW(solidBoundary(box, 0.2, 0.1), Error);
}

// The contact tree of the soup is the field of the union: outside, the nearer box's distance;
// on the wall inside A, the distance to A's faces (0.5 - max(|y|, |z|) deep), not the 0 of a
// surface, which a field over every face would report there with a tight bound.
TEST(SolidBoundary, ContactTreeOfASoupIsTheFieldOfItsSolid) {
  const TwoBoxes boxes;
  // Under the sanitizers a coarser tree (4e-3 of the diagonal, ~1/16 of the cells): the checks
  // below are against the tree's own errorAbs, so they hold at any eps.
  ContactTreeSettings settings;
  if (test::sanitizerRun()) settings.errorRel = 4e-3;
  const ContactTree tree = buildContactTree(MeshDistance(boxes.soup), settings);
  // The union's box is [-0.5, 1] x [-0.5, 0.5]^2. Stored corners are floats: 2^-23 of the
  // diagonal covers their rounding (as tests/contact_tree/contact_tree_box_test.cpp).
  const double diag = Vec3(1.5, 1.0, 1.0).norm();
  const double rounding = std::ldexp(diag, -23);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  int outside = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p(-0.55 + 1.6 * uni(rng), -0.55 + 1.1 * uni(rng), -0.55 + 1.1 * uni(rng));
    const double exact = boxes.outsideDistance(p);
    if (exact <= 0.0 || exact > tree.bandAbs) continue;
    ++outside;
    ASSERT_NEAR(tree.distance(p), exact, tree.errorAbs + rounding) << p.transpose();
  }
  EXPECT_GT(outside, 500);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p(0.02 * (uni(rng) - 0.5), 0.4 * (uni(rng) - 0.5), 0.4 * (uni(rng) - 0.5));
    const double exact = -(0.5 - std::max(std::abs(p.y()), std::abs(p.z())));
    const ContactFieldSample s = tree.sample(p);
    // Wall pieces may be left within eps of the crossings (solid_boundary.h), far from here.
    ASSERT_NEAR(s.distance, exact, s.errorBound + rounding) << p.transpose();
  }
}

}  // namespace
}  // namespace clod
