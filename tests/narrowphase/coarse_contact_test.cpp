// Contacts of interrupted queries against analytic answers: a box resting face-down on a slab
// (the world's box-drop scene, docs/dynamics.md) and small bodies resting on a large floor (the
// 200-body bin), at tiny budgets where the frontier is still at the roots or one level below.
// A resting body needs contact normals along the face normal, points in the contact face whose
// support polygon holds its centre of mass, and depths near the true penetration: a coarse
// contact that fails one of these lets a dropped box come to rest tilted (docs/narrow-phase.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "clod/bake.h"
#include "clod/contact_tree_builder.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "support/floor_quad.h"
#include "support/grid_box.h"
#include "support/l_shaped_body.h"
#include "support/test_scale.h"
#include "clod/proximity.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::octreeBodyForCfm;
using test::settingsFor;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }


// The bake of tests/dynamics/world_test.cpp (octree sphere-tree of depth 3, default closest
// feature map, contact tree of depth 6), so these are the trees the box-drop test runs on.
CollisionBody bakeLikeTheWorldTest(const TriangleMesh& mesh) {
  CollisionBody body = octreeBodyForCfm(mesh);
  ContactTreeSettings ct;
  ct.maxDepth = 6;
  body.setContactTree(buildContactTree(MeshDistance(mesh), ct));
  return body;
}

struct SlabBodies {
  // A 4 x 4 x 0.5 slab (top face at z = 0.25) and a unit cube, both centred at their origin.
  CollisionBody slab = bakeLikeTheWorldTest(makeBox(Vec3(2.0, 2.0, 0.25)));
  CollisionBody cube = bakeLikeTheWorldTest(makeBox(Vec3(0.5, 0.5, 0.5)));
  // The same cube with 3 x 3 squares per face (56 vertices) and a dent in its top: not convex,
  // so not a whole-body patch.
  CollisionBody gridCube = bakeLikeTheWorldTest(test::makeGridBox(Vec3(0.5, 0.5, 0.5), 3, 0.05));
};

const SlabBodies& slabBodies() {
  static const SlabBodies b;
  return b;
}

// Twice the signed area of triangle (o, a, b) in the xy plane.
double cross2(const Vec3& o, const Vec3& a, const Vec3& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// True if (x, y) of `p` lies inside the convex hull of the contacts' (x, y), at least `margin`
// from its boundary (Andrew's monotone chain, then the point against every hull edge).
bool insideSupportPolygon(const std::vector<Contact>& contacts, const Vec3& p, double margin) {
  std::vector<Vec3> pts;
  for (const Contact& c : contacts) pts.push_back(c.point);
  std::sort(pts.begin(), pts.end(), [](const Vec3& a, const Vec3& b) { return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y(); });
  if (pts.size() < 3) return false;
  std::vector<Vec3> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0.0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0.0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);  // counter-clockwise, last point == first dropped
  if (hull.size() < 3) return false;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vec3& a = hull[i];
    const Vec3& b = hull[(i + 1) % hull.size()];
    const double length = std::hypot(b.x() - a.x(), b.y() - a.y());
    if (cross2(a, b, p) / length < margin) return false;
  }
  return true;
}

// The box-drop scene's resting pose: the cube face-down on the slab, `penetration` deep, at a
// few lateral offsets (the drop test's (0.1, -0.05) first; the others move the cube's footprint
// across the slab's octree cells, up to the slab's edge region).
const std::vector<Vec3>& cubeOffsets() {
  static const std::vector<Vec3> o = {{0.1, -0.05, 0}, {0.0, 0.0, 0}, {0.7, 0.45, 0}, {-1.2, 0.35, 0}, {0.4, -1.3, 0}};
  return o;
}
constexpr double kPenetration = 0.01;
constexpr double kSlabTop = 0.25;

TEST(CoarseContacts, BoxRestingOnASlabGetsTheFaceNormalPointsInTheContactFaceAndTheDepth) {
  const SlabBodies& b = slabBodies();
  // Tolerance for cfm's points and depths, computed from the patches' vertices: rounding only;
  // 1e-3 of the cube's diagonal (1.7 mm) is far above it and far below the 0.5 m half width
  // the check is about. The contact tree samples cell half-planes, which near the cube's edges
  // reach past the face (a right-angled edge fits its cell's plane only to ~0.3 of the cell
  // size), and there the field of the rounded edge reads shallower than the penetration
  // (measured: points 0.035 past the footprint, 0.0016 deep instead of 0.01, at full budget
  // too). For it: points within 0.05 (the cube-on-cube test's bound, 5 % of the width), and
  // depths checked away from the edges only.
  const double tolerance = 1e-3 * b.cube.diagonal();
  const double treeTolerance = 0.05;
  int contacts = 0;
  for (const Vec3& offset : cubeOffsets()) {
    const Vec3 cubeCentre(offset.x(), offset.y(), kSlabTop + 0.5 - kPenetration);
    const Pose poseCube{Quat::Identity(), cubeCentre};
    for (const bool slabIsA : {true, false}) {
      for (ContactModel model : {ContactModel::kCfm, ContactModel::kContactTree}) {
        for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(64), std::uint64_t(256), kUnlimitedTests}) {
          const std::string what = std::string(contactModelName(model)) + " budget " + std::to_string(budget) +
                                   " offset " + std::to_string(offset.x()) + "," + std::to_string(offset.y()) +
                                   (slabIsA ? " slab=A" : " slab=B");
          const QueryResult r = slabIsA ? queryContacts(b.slab, Pose{}, b.cube, poseCube, settingsFor(model, budget))
                                        : queryContacts(b.cube, poseCube, b.slab, Pose{}, settingsFor(model, budget));
          ASSERT_TRUE(r.colliding) << what;
          // The normal points from B toward A: down when the slab is A.
          const Vec3 expected = slabIsA ? Vec3(-Vec3::UnitZ()) : Vec3::UnitZ();
          const bool tree = model == ContactModel::kContactTree;
          const double lateral = tree ? treeTolerance : tolerance;
          for (const Contact& c : r.contacts) {
            ++contacts;
            const bool nearEdge = std::max(std::abs(c.point.x() - offset.x()), std::abs(c.point.y() - offset.y())) > 0.5 - treeTolerance;
            // 2 degrees: the bound (above the maps' 16-bit codec error of ~0.95 degrees).
            EXPECT_LT(angleBetween(c.normal, expected), 2.0 * kDegree) << what << " normal " << c.normal.transpose();
            // In the overlap of the two boxes: the cube's footprint, between the slab's top and
            // the cube's bottom face.
            EXPECT_LE(std::abs(c.point.x() - offset.x()), 0.5 + lateral) << what << " at " << c.point.transpose();
            EXPECT_LE(std::abs(c.point.y() - offset.y()), 0.5 + lateral) << what << " at " << c.point.transpose();
            EXPECT_GE(c.point.z(), kSlabTop - kPenetration - tolerance) << what << " at " << c.point.transpose();
            EXPECT_LE(c.point.z(), kSlabTop + tolerance) << what << " at " << c.point.transpose();
            // Depth: the true penetration within the contact's own error bound (the level's),
            // and never deeper than the penetration plus the tolerance.
            if (!(tree && nearEdge)) {
              EXPECT_LE(std::abs(c.depth - kPenetration), c.errorBound + tolerance) << what << " at " << c.point.transpose();
              EXPECT_LE(c.depth, kPenetration + tolerance) << what;
            }
          }
          // A box resting under gravity needs the contacts' support polygon to hold its centre
          // of mass; 5 cm (a tenth of the half width) inside, so it does not rest on an edge.
          EXPECT_TRUE(insideSupportPolygon(r.contacts, cubeCentre, 0.05)) << what << ": " << r.contacts.size() << " contacts";
        }
      }
    }
  }
  EXPECT_GT(contacts, 200);  // the cases produce many contacts, not a vacuous pass
}

TEST(CoarseContacts, CfmAndContactTreeAreNeverWorseThanDosOnTheSlab) {
  const SlabBodies& b = slabBodies();
  auto worstAngle = [](const QueryResult& r) {
    double worst = 0.0;
    for (const Contact& c : r.contacts) worst = std::max(worst, angleBetween(c.normal, -Vec3::UnitZ()));
    return worst;
  };
  for (const Vec3& offset : cubeOffsets()) {
    const Pose poseCube{Quat::Identity(), Vec3(offset.x(), offset.y(), kSlabTop + 0.5 - kPenetration)};
    // The budgets. Below 16 (1 or 4 tests: the root cells) the contact tree samples the
    // cube's root cell, whose half-plane is a poor fit of a whole cube, and its worst contact is
    // up to 72 degrees off where dos's is 61 (docs/narrow-phase.md, known limits).
    for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(64), std::uint64_t(256), std::uint64_t(1024), kUnlimitedTests}) {
      const double dos = worstAngle(queryContacts(b.slab, Pose{}, b.cube, poseCube, settingsFor(ContactModel::kDos, budget)));
      for (ContactModel model : {ContactModel::kCfm, ContactModel::kContactTree}) {
        const QueryResult r = queryContacts(b.slab, Pose{}, b.cube, poseCube, settingsFor(model, budget));
        ASSERT_FALSE(r.contacts.empty()) << contactModelName(model) << " budget " << budget;
        EXPECT_LE(worstAngle(r), dos + 1e-9) << contactModelName(model) << " budget " << budget;  // rounding only
      }
    }
  }
}

TEST(CoarseContacts, CfmDropsSpherePairsWhosePatchesAreProvenApart) {
  // The cube hovering 0.05 above the slab: every sphere pair down to the leaves still overlaps
  // (the spheres bound box corners loosely), but the patches are apart along z. No contact:
  // contacts there would hold the box up in the air (it rested 0.055 above the slab, 8 degrees
  // tilted, in the box-drop test). dos keeps its sphere contacts (it has no patches).
  const SlabBodies& b = slabBodies();
  const Pose poseCube{Quat::Identity(), Vec3(0.1, -0.05, kSlabTop + 0.5 + 0.05)};
  for (std::uint64_t budget : {std::uint64_t(16), std::uint64_t(256), kUnlimitedTests}) {
    const QueryResult dos = queryContacts(b.slab, Pose{}, b.cube, poseCube, settingsFor(ContactModel::kDos, budget));
    ASSERT_FALSE(dos.contacts.empty()) << "the spheres must overlap, or the test proves nothing; budget " << budget;
    const QueryResult cfm = queryContacts(b.slab, Pose{}, b.cube, poseCube, settingsFor(ContactModel::kCfm, budget));
    EXPECT_TRUE(cfm.contacts.empty()) << budget;
    EXPECT_FALSE(cfm.colliding) << budget;
  }
}

// An exact query whose budget runs out before its triangle tests are done answers the frontier
// pairs without triangle tests from the sphere tree. With closest feature maps on both bodies
// they answer as cfm does (before: D&O contacts, whose normals follow the sphere centre lines,
// tens of degrees off on the slab; an exact run at budget 1024 on two bunnies was 19.8 deg off,
// as bad as dos). Box resting on the slab, both orders, budgets too small for every triangle
// test: every contact within 2 deg of the face normal (the cfm bound above), tests never over
// the budget.
TEST(CoarseContacts, InterruptedExactQueryFallsBackToCfmContacts) {
  const SlabBodies& b = slabBodies();
  ASSERT_TRUE(b.slab.hasClosestFeatureMap() && b.gridCube.hasClosestFeatureMap());
  ASSERT_FALSE(b.gridCube.patchIsWholeConvexBody(0));  // else no triangle test would be made
  int interrupted = 0, duringTriangles = 0, contacts = 0;
  for (const Vec3& offset : cubeOffsets()) {
    const Pose poseCube{Quat::Identity(), Vec3(offset.x(), offset.y(), kSlabTop + 0.5 - kPenetration)};
    for (const bool slabIsA : {true, false}) {
      // 16-256 stop in the sphere traversal of the grid cube, 384 and 512 during its triangle tests.
      for (std::uint64_t budget : {16, 64, 256, 384, 512}) {
        const QuerySettings settings = settingsFor(ContactModel::kExact, budget);
        const QueryResult r = slabIsA ? queryContacts(b.slab, Pose{}, b.gridCube, poseCube, settings)
                                      : queryContacts(b.gridCube, poseCube, b.slab, Pose{}, settings);
        EXPECT_LE(r.tests, budget);
        if (r.finished) continue;
        ++interrupted;
        duringTriangles += r.triangleTests > 0 ? 1 : 0;
        const std::string what = "budget " + std::to_string(budget) + " offset " + std::to_string(offset.x()) + "," +
                                 std::to_string(offset.y()) + (slabIsA ? " slab=A" : " slab=B");
        ASSERT_TRUE(r.colliding) << what;
        ASSERT_FALSE(r.contacts.empty()) << what;
        const Vec3 expected = slabIsA ? Vec3(-Vec3::UnitZ()) : Vec3::UnitZ();
        for (const Contact& c : r.contacts) {
          ++contacts;
          EXPECT_LT(angleBetween(c.normal, expected), 2.0 * kDegree)
              << what << " level " << c.level << " normal " << c.normal.transpose() << " at " << c.point.transpose();
        }
      }
    }
  }
  // Not vacuous: most cases are interrupted, some of them during the triangle tests.
  EXPECT_GE(interrupted, 20);
  EXPECT_GE(duringTriangles, 1);
  EXPECT_GT(contacts, 50);
}

// Small bodies on a 20 m floor (the bin's floor is 4.4 m for 0.3 m bodies): at the root level
// the centre line of a small body's sphere and the floor's root sphere is nearly horizontal, and
// so is the D&O normal; the floor's map, looked up on its huge root sphere, returns a side face.
// The contact must still push the body up.
TEST(CoarseContacts, SmallBodiesOnALargeFloorArePushedAlongTheFloorNormalAtTheRoot) {
  static const CollisionBody floor = test::makeTestBody(makeBox(Vec3(10.0, 10.0, 0.5)), 2, false);
  static const CollisionBody ball = test::makeTestBody(makeIcosphere(0.15, 2), 2, false);
  static const CollisionBody cube = test::makeTestBody(makeBox(Vec3(0.15, 0.15, 0.15)), 2, false);
  const double penetration = 0.003;
  const std::vector<Vec3> spots = {{0.3, 0.2, 0}, {6.0, -3.0, 0}, {-8.5, 7.0, 0}, {-2.0, -9.0, 0}};
  int cases = 0;
  for (const CollisionBody* body : {&ball, &cube}) {
    const bool isBall = body == &ball;
    double halfHeight = 0.0;  // the body's lowest vertex below its origin
    for (const Vec3& v : body->mesh().vertices) halfHeight = std::max(halfHeight, -v.z());
    for (const Vec3& spot : spots) {
      const Pose pose{Quat::Identity(), Vec3(spot.x(), spot.y(), 0.5 + halfHeight - penetration)};
      for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(8), std::uint64_t(16), std::uint64_t(64)}) {
        const std::string what = std::string(isBall ? "ball" : "cube") + " at " + std::to_string(spot.x()) + "," +
                                 std::to_string(spot.y()) + " budget " + std::to_string(budget);
        // Face planes use the patches' face normals, stored as floats (~6e-8 rad): over the
        // body's extent that moves a point's height by < 1e-7 of its diagonal; coordinates of
        // the 20 m floor round at 1e-12 of its size.
        const double rounding = 1e-7 * body->diagonal() + 1e-12 * floor.diagonal();
        const QueryResult dos = queryContacts(*body, pose, floor, Pose{}, settingsFor(ContactModel::kDos, budget));
        const QueryResult r = queryContacts(*body, pose, floor, Pose{}, settingsFor(ContactModel::kCfm, budget));
        ASSERT_FALSE(r.contacts.empty()) << what;
        double worstDos = 0.0;
        for (const Contact& c : dos.contacts) worstDos = std::max(worstDos, angleBetween(c.normal, Vec3::UnitZ()));
        for (const Contact& c : r.contacts) {
          ++cases;
          // The floor's face normal is exact, and it is the normal: 2 degrees as elsewhere
          // (rounding only, in fact), and never worse than dos.
          EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 2.0 * kDegree) << what << " normal " << c.normal.transpose();
          EXPECT_LE(angleBetween(c.normal, Vec3::UnitZ()), worstDos + 1e-9) << what;
          // Under the body (within its 0.15 half width, plus rounding) and between the floor's
          // top and the body's bottom; depth no deeper than the body's sphere reaches.
          EXPECT_LE(std::hypot(c.point.x() - spot.x(), c.point.y() - spot.y()), 0.15 * std::sqrt(2.0) + 1e-9) << what;
          // Each contact carries the separation of the two surfaces at its own point (a corner of
          // a ball's facet lifted off the floor has a smaller or negative depth) and lies midway
          // between them; its depth is off by at most the error bound -- 0 between convex
          // polyhedra's facing faces, so rounding of the 20 m floor's coordinates (1e-12 of its
          // size) is the only slack. No contact is deeper than the body's penetration, and the
          // deepest one has it.
          EXPECT_LE(std::abs(c.point.z() - 0.5), c.errorBound + 0.5 * std::abs(c.depth) + rounding) << what;
          EXPECT_LE(c.depth, penetration + c.errorBound + rounding) << what;
        }
        {
          const Contact& deepest = r.contacts.front();  // deepest first
          EXPECT_LE(std::abs(deepest.depth - penetration), deepest.errorBound + rounding) << what;
        }
      }
    }
  }
  EXPECT_GE(cases, 32);
}

}  // namespace
// A curved mesh (the shared bunny-1500, unit diagonal) resting on a box at 1 to 64 tests, where
// its spheres are the root or one level below: every contact is one of its vertices that lies
// inside the box, with the box's face normal, and its depth is that vertex's depth below the top
// face. Oracle: the mesh's vertices, checked one by one against the box (brute force). Before,
// the pair gave one contact at its sphere's centre with the sphere's overlap as depth, and the
// world let the bunny sink 20 % of its diagonal within that depth's error bound.
TEST(CoarseContacts, CurvedMeshOnABoxRestsOnItsOwnVerticesWithTheirDepths) {
  static const CollisionBody floor = test::makeTestBody(makeBox(Vec3(2.0, 2.0, 0.25)), 2, false);
  static const CollisionBody bunny = test::makeTestBody(test::loadUnitMesh("bunny-1500.obj"), 2, false);
  const double floorTop = 0.25;
  // Rounding: face planes from float face normals (~6e-8 rad over a few m) and coordinates.
  const double rounding = 1e-6;
  const Quat upright(Eigen::AngleAxisd(kPi / 2.0, Vec3::UnitX()));  // the bunny's base down
  double lowest = std::numeric_limits<double>::infinity();
  for (const Vec3& v : bunny.mesh().vertices) lowest = std::min(lowest, (upright * v).z());
  int cases = 0;
  for (double penetration : {0.002, 0.01}) {
    const Pose pose{upright, Vec3(0.1, -0.2, floorTop - lowest - penetration)};
    // Brute force: every vertex's depth below the top face (the box is 4 x 4, wider than the bunny).
    std::vector<double> vertexDepths;
    for (const Vec3& v : bunny.mesh().vertices) vertexDepths.push_back(floorTop - pose.apply(v).z());
    const double deepest = *std::max_element(vertexDepths.begin(), vertexDepths.end());
    ASSERT_NEAR(deepest, penetration, 1e-12);
    for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(4), std::uint64_t(16), std::uint64_t(64)}) {
      const std::string what = "penetration " + std::to_string(penetration) + " budget " + std::to_string(budget);
      const QueryResult r = queryContacts(bunny, pose, floor, Pose{}, settingsFor(ContactModel::kCfm, budget));
      std::size_t exactContacts = 0;
      double deepestExact = -std::numeric_limits<double>::infinity();
      for (const Contact& c : r.contacts) {
        EXPECT_LT(angleBetween(c.normal, Vec3::UnitZ()), 1e-6) << what << " normal " << c.normal.transpose();
        if (c.errorBound > rounding) {
          // A sphere pair whose vertices all lie outside the box (its sphere reaches in): the
          // generic contact, whose depth only keeps its promise.
          EXPECT_LE(std::abs(c.depth - penetration), c.errorBound) << what;
          continue;
        }
        ++cases;
        ++exactContacts;
        // The contact lies midway between a vertex and the face: the vertex is c.point - depth/2 n_up.
        const Vec3 vertex = c.point - 0.5 * c.depth * Vec3::UnitZ();
        double nearest = std::numeric_limits<double>::infinity();
        for (const Vec3& v : bunny.mesh().vertices) nearest = std::min(nearest, (pose.apply(v) - vertex).norm());
        EXPECT_LT(nearest, rounding) << what << ": not a vertex of the mesh";
        EXPECT_NEAR(c.depth, floorTop - vertex.z(), rounding) << what;
        EXPECT_GT(c.depth, 0.0) << what;
        deepestExact = std::max(deepestExact, c.depth);
      }
      EXPECT_GE(exactContacts, 3u) << what << ": a support area needs three points";
      // The deepest vertex is among them.
      EXPECT_NEAR(deepestExact, deepest, rounding) << what;
    }
  }
  EXPECT_GE(cases, 24);
}


// Two curved bodies at the roots (budget 1: the root pair is the whole frontier): wherever the
// bodies' vertices, projected on the line through the root spheres' centres, do not overlap (a
// separating axis, found by brute force over every vertex), cfm gives no contact, however much
// the spheres overlap; wherever the exact model finds the surfaces crossing, cfm gives one. Before
// two curved patches were bounded by their spheres alone, and cfm responded across the gap.
TEST(CoarseContacts, CurvedPatchesApartAlongTheCentreLineGiveNoContact) {
  static const CollisionBody bunny = test::makeTestBody(test::loadUnitMesh("bunny-1500.obj"), 2, false);
  const SphereTree& tree = bunny.sphereTree();
  const double rootRadius = tree.radius[0];
  std::mt19937_64 rng(17);
  int apart = 0, touching = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Pose poseA = test::randomPose(rng, 0.0);
    Pose poseB = test::randomPose(rng, 0.0);
    // Root spheres overlapping by up to their radius.
    std::uniform_real_distribution<double> gap(1.0, 2.0);
    poseB.translation = poseA.apply(tree.center(0)) - poseB.rotation * tree.center(0) +
                        gap(rng) * rootRadius * test::randomPose(rng, 1.0).translation.normalized();
    const Vec3 cA = poseA.apply(tree.center(0)), cB = poseB.apply(tree.center(0));
    const Vec3 u = (cA - cB).normalized();
    double minA = std::numeric_limits<double>::infinity(), maxB = -minA;
    for (const Vec3& v : bunny.mesh().vertices) {
      minA = std::min(minA, u.dot(poseA.apply(v)));
      maxB = std::max(maxB, u.dot(poseB.apply(v)));
    }
    const QueryResult cfm = queryContacts(bunny, poseA, bunny, poseB, settingsFor(ContactModel::kCfm, 1));
    if (maxB < minA) {
      ++apart;
      EXPECT_TRUE(cfm.contacts.empty()) << "trial " << trial << ": apart by " << minA - maxB;
    }
    const QueryResult exact = queryContacts(bunny, poseA, bunny, poseB, settingsFor(ContactModel::kExact, kUnlimitedTests));
    if (exact.colliding && !exact.contacts.empty()) {
      ++touching;
      EXPECT_FALSE(cfm.contacts.empty()) << "trial " << trial << ": the surfaces cross";
    }
  }
  // Both kinds of pose occur often enough to mean something.
  EXPECT_GE(apart, 20);
  EXPECT_GE(touching, 20);
}


// Two unit icospheres (320 triangles; curved patches down to level 2 of an 8-ary octree tree)
// 2 % of the radius into each other along a random line, resolved at level 1 (an interrupted
// answer's curved pairs). Oracle: the lens where the two balls overlap. Every cfm contact must
// lie in it, grown by one edge of the tessellation (0.13 of the radius: where the vertices
// nearest the centre line can stand). Before, a curved pair's point started from A's sphere
// centre: contacts stood up to 0.24 radii outside the lens, 0.3 off the centre line in the
// median -- where the bodies do not touch.
TEST(CoarseContacts, TwoCurvedPatchesTouchInsideTheirLens) {
  static const CollisionBody ball = octreeBodyForCfm(makeIcosphere(1.0, 3));
  const double edge = 0.13, overlap = 0.02;
  std::mt19937_64 rng(5);
  int contacts = 0;
  for (int trial = 0; trial < (test::sanitizerRun() ? 10 : 60); ++trial) {
    const Pose poseA{test::randomPose(rng, 0.0).rotation, Vec3::Zero()};
    const Vec3 line = test::randomPose(rng, 1.0).translation.normalized();
    const Pose poseB{test::randomPose(rng, 0.0).rotation, (2.0 - overlap) * line};
    QuerySettings settings = settingsFor(ContactModel::kCfm, kUnlimitedTests);
    settings.maxLevel = 1;
    const QueryResult r = queryContacts(ball, poseA, ball, poseB, settings);
    for (const Contact& c : r.contacts) {
      const double outside = std::max(c.point.norm(), (c.point - poseB.translation).norm()) - 1.0;
      EXPECT_LE(outside, edge) << "trial " << trial << ": point " << c.point.transpose();
      ++contacts;
    }
  }
  EXPECT_GE(contacts, test::sanitizerRun() ? 10 : 60);  // every pose touches: the test must see contacts
}


// A closed slab whose top (z = 0) is a height field with a smooth bump h(r) = H (1 + cos(pi r /
// R)) / 2 for r < R around (bx, 0): 2 cm cells within the bump's square, 10 cm elsewhere, side
// walls and a bottom fanned from its centre; counter-clockwise seen from outside.
TriangleMesh makeBumpedSlab(double halfX, double halfY, double bx, double height, double radius) {
  auto lines = [](double lo, double hi, double c, double r) {
    std::vector<double> v;
    for (double x = lo; x < c - r - 1e-9; x += 0.1) v.push_back(x);
    for (double x = c - r; x < c + r - 1e-9; x += 0.02) v.push_back(x);
    for (double x = c + r; x < hi - 1e-9; x += 0.1) v.push_back(x);
    v.push_back(hi);
    std::vector<double> out;
    for (double x : v)
      if (out.empty() || x - out.back() > 0.005) out.push_back(x);
    out.back() = hi;
    return out;
  };
  const std::vector<double> xs = lines(-halfX, halfX, bx, radius), ys = lines(-halfY, halfY, 0.0, radius);
  const auto nx = static_cast<std::uint32_t>(xs.size()), ny = static_cast<std::uint32_t>(ys.size());
  TriangleMesh mesh;
  auto top = [&](std::uint32_t i, std::uint32_t j) { return j * nx + i; };
  for (std::uint32_t j = 0; j < ny; ++j) {
    for (std::uint32_t i = 0; i < nx; ++i) {
      const double r = std::hypot(xs[i] - bx, ys[j]);
      mesh.vertices.emplace_back(xs[i], ys[j], r < radius ? 0.5 * height * (1.0 + std::cos(kPi * r / radius)) : 0.0);
    }
  }
  for (std::uint32_t j = 0; j + 1 < ny; ++j) {
    for (std::uint32_t i = 0; i + 1 < nx; ++i) {
      mesh.triangles.push_back({top(i, j), top(i + 1, j), top(i + 1, j + 1)});
      mesh.triangles.push_back({top(i, j), top(i + 1, j + 1), top(i, j + 1)});
    }
  }
  std::vector<std::uint32_t> ring;  // the top's boundary, counter-clockwise seen from +z
  for (std::uint32_t i = 0; i + 1 < nx; ++i) ring.push_back(top(i, 0));
  for (std::uint32_t j = 0; j + 1 < ny; ++j) ring.push_back(top(nx - 1, j));
  for (std::uint32_t i = nx - 1; i > 0; --i) ring.push_back(top(i, ny - 1));
  for (std::uint32_t j = ny - 1; j > 0; --j) ring.push_back(top(0, j));
  const auto bottom0 = static_cast<std::uint32_t>(mesh.vertices.size());
  for (std::uint32_t v : ring) mesh.vertices.emplace_back(mesh.vertices[v].x(), mesh.vertices[v].y(), -0.5);
  const auto centre = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, -0.5);
  const auto n = static_cast<std::uint32_t>(ring.size());
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t k1 = (k + 1) % n;
    mesh.triangles.push_back({bottom0 + k, bottom0 + k1, ring[k1]});
    mesh.triangles.push_back({bottom0 + k, ring[k1], ring[k]});
    mesh.triangles.push_back({centre, bottom0 + k1, bottom0 + k});
  }
  return mesh;
}

// A unit cube resting on a bumped ground (a 4 cm bump of radius 20 cm, the ground of `clod
// experiment flat-contact`), 0.5 mm into its flat part, with its front face over the bump's
// flank (the bump's top still outside the box) or over its top. Two oracles. (1) By brute force
// over every ground vertex inside the box: cfm's deepest contact must reach at least the deepest
// vertex's height (before, a curved patch of the ground offered only its convex hull's vertices
// -- the bump's top and the patch's rim -- so the flank under the box's edge gave no contact,
// the box ploughed into the bump and was thrown up when the top arrived: flat-contact, 239 mm rms
// from the exact track). (2) From the bump's analytic height h(r): the minimum translation that
// lifts the box's bottom face clear of the bump over its whole footprint, searched over
// directions tilted back from the vertical by 0-30 deg in 0.05 deg steps (bisection on the
// travel along each). Every normal must lie between the vertical and that direction: the flank
// under the front edge pushes the box up and back, never forward (with straight-up normals the
// box crossed the bump without turning, 7 deg off the exact model's heading).
TEST(CoarseContacts, BoxOverABumpsFlankIsPushedUpAndBackFromTheDeepestGroundVertex) {
  const double bx = 0.6, by = 0.0, bumpHeight = 0.04, bumpRadius = 0.2, sunk = 0.0005;
  static const CollisionBody ground = octreeBodyForCfm(makeBumpedSlab(1.6, 1.0, bx, bumpHeight, bumpRadius));
  const CollisionBody& cube = slabBodies().cube;
  // Rounding of face planes from float face normals over a few metres, relative to the ground's
  // diagonal (~3.8 m): 1e-6 of it is far below the millimetres the test tells apart.
  const double rounding = 1e-6 * ground.diagonal();
  // The oracle's direction step (0.05 deg), and the 2 cm tessellation of the bump, whose flank
  // turns by up to 1 deg between grid lines.
  const double angleSlack = 1.0 * kDegree;
  // Highest point of the bump under a footprint reaching x0 along +x (the box spans y = -0.45 ..
  // 0.55 over the bump's centre line y = by, so the row through the centre is the highest).
  auto highestUnder = [&](double x0) {
    const double r = std::max(0.0, bx - x0);
    return r < bumpRadius ? 0.5 * bumpHeight * (1.0 + std::cos(kPi * r / bumpRadius)) : 0.0;
  };
  int cases = 0;
  // Front face at r = 0.14, 0.1, 0.06 before the bump's centre (the top outside the box), and
  // past it (the top under the face).
  for (double front : {bx - 0.14, bx - 0.1, bx - 0.06, bx + 0.1}) {
    const Pose pose{Quat::Identity(), Vec3(front - 0.5, by + 0.05, 0.5 - sunk)};
    double deepest = 0.0;
    for (const Vec3& v : ground.mesh().vertices) {
      const Vec3 local = pose.applyInverse(v);
      if ((local.array().abs() < 0.5).all()) deepest = std::max(deepest, local.z() + 0.5);
    }
    ASSERT_GT(deepest, 4.0 * sunk) << "front " << front << ": the bump's flank is under the box";
    double minTravel = std::numeric_limits<double>::infinity(), minTilt = 0.0;
    for (double tilt = 0.0; tilt <= 30.0 * kDegree; tilt += 0.05 * kDegree) {
      double lo = 0.0, hi = 0.2;
      for (int k = 0; k < 60; ++k) {
        const double t = 0.5 * (lo + hi);
        const bool clear = t * std::cos(tilt) - sunk >= highestUnder(front - t * std::sin(tilt));
        (clear ? hi : lo) = t;
      }
      if (hi < minTravel) minTravel = hi, minTilt = tilt;
    }
    for (bool groundIsA : {true, false}) {
      QuerySettings settings;  // unlimited budget: the ground's leaves against the box
      settings.model = ContactModel::kCfm;
      const QueryResult r = groundIsA ? queryContacts(ground, Pose{}, cube, pose, settings)
                                      : queryContacts(cube, pose, ground, Pose{}, settings);
      const std::string what = "front " + std::to_string(front) + (groundIsA ? ", ground is A" : ", ground is B") +
                               " (minimum translation " + std::to_string(minTravel) + " m, tilted " +
                               std::to_string(minTilt / kDegree) + " deg)";
      double deepestContact = 0.0;
      Vec3 deepestPush = Vec3::UnitZ();
      for (const Contact& c : r.contacts) {
        // The direction the box is pushed: along the normal (B to A) when the box is A.
        const Vec3 push = groundIsA ? Vec3(-c.normal) : c.normal;
        EXPECT_LE(angleBetween(push, Vec3::UnitZ()), minTilt + angleSlack) << what;
        EXPECT_LE(push.x(), rounding) << what << ": pushed forward, into the bump";
        if (c.depth > deepestContact) deepestContact = c.depth, deepestPush = push;
      }
      EXPECT_GE(deepestContact, deepest - rounding) << what;
      // On the flank the push tilts back by at least a quarter of the minimum translation's tilt
      // (the flat part's vertices, pressed 0.5 mm, dilute the flank's normals in the mean);
      // straight up, the box crossed the bump without turning.
      if (front < bx) {
        EXPECT_GE(angleBetween(deepestPush, Vec3::UnitZ()), 0.25 * minTilt) << what;
      }
      ++cases;
    }
  }
  EXPECT_EQ(cases, 8);
}

// A unit cube rolled 2 deg about x, its low bottom edge 1 mm into the flat part of the bumped
// ground (a non-convex mesh, so its flat leaves are patches of a larger surface). Oracle: the
// cube's two low corners, by construction -- their positions and their depth below the plane
// z = 0. cfm must give exactly them, along the floor's normal, with error bound 0. Before, the
// floor's flat leaves (more vertices than a faceted patch keeps) counted as curved patches: the
// contacts stood along the floor normal at the floor spheres' centres, up to 0.24 m inside the
// edge, with the spheres' error bound (1.3 m), and turned a box riding over the bump the wrong
// way (flat-contact: cfm 58 mm rms from the exact track).
TEST(CoarseContacts, CubeOnOneEdgeOverAFlatPieceOfANonConvexFloorRestsOnItsTwoLowCorners) {
  static const CollisionBody ground = octreeBodyForCfm(makeBumpedSlab(1.6, 1.0, 0.6, 0.04, 0.2));
  const CollisionBody& cube = slabBodies().cube;
  const double roll = 2.0 * kDegree, sunk = 0.001;
  const Quat q(Eigen::AngleAxisd(roll, Vec3::UnitX()));
  // The low edge is the one at local y = -0.5, z = -0.5; lift the centre so it lies `sunk` deep.
  const Vec3 lowLocal(0.0, -0.5, -0.5);
  const Pose pose{q, Vec3(-0.4, 0.1, -sunk - (q * lowLocal).z())};
  const Vec3 corners[2] = {pose.apply(Vec3(-0.5, -0.5, -0.5)), pose.apply(Vec3(0.5, -0.5, -0.5))};
  // Float face normals and bake rounding over the ground's ~3.8 m diagonal.
  const double rounding = 1e-6 * ground.diagonal();
  for (bool groundIsA : {true, false}) {
    QuerySettings settings;
    settings.model = ContactModel::kCfm;
    const QueryResult r = groundIsA ? queryContacts(ground, Pose{}, cube, pose, settings)
                                    : queryContacts(cube, pose, ground, Pose{}, settings);
    const std::string what = groundIsA ? "ground is A" : "ground is B";
    ASSERT_EQ(r.contacts.size(), 2u) << what;
    bool found[2] = {false, false};
    for (const Contact& c : r.contacts) {
      const Vec3 push = groundIsA ? Vec3(-c.normal) : c.normal;
      EXPECT_LT(angleBetween(push, Vec3::UnitZ()), 1e-6) << what;
      EXPECT_NEAR(c.depth, sunk, rounding) << what;
      EXPECT_EQ(c.errorBound, 0.0) << what;
      for (int k = 0; k < 2; ++k) {
        // The point lies halfway along the depth, above the corner.
        if ((c.point - (corners[k] + 0.5 * sunk * Vec3::UnitZ())).norm() < rounding) found[k] = true;
      }
    }
    EXPECT_TRUE(found[0] && found[1]) << what;
  }
}

// A 0.5 m box standing 1 mm deep on the floor of a closed L-shaped body (test::makeLShapedBody), once in the open and once in the
// corner with its +x face flush with the wall. Oracle, by construction: the contact is the four
// bottom corners, 1 mm below the plane z = 0, pushed straight up. The separating-axis choice
// treated the L's patches as their convex hull, in whose pocket the box stands: the least overlap
// was downward, through the floor (0.999 deep; the box fell through at 16 and 64 tests per frame,
// cfm and exact alike). cfm at 1 test to unlimited, and exact where it answers from the spheres
// (1-16 tests: its traversal does not finish, so every pair falls back to cfm; at 64 it finishes
// and tests some triangle pairs, whose partial patches are not this test's subject) and at an
// unlimited budget (its triangle pairs that only touch -- the box's side face in the wall's plane
// -- had joined the floor's patch, whose normal turned 45 deg toward the wall, and the wall's
// coplanar patch read 26 mm deep); both orders of the bodies.
TEST(CoarseContacts, BoxOnTheFloorOfAnLShapedBodyIsHeldUpByItsCornersAtEveryBudget) {
  static const CollisionBody ground = octreeBodyForCfm(test::makeLShapedBody());
  static const CollisionBody box = octreeBodyForCfm(makeBox(Vec3::Constant(0.25)));
  ASSERT_TRUE(ground.isClosed());
  ASSERT_FALSE(ground.isConvexPolyhedron());
  constexpr double kSunk = 0.001;
  const double rounding = 1e-9 * (ground.diagonal() + box.diagonal());  // float-free: exact corners
  for (const double x : {-1.0, 0.75}) {
    const Pose pose{Quat::Identity(), Vec3(x, 0.3, 0.25 - kSunk)};
    for (const ContactModel model : {ContactModel::kCfm, ContactModel::kExact}) {
      for (const std::uint64_t budget : {std::uint64_t(1), std::uint64_t(4), std::uint64_t(16), std::uint64_t(64), std::uint64_t(256), kUnlimitedTests}) {
        if (model == ContactModel::kExact && budget > 16 && budget != kUnlimitedTests) continue;
        for (const bool groundIsA : {true, false}) {
          const QuerySettings settings = settingsFor(model, budget);
          const QueryResult r = groundIsA ? queryContacts(ground, Pose{}, box, pose, settings)
                                          : queryContacts(box, pose, ground, Pose{}, settings);
          const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget) +
                                   " tests, box at x = " + std::to_string(x) + (groundIsA ? ", ground is A" : ", ground is B");
          bool found[4] = {false, false, false, false};
          for (const Contact& c : r.contacts) {
            const Vec3 push = groundIsA ? Vec3(-c.normal) : c.normal;  // the box's way out
            // The exact model's face flush against the wall touches it: depth 0, along -x.
            if (x > 0.0 && std::abs(c.depth) <= rounding) {
              EXPECT_LT(angleBetween(push, -Vec3::UnitX()), 1e-6) << what << ": contact at " << c.point.transpose();
              continue;
            }
            EXPECT_LT(angleBetween(push, Vec3::UnitZ()), 1e-6) << what << ": contact at " << c.point.transpose();
            EXPECT_NEAR(c.depth, kSunk, rounding) << what;
            for (int k = 0; k < 4; ++k) {
              const Vec3 corner = pose.apply(Vec3(k & 1 ? 0.25 : -0.25, k & 2 ? 0.25 : -0.25, -0.25));
              if ((c.point - (corner + 0.5 * kSunk * Vec3::UnitZ())).norm() < 1e-9) found[k] = true;
            }
          }
          EXPECT_TRUE(found[0] && found[1] && found[2] && found[3]) << what << ": " << r.contacts.size() << " contacts";
        }
      }
    }
  }
}

// A closed non-convex body (the L, turned 20 deg about x and 10 deg about y) and a box, turned
// onto a corner, sunk 1 cm into a two-triangle floor (8 x 4 m: what a user's ground mesh is). Oracle: the floor is the plane z = 0, so
// each vertex's depth is -z, and the deepest vertex is the penetration. Every contact of cfm (and
// of exact: its cfm fallback below 64 tests, its triangle-level answer unlimited) pushes the body
// up, none is deeper than the deepest vertex, and the deepest contact is it. Before, the L got one
// contact at the roots' spheres, and at full depth its leaves' cfm normals below the plane pointed
// down, through the floor (a spot on such a floor sank 18 % of its size); the exact model ignored
// vertices behind an open body's triangles and hung a box from the floor's vertices, 23 cm under.
TEST(CoarseContacts, BodiesSunkIntoATwoTriangleFloorArePushedUpFromTheirDeepestVertex) {
  static const CollisionBody floor = octreeBodyForCfm(test::makeFloorQuad(4.0, 2.0));
  ASSERT_FALSE(floor.isClosed());
  const Quat turn = Quat(Eigen::AngleAxisd(20.0 * M_PI / 180.0, Vec3::UnitX())) *
                    Quat(Eigen::AngleAxisd(10.0 * M_PI / 180.0, Vec3::UnitY()));
  const Quat corner = Quat(Eigen::AngleAxisd(0.6, Vec3(1, 1, 0).normalized()));
  const std::pair<TriangleMesh, Quat> bodies[] = {{test::makeLShapedBody(), turn},
                                                  {makeBox(Vec3(0.3, 0.2, 0.4)), corner}};
  constexpr double kSunk = 0.01;
  for (const auto& [mesh, q] : bodies) {
    const CollisionBody body = octreeBodyForCfm(mesh);
    double lowest = INFINITY;
    for (const Vec3& v : mesh.vertices) lowest = std::min(lowest, (q * v).z());
    const Pose pose{q, Vec3(0.3, -0.2, -lowest - kSunk)};
    // Rounding of the vertices' transforms, relative to the bodies' size.
    const double rounding = 1e-9 * (floor.diagonal() + body.diagonal());
    for (const ContactModel model : {ContactModel::kCfm, ContactModel::kExact}) {
      for (const std::uint64_t budget : {std::uint64_t(1), std::uint64_t(4), std::uint64_t(16), std::uint64_t(64), kUnlimitedTests}) {
        if (model == ContactModel::kExact && budget > 16 && budget != kUnlimitedTests) continue;
        for (const bool floorIsA : {true, false}) {
          const QuerySettings settings = settingsFor(model, budget);
          const QueryResult r = floorIsA ? queryContacts(floor, Pose{}, body, pose, settings)
                                         : queryContacts(body, pose, floor, Pose{}, settings);
          const std::string what = std::string(contactModelName(model)) + " at " + std::to_string(budget) + " tests, " +
                                   std::to_string(mesh.triangleCount()) + " triangles" + (floorIsA ? ", floor is A" : ", floor is B");
          ASSERT_FALSE(r.contacts.empty()) << what;
          // The exact model interrupted within its triangle tests keeps, beside its cfm fallback,
          // the curve points of the patches tested so far, along their pieces' penetration-volume
          // normal (a partial volume: docs/narrow-phase.md, Known limits), measured 2.2e-5 rad
          // off at 4 tests: 0.01 deg there.
          const bool partialExact = model == ContactModel::kExact && !r.finished;
          const double angleTolerance = partialExact ? 0.01 * M_PI / 180.0 : 1e-6;
          double deepest = -INFINITY;
          for (const Contact& c : r.contacts) {
            const Vec3 push = floorIsA ? Vec3(-c.normal) : c.normal;  // the body's way out
            EXPECT_LT(angleBetween(push, Vec3::UnitZ()), angleTolerance) << what << ": contact at " << c.point.transpose();
            EXPECT_LE(c.depth, kSunk + rounding) << what;
            deepest = std::max(deepest, c.depth);
          }
          EXPECT_NEAR(deepest, kSunk, rounding) << what;
        }
      }
    }
  }
}

// A ball (an icosphere of radius 0.25: a convex body whose patches above the leaves are curved)
// 0.5 mm deep on the L's floor, touching its wall. Oracle, by construction: the ball's lowest
// vertex is the one point inside the floor, so every contact lies near the ball (within its
// diameter of its centre), pushes it up or away from the wall, and is no deeper than 0.5 mm. Before, the
// L's far corners (2.5 m away) lay behind the few face planes of the ball's leaves and came back
// as contacts 0.1-0.9 m "deep" at 256 tests and up (the ball rolled 60 cm off the wall), and at
// 16-64 tests the curved patches took the L's hull: pushed down, the ball fell through.
TEST(CoarseContacts, BallInTheCornerOfAnLShapedBodyGetsContactsOnlyWhereItIs) {
  static const CollisionBody ground = octreeBodyForCfm(test::makeLShapedBody());
  static const CollisionBody ball = octreeBodyForCfm(makeIcosphere(0.25, 2));
  constexpr double kSunk = 0.0005;
  const Vec3 centre(0.75, 0.3, 0.25 - kSunk);
  const double rounding = 1e-9 * (ground.diagonal() + ball.diagonal());
  for (const std::uint64_t budget : {std::uint64_t(16), std::uint64_t(64), std::uint64_t(256), std::uint64_t(1024), kUnlimitedTests}) {
    const QueryResult r = queryContacts(ground, Pose{}, ball, Pose{Quat::Identity(), centre}, settingsFor(ContactModel::kCfm, budget));
    const std::string what = "cfm at " + std::to_string(budget) + " tests";
    EXPECT_FALSE(r.contacts.empty()) << what;
    for (const Contact& c : r.contacts) {
      // Near the ball: a coarse pair's separating-axis contact stands in the two patches' common
      // extent (2.6 cm outside the ball on the wall at 256 tests), not at the L's corners 2.5 m away.
      EXPECT_LE((c.point - centre).norm(), 2.0 * 0.25) << what << ": contact at " << c.point.transpose();
      EXPECT_LE(c.depth, kSunk + rounding) << what << ": contact at " << c.point.transpose();
      const Vec3 push = -c.normal;  // the ball is B: it leaves along -n
      EXPECT_TRUE(push.z() > 0.99 || push.x() < -0.99) << what << ": pushed along " << push.transpose();
    }
  }
}

// A contact-tree sample half a coarse cell below one face of a thin body lies past its far face,
// outside it: the other body's field there is no penetration. A flat box (1.08 x 0.6 x 0.45) on
// a slab, tipped onto one long edge, got contacts 5-10 cm "deep" at 16-42 tests from such points
// (its root cell is 1.1 m), was lifted and tipped 14 degrees. Oracle: the box's vertices -- the
// deepest penetration of a box into a slab is its lowest vertex's. No contact may be deeper than
// that beyond its own error bound. Fails with the unchecked layer (0.12 m deep at 9.5 degrees).
TEST(CoarseContacts, ContactTreeSamplesOutsideAThinBodyGiveNoPhantomPenetration) {
  const Vec3 half(0.54, 0.3, 0.225);
  const TriangleMesh plate = makeBox(half);
  const CollisionBody body = bakeLikeTheWorldTest(plate);
  const SlabBodies& b = slabBodies();
  for (double tiltDeg : {0.0, 5.0, 9.5, 20.0}) {
    Pose pose;
    pose.rotation = Quat(Eigen::AngleAxisd(tiltDeg * kDegree, Vec3(1.0, 0.6, 0.0).normalized()));
    double lowest = std::numeric_limits<double>::infinity();
    for (const Vec3& v : plate.vertices) lowest = std::min(lowest, (pose.rotation * v).z());
    constexpr double kDeepest = 0.004;  // the lowest vertex 4 mm into the slab
    pose.translation = Vec3(0.1, -0.2, kSlabTop - lowest - kDeepest);
    for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(4), std::uint64_t(16), std::uint64_t(42),
                                 std::uint64_t(256), kUnlimitedTests}) {
      const QueryResult r = queryContacts(b.slab, Pose{}, body, pose, settingsFor(ContactModel::kContactTree, budget));
      const std::string what = "tilt " + std::to_string(tiltDeg) + " at " + std::to_string(budget) + " tests";
      // (Contacts at all are not asserted: at 20 degrees the 4 mm corner is a region ~2 cm
      // across, which the samples of the 16- and 42-test frontiers miss -- docs/dynamics.md,
      // "Known limits".)
      // 1e-6 of the slab's diagonal (4.2): rounding of the poses.
      for (const Contact& c : r.contacts)
        EXPECT_LE(c.depth, kDeepest + c.errorBound + 1e-6 * 4.2) << what << " at " << c.point.transpose();
    }
  }
}

}  // namespace clod

namespace clod {
namespace {

// A curved mesh pressed into a slab at a random orientation, deepestRel of its 0.8 m diagonal
// below the slab's top: every contact-tree answer, from the roots up, must see how deep it is.
// Oracle: the mesh's vertices -- the deepest point of a mesh below a plane is a vertex. Each
// answer's deepest contact must be at least half the true depth (a support point along a grid
// direction up to 4.5 degrees off the slab's normal sits above the lowest vertex by up to
// r (1 - cos 4.5 deg) ~ 0.3 % of the local radius r, here a few tenths of the true depth) and no
// contact deeper than it beyond the contact's own error bound.
void expectTheDeepestPointSeenAtEveryBudget(double deepestRel, std::uint64_t seed) {
  constexpr double kDiagonal = 0.8;
  const std::vector<std::string> names =
      test::sanitizerRun() ? std::vector<std::string>{"fandisk.obj"} : std::vector<std::string>{"fandisk.obj", "spot.obj", "bunny-1500.obj"};
  const SlabBodies& b = slabBodies();
  std::mt19937_64 rng(seed);
  for (const std::string& name : names) {
    TriangleMesh mesh = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/" + name).mesh;
    const double scale = kDiagonal / mesh.bounds().diagonal();
    for (Vec3& v : mesh.vertices) v *= scale;
    const CollisionBody body = bakeLikeTheWorldTest(mesh);
    std::normal_distribution<double> gauss;
    for (int trial = 0; trial < 6; ++trial) {
      Pose pose;
      pose.rotation = Quat(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized();
      double lowest = std::numeric_limits<double>::infinity();
      for (const Vec3& v : mesh.vertices) lowest = std::min(lowest, (pose.rotation * v).z());
      const double deepest = deepestRel * kDiagonal;
      pose.translation = Vec3(0.2, -0.1, kSlabTop - lowest - deepest);
      for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(4), std::uint64_t(16), std::uint64_t(64)}) {
        const QueryResult r = queryContacts(b.slab, Pose{}, body, pose, settingsFor(ContactModel::kContactTree, budget));
        const std::string what = name + " trial " + std::to_string(trial) + " at " + std::to_string(budget) + " tests";
        double found = -std::numeric_limits<double>::infinity();
        for (const Contact& c : r.contacts) {
          found = std::max(found, c.depth);
          // 1e-6 of the slab's diagonal (4.2): rounding of the poses.
          EXPECT_LE(c.depth, deepest + c.errorBound + 1e-6 * 4.2) << what;
        }
        EXPECT_GE(found, 0.5 * deepest) << what;
      }
    }
  }
}

// 1 % of the diagonal (8 mm). The coarse frontier's lattice samples, spread over cells a third of
// the body across, missed a contact region a few centimetres wide: fandisk's lowest corner
// 1.15 cm deep got contacts of depth 0 1.8 cm away at 16 tests, and in the world such bodies
// sank 1-15 % of their diagonal. The cells' support points (cell_support.h) hold the points that
// reach farthest.
TEST(CoarseContacts, ContactTreeSeesTheDeepestPointOfACurvedMeshAtEveryBudget) {
  expectTheDeepestPointSeenAtEveryBudget(0.01, 17);
}

// 0.1 % of the diagonal (0.8 mm), less than the slab's eps_s (1e-3 of its 5.7 m diagonal): the
// lowest support point is inside the slab by less than the slab field's refinement target, but
// the slab's leaf there is a flat face cell whose field is exact to its own bound (~1e-7 m). With
// eps_s taken as the slab field's error the samples counted as grazing and were dropped: no
// contact at 1-16 tests (docs/narrow-phase.md), and in the world a landing bunny sank with no
// contact for four frames.
TEST(CoarseContacts, ContactTreeSeesAShallowPenetrationOfACurvedMeshIntoAFlatFaceAtEveryBudget) {
  expectTheDeepestPointSeenAtEveryBudget(0.001, 23);
}

// A curved mesh hovering just above a slab: an interrupted contact-tree answer must not report
// it touching. Oracle: the mesh's vertices -- the gap between a mesh and a plane below it is its
// lowest vertex's height. A lattice point that the slide along S's surface accepted up to its
// projection tolerance off that surface (4.4 mm outside spot's hind feet, S's field bounding its
// own error there by 2.5 mm) lay on the slab's top: zero-depth contacts on two feet at 62 and
// 128 tests, 3 mm before the feet arrived. In the world spot stopped on them at 60 Hz, turned
// about them and toppled at 2,048-8,192 tests per frame. The gap here (2 mm, 2.7 eps_s) is the
// one spot had there; every contact fails (before the fix: 2-3 at 62 and 128 tests).
TEST(CoarseContacts, ContactTreeGivesNoContactToACurvedMeshHoveringAboveASlab) {
  constexpr double kDiagonal = 0.75, kGapRel = 0.0027;
  const SlabBodies& b = slabBodies();
  TriangleMesh mesh = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/spot.obj").mesh;
  const double scale = kDiagonal / mesh.bounds().diagonal();
  for (Vec3& v : mesh.vertices) v *= scale;
  const CollisionBody body = bakeLikeTheWorldTest(mesh);
  // Standing on its feet (spot is modelled y-up) as it was dropped, and tipped a few degrees.
  for (double tiltDeg : {0.0, 3.0, -3.0}) {
    Pose pose;
    pose.rotation = Quat(Eigen::AngleAxisd(tiltDeg * kDegree, Vec3::UnitY())) * Quat(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()));
    double lowest = std::numeric_limits<double>::infinity();
    for (const Vec3& v : mesh.vertices) lowest = std::min(lowest, (pose.rotation * v).z());
    pose.translation = Vec3(0.0, 0.055, kSlabTop - lowest + kGapRel * kDiagonal);
    for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(16), std::uint64_t(62), std::uint64_t(128),
                                 std::uint64_t(256), std::uint64_t(1024), kUnlimitedTests}) {
      const QueryResult r = queryContacts(b.slab, Pose{}, body, pose, settingsFor(ContactModel::kContactTree, budget));
      const std::string what = "tilt " + std::to_string(tiltDeg) + " at " + std::to_string(budget) + " tests";
      for (const Contact& c : r.contacts) ADD_FAILURE() << what << ": contact at " << c.point.transpose() << " depth " << c.depth;
    }
  }
}

}  // namespace
}  // namespace clod
