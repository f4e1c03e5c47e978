// The exact model's per-patch normals and depths against an analytic scene: a cube pressed
// face-down into a slab while a small raised block (a separate closed part of the slab's mesh,
// not touching the slab) presses into the cube's front face. The two touching regions are two
// patches; each must carry its own face normal and its own depth.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Appends `part`, moved by `offset`, to `mesh` as a separate closed component.
void appendMoved(TriangleMesh& mesh, const TriangleMesh& part, const Vec3& offset) {
  const auto base = mesh.vertexCount();
  for (const Vec3& v : part.vertices) mesh.vertices.push_back(v + offset);
  for (const Triangle& t : part.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

// `mesh` with every triangle split into four at its edges' midpoints, `levels` times; a midpoint
// is shared by the two triangles of its edge, so a closed mesh stays closed.
TriangleMesh subdivided(TriangleMesh mesh, int levels) {
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t i, std::uint32_t j) {
      const auto key = std::minmax(i, j);
      const auto [it, added] = midpoints.try_emplace(key, static_cast<std::uint32_t>(mesh.vertices.size()));
      if (added) mesh.vertices.push_back(0.5 * (mesh.vertices[i] + mesh.vertices[j]));
      return it->second;
    };
    std::vector<Triangle> finer;
    for (const Triangle& t : mesh.triangles) {
      const std::uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      finer.push_back({t[0], a, c});
      finer.push_back({a, t[1], b});
      finer.push_back({c, b, t[2]});
      finer.push_back({a, b, c});
    }
    mesh.triangles = std::move(finer);
  }
  return mesh;
}

// Scene (B at the origin): slab |x|, |y| <= 3, -1 <= z <= 0; block 0.4 x 0.4 x 0.4 at
// z in [0.3, 0.7], its -x face at x = 1 - kBlockPenetration. Cube A (half extent 1) at
// (0, 0, 1 - kSlabPenetration): its bottom is kSlabPenetration below the slab's top, its +x face
// kBlockPenetration behind the block's -x face. The block does not reach down to the slab, so
// the two intersection curves (one around the cube at z = 0, one around the block on the cube's
// +x face) are apart, but both run over the cube's two +x-face triangles.
constexpr double kSlabPenetration = 0.01;
constexpr double kBlockPenetration = 0.04;
constexpr double kBlockBottom = 0.3;

struct Scene {
  CollisionBody cube, ground;
  Scene()
      : cube(test::makeTestBody(makeBox(Vec3::Constant(1.0)), 2, false, false)),
        ground(test::makeTestBody(makeGround(), 2, false, false)) {}
  static TriangleMesh makeGround() {
    TriangleMesh mesh;
    appendMoved(mesh, makeBox(Vec3(3.0, 3.0, 0.5)), Vec3(0.0, 0.0, -0.5));
    appendMoved(mesh, makeBox(Vec3::Constant(0.2)), Vec3(1.0 - kBlockPenetration + 0.2, 0.0, kBlockBottom + 0.2));
    return mesh;
  }
};

const Scene& scene() {
  static const Scene s;
  return s;
}

Pose cubePose() {
  Pose p;
  p.translation = Vec3(0.0, 0.0, 1.0 - kSlabPenetration);
  return p;
}

QuerySettings exactSettings(std::uint32_t maxContacts) {
  QuerySettings s;
  s.model = ContactModel::kExact;
  s.budget.maxTests = kUnlimitedTests;
  s.maxContacts = maxContacts;
  s.mergeDistanceRel = 0.0;
  return s;
}

// Normals point from B (ground) toward A (cube): the slab's top pushes the cube up (+z), the
// block's -x face pushes it back (-x). Depth, analytically: a patch's depth is its intersection
// volume over its area projected along the normal (docs/narrow-phase.md, "Depth"): at the slab
// the overlap is a 2 x 2 x kSlabPenetration slab of the cube, so kSlabPenetration; at the block
// kBlockPenetration. (Before the cube's bottom -- wholly inside the slab, crossing nothing --
// was part of its inside surface, the depth was the side strips' centroid: half of these.)
// Tolerance: 1e-9 of the scene's ~8.5 m diagonal, far above rounding, far below the 30 mm
// between the two depths.
constexpr double kDepthTolerance = 1e-8;

TEST(ExactModelPatches, SlabAndRaisedBlockGiveTwoPatchesWithTheirOwnNormalAndDepth) {
  const Scene& s = scene();
  // Every raw contact (no reduction): classify each by where it lies.
  const QueryResult all = queryContacts(s.cube, cubePose(), s.ground, Pose{}, exactSettings(100000));
  ASSERT_TRUE(all.finished);
  ASSERT_TRUE(all.colliding);
  // (Coincident copies of a point, from neighbouring triangle pairs, are merged: 0 distance.)
  int slabContacts = 0, blockContacts = 0;
  for (const Contact& c : all.contacts) {
    // Slab contacts lie on the slab's top (z = 0, down to the cube's bottom); block contacts on
    // the cube's +x face between the block's bottom and top.
    const bool onBlock = c.point.z() > kBlockBottom - 1e-6;
    if (onBlock) {
      ++blockContacts;
      EXPECT_NEAR(c.point.x(), 1.0 - 0.5 * kBlockPenetration, 0.5 * kBlockPenetration + 1e-9) << c.point.transpose();
      EXPECT_LT(angleBetween(c.normal, -Vec3::UnitX()), 2.0 * kDegree) << c.normal.transpose();
      EXPECT_NEAR(c.depth, kBlockPenetration, kDepthTolerance) << c.point.transpose();
    } else {
      ++slabContacts;
      EXPECT_NEAR(c.point.z(), -0.5 * kSlabPenetration, 0.5 * kSlabPenetration + 1e-9) << c.point.transpose();
      EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 2.0 * kDegree) << c.normal.transpose();
      EXPECT_NEAR(c.depth, kSlabPenetration, kDepthTolerance) << c.point.transpose();
    }
  }
  EXPECT_GE(slabContacts, 3);   // the cube's footprint on the slab
  EXPECT_GE(blockContacts, 3);  // the block's cross-section on the cube's face

  // A manifold of 8 keeps the deepest (block) patch and spreads onto the slab's patch too, each
  // contact still carrying its own patch's normal.
  const QueryResult reduced = queryContacts(s.cube, cubePose(), s.ground, Pose{}, exactSettings(8));
  int up = 0, back = 0;
  for (const Contact& c : reduced.contacts) {
    if (angleBetween(c.normal, Vec3::UnitZ()) < 2.0 * kDegree) ++up;
    if (angleBetween(c.normal, -Vec3::UnitX()) < 2.0 * kDegree) ++back;
  }
  EXPECT_EQ(up + back, static_cast<int>(reduced.contacts.size()));
  EXPECT_GE(up, 1);
  EXPECT_GE(back, 1);
  ASSERT_FALSE(reduced.contacts.empty());
  EXPECT_NEAR(reduced.contacts.front().depth, kBlockPenetration, kDepthTolerance);  // deepest first
}

// The same scene with the block moved off the cube: one patch, the slab's, as before.
TEST(ExactModelPatches, WithoutTheBlockOnlyTheSlabPatchRemains) {
  const Scene& s = scene();
  Pose pose = cubePose();
  pose.translation.x() -= 2.0 * kBlockPenetration;  // the cube's +x face now 4 cm short of the block
  const QueryResult r = queryContacts(s.cube, pose, s.ground, Pose{}, exactSettings(100000));
  ASSERT_TRUE(r.finished);
  ASSERT_FALSE(r.contacts.empty());
  for (const Contact& c : r.contacts) {
    EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 2.0 * kDegree) << c.normal.transpose();
    EXPECT_NEAR(c.depth, kSlabPenetration, kDepthTolerance);
  }
}

// A pillar much narrower than it is sunk deep relative to its width: its bottom (wholly inside
// the bed, crossing nothing) is most of the overlap's boundary below and its side strips are
// 40 % of the inside surface, so a depth from the inside surfaces' centroids (0.005 without the
// bottom, 0.0086 with it) is far from the analytic 0.01; the volume over the projected area is
// exact. The bed is two boxes in one mesh, so the pair is not two convex polyhedra (the
// separating-axis path). Tolerance as above.
TEST(ExactModelPatches, NarrowPillarSunkIntoABedGetsTheFullDepth) {
  TriangleMesh bed;
  appendMoved(bed, makeBox(Vec3(1.0, 1.0, 0.1)), Vec3(0.0, 0.0, -0.1));
  appendMoved(bed, makeBox(Vec3(1.0, 1.0, 0.1)), Vec3(3.0, 0.0, -0.1));
  const CollisionBody bedBody = test::makeTestBody(bed, 2, false, false);
  const CollisionBody pillar = test::makeTestBody(makeBox(Vec3(0.05, 0.05, 0.5)), 2, false, false);
  for (const double depth : {0.002, 0.01, 0.03}) {
    Pose pose;
    pose.translation = Vec3(0.3, 0.2, 0.5 - depth);
    const QueryResult r = queryContacts(bedBody, Pose{}, pillar, pose, exactSettings(8));
    ASSERT_TRUE(r.finished);
    ASSERT_FALSE(r.contacts.empty());
    for (const Contact& c : r.contacts) {
      EXPECT_NEAR(c.depth, depth, kDepthTolerance);
      EXPECT_LT(angleBetween(c.normal, -Vec3::UnitZ()), 0.01 * kDegree) << c.normal.transpose();
    }
  }
}

// A bed of two boxes in one mesh (so not one convex body): a 4 x 4 x 0.2 slab with its top at
// z = 0 and a smaller one beside it.
const CollisionBody& bed() {
  static const CollisionBody body = [] {
    TriangleMesh mesh;
    appendMoved(mesh, makeBox(Vec3(2.0, 2.0, 0.1)), Vec3(0.0, 0.0, -0.1));
    appendMoved(mesh, makeBox(Vec3(1.0, 1.0, 0.1)), Vec3(5.0, 0.0, -0.1));
    return test::makeTestBody(mesh, 2, false, false);
  }();
  return body;
}

// A unit cube (half extent 0.5) turned 10 deg about y, its lowest edge (x = +0.5, z = -0.5 of the
// cube) `depth` into the bed's top.
Pose cubeOnItsEdge(double depth) {
  const double tilt = 10.0 * kDegree;
  Pose pose;
  pose.rotation = Quat(Eigen::AngleAxisd(tilt, Vec3::UnitY()));
  pose.translation = Vec3(0.1, 0.2, 0.5 * (std::sin(tilt) + std::cos(tilt)) - depth);
  return pose;
}

// A cube landing tilted on one bottom edge (turned 10 deg about y, that edge 1 cm into a bed of two
// boxes in one mesh): the points on the intersection curve run up the tilt to the bed's top, where
// the penetration along any line is 0, and a patch depth on every one of them (before: the
// volume over the area, 3.3 mm) pushed back along the whole edge at a third of the real depth. Per
// point (docs/narrow-phase.md, "exact"): the two vertices of the edge are the contacts, each 1 cm
// deep, with their surface points on the cube (the vertex) and on the bed's top. Analytic: the
// cube's bottom vertices at x = +0.5 lie 0.5 (sin + cos) below its centre, the others at least
// sin 10 deg - 1 cm = 16 cm above the bed. Tolerance as above.
TEST(ExactModelPatches, CubeLandingOnAnEdgeGetsItsTwoVerticesAtTheirOwnDepth) {
  const double depth = 0.01;
  const CollisionBody cube = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2, false, false);
  const Pose pose = cubeOnItsEdge(depth);
  const QueryResult r = queryContacts(bed(), Pose{}, cube, pose, exactSettings(8));
  ASSERT_TRUE(r.finished);
  ASSERT_EQ(r.contacts.size(), 2u);
  for (const Contact& c : r.contacts) {
    EXPECT_NEAR(c.depth, depth, kDepthTolerance);
    EXPECT_EQ(c.errorBound, 0.0);
    EXPECT_LT(angleBetween(c.normal, -Vec3::UnitZ()), 0.01 * kDegree) << c.normal.transpose();
    // B is the cube here: its point is the vertex, A's (the bed's) lies on the bed's top.
    const Vec3 vertex = pose.applyInverse(contactPointOnB(c));
    EXPECT_NEAR(vertex.x(), 0.5, 1e-9) << vertex.transpose();
    EXPECT_NEAR(std::abs(vertex.y()), 0.5, 1e-9) << vertex.transpose();
    EXPECT_NEAR(vertex.z(), -0.5, 1e-9) << vertex.transpose();
    EXPECT_NEAR(contactPointOnA(c).z(), 0.0, 1e-9) << contactPointOnA(c).transpose();
  }
}

// The same landing with the cube finely tessellated (3,072 triangles, legs of 1/16 of its edge):
// some of its triangles along the edge now lie wholly inside the bed, cross nothing, and their
// pieces are missing from the crossing pieces' area-vector sum, which then leans toward the
// cube's bottom face (before: 4 deg off; a fandisk landing on a box on one edge got normals 6 deg
// off the box's face). The bed's side of the patch is one plane, and the overlap of a body with
// a half-space is separated along the plane's normal by the deepest point's depth in no other
// direction by less (every other direction u needs depth / (u . n)): the normal is the face's.
// Analytic: the edge's vertices, 2 cm deep, at x = 0.5 of the cube; the face normal -z (B, the
// cube, lies above A, the bed).
TEST(ExactModelPatches, FinelyTessellatedCubeLandingOnAnEdgeGetsTheBedsFaceNormal) {
  const double depth = 0.02;
  const CollisionBody cube = test::makeTestBody(subdivided(makeBox(Vec3::Constant(0.5)), 4), 3, false, false);
  const Pose pose = cubeOnItsEdge(depth);
  const QueryResult r = queryContacts(bed(), Pose{}, cube, pose, exactSettings(64));
  ASSERT_TRUE(r.finished);
  ASSERT_FALSE(r.contacts.empty());
  double deepest = 0.0;
  for (const Contact& c : r.contacts) {
    EXPECT_LT(angleBetween(c.normal, -Vec3::UnitZ()), 0.01 * kDegree) << c.normal.transpose();
    // Each contact is a vertex of the cube at its own depth below the bed's top (tolerance as above).
    const Vec3 vertex = pose.applyInverse(contactPointOnB(c));
    EXPECT_NEAR(c.depth, -pose.apply(vertex).z(), kDepthTolerance) << vertex.transpose();
    deepest = std::max(deepest, c.depth);
  }
  EXPECT_NEAR(deepest, depth, kDepthTolerance);
}

}  // namespace
}  // namespace clod
