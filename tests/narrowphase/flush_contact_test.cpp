// Flush and coplanar contact (issue 18, point 1): boxes whose side faces are coplanar with the
// other box's side faces, facing the same way. Such a face touches nothing it could press on, so
// no model may return a contact that pushes along it. Oracle: the analytic contact of two boxes
// in each configuration -- normal, penetration and the corners of the overlap region -- written
// down from the poses, not computed by the narrow phase.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "clod/primitives.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"
#include "support/grid_box.h"

namespace clod {
namespace {

using test::settingsFor;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;
constexpr double kPenetration = 0.01;

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Bodies {
  // Unit cubes and a half-size cube: 12-triangle convex polyhedra, with sphere-trees, closest
  // feature maps and contact trees (narrowphase_test_support.h).
  CollisionBody unit = test::makeTestBody(makeBox(Vec3::Constant(0.5)), 2);
  CollisionBody half = test::makeTestBody(makeBox(Vec3::Constant(0.25)), 2);
  // The same cubes with every face split into 4 x 4 squares (98 vertices, 192 triangles): convex
  // polyhedra whose faces are many triangles, as a CAD export or a remeshed box has them.
  CollisionBody gridUnit = test::makeTestBody(test::makeGridBox(Vec3::Constant(0.5), 4), 2);
  CollisionBody gridHalf = test::makeTestBody(test::makeGridBox(Vec3::Constant(0.25), 4), 2);
};

const Bodies& bodies() {
  static const Bodies b;
  return b;
}

// One configuration: A (posed) on B (the unit cube at the origin, top face at z = 0.5).
struct Configuration {
  std::string name;
  bool smallA = false;  // A is the half-size cube
  Pose poseA;
  Vec3 normal = Vec3::UnitZ();  // the analytic contact normal (B -> A); unused when !faceNormal
  bool faceNormal = true;       // false: edge on a parallel edge, the normal is not unique
  double depth = kPenetration;  // the analytic penetration along `normal`
  std::vector<Vec3> flushNormals;   // outward normals of the flush side faces (world)
  std::vector<Vec3> corners;        // corners of the overlap region in the contact plane
};

std::vector<Configuration> configurations() {
  const double p = kPenetration;
  const double r2 = std::sqrt(2.0);
  const Quat aboutX45(Eigen::AngleAxisd(45.0 * kDegree, Vec3::UnitX()));
  const Quat aboutZ30(Eigen::AngleAxisd(30.0 * kDegree, Vec3::UnitZ()));
  std::vector<Configuration> out;
  {  // face on face, shifted along x: the faces at +-y are flush (the example)
    Configuration c{"shifted along x", false, Pose{Quat::Identity(), Vec3(0.3, 0.0, 1.0 - p)}, Vec3::UnitZ(), true, p, {}, {}};
    c.flushNormals = {Vec3::UnitY(), -Vec3::UnitY()};
    c.corners = {{-0.2, -0.5, 0.5}, {0.5, -0.5, 0.5}, {0.5, 0.5, 0.5}, {-0.2, 0.5, 0.5}};
    out.push_back(c);
  }
  {  // a box on an equal box: all four side faces flush
    Configuration c{"equal box on a box", false, Pose{Quat::Identity(), Vec3(0.0, 0.0, 1.0 - p)}, Vec3::UnitZ(), true, p, {}, {}};
    c.flushNormals = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY()};
    c.corners = {{-0.5, -0.5, 0.5}, {0.5, -0.5, 0.5}, {0.5, 0.5, 0.5}, {-0.5, 0.5, 0.5}};
    out.push_back(c);
  }
  {  // a half-size box in the corner of the top face: its +x and +y faces flush with B's
    Configuration c{"small box in a corner", true, Pose{Quat::Identity(), Vec3(0.25, 0.25, 0.75 - p)}, Vec3::UnitZ(), true, p, {}, {}};
    c.flushNormals = {Vec3::UnitX(), Vec3::UnitY()};
    c.corners = {{0.0, 0.0, 0.5}, {0.5, 0.0, 0.5}, {0.5, 0.5, 0.5}, {0.0, 0.5, 0.5}};
    out.push_back(c);
  }
  {  // edge on a face: A turned 45 degrees about x, its lowest edge along x on B's top face; its
     // end faces (+-x) flush with B's. The overlap is a strip 2p wide along the edge: its ends.
    Configuration c{"edge on a face", false, Pose{aboutX45, Vec3(0.0, 0.0, 0.5 + 0.5 * r2 - p)}, Vec3::UnitZ(), true, p, {}, {}};
    c.flushNormals = {Vec3::UnitX(), -Vec3::UnitX()};
    c.corners = {{-0.5, 0.0, 0.5}, {0.5, 0.0, 0.5}};
    out.push_back(c);
  }
  {  // edge on a parallel edge: both turned 45 degrees about x, flush end faces. The two faces
     // at 45 degrees tie as the least-penetration axis (depth p / sqrt 2), so only the
     // direction is checked: no push along x, and A pushed up.
    Configuration c{"edge on a parallel edge", false, Pose{aboutX45, Vec3(0.0, 0.0, r2 - p)}, Vec3::UnitZ(), false, p / r2, {}, {}};
    c.flushNormals = {Vec3::UnitX(), -Vec3::UnitX()};
    c.corners = {{-0.5, 0.0, 0.5 * r2 - 0.5 * p}, {0.5, 0.0, 0.5 * r2 - 0.5 * p}};
    out.push_back(c);
  }
  {  // a box turned 30 degrees about z on a box: no flush faces, the overlap is a polygon
    Configuration c{"twisted box on a box", false, Pose{aboutZ30, Vec3(0.1, 0.0, 1.0 - p)}, Vec3::UnitZ(), true, p, {}, {}};
    out.push_back(c);
  }
  return out;
}

void dump(const std::string& what, const QueryResult& r) {
  if (!std::getenv("CLOD_FLUSH_DUMP")) return;
  for (const Contact& c : r.contacts)
    std::printf("%s: p %.4f %.4f %.4f n %.5f %.5f %.5f d %.6f e %.6f\n", what.c_str(), c.point.x(), c.point.y(),
                c.point.z(), c.normal.x(), c.normal.y(), c.normal.z(), c.depth, c.errorBound);
}

// Distance from `corner` to the nearest contact, measured across z (the contact plane of every
// configuration but the parallel edges, whose points lie within the penetration of it).
double nearestInPlane(const QueryResult& r, const Vec3& corner) {
  double nearest = 1e9;
  for (const Contact& c : r.contacts) {
    const Vec3 d = c.point - corner;
    nearest = std::min(nearest, Vec3(d.x(), d.y(), 0.0).norm());
  }
  return nearest;
}

Pose bPose(const Configuration& c) {
  // For the edge-on-edge configuration B is turned too, its top edge along x at z = sqrt(2)/2.
  if (!c.faceNormal) return Pose{Quat(Eigen::AngleAxisd(45.0 * kDegree, Vec3::UnitX())), Vec3::Zero()};
  return Pose{};
}

// Exact, cfm and the contact tree at an unlimited budget and at 16 tests: no contact along a
// flush side face; the analytic normal (0.01 deg) and depth (1e-6 of the diagonal); the deepest
// penetration kept; the contacts at the corners of the overlap (an edge on a face: the edge's two
// ends).
void expectAnalyticFlushContacts(const CollisionBody& unit, const CollisionBody& half) {
  const double diagonal = std::sqrt(3.0);
  // Every model answers two convex polyhedra from their faces (error bound 0): 0.01 deg and 1e-6
  // of the diagonal cover rounding only.
  const double normalTolerance = 0.01 * kDegree;
  const double depthRounding = 1e-6 * diagonal;
  for (const Configuration& config : configurations()) {
    const CollisionBody& a = config.smallA ? half : unit;
    for (ContactModel model : {ContactModel::kCfm, ContactModel::kExact, ContactModel::kContactTree})
    for (std::uint64_t budget : {std::uint64_t(16), kUnlimitedTests}) {
      const std::string what = config.name + ", " + std::string(contactModelName(model)) + " at " + std::to_string(budget);
      const QueryResult r = queryContacts(a, config.poseA, unit, bPose(config), settingsFor(model, budget));
      ASSERT_TRUE(r.finished) << what;
      ASSERT_FALSE(r.contacts.empty()) << what;
      dump(what, r);
      double deepest = -1.0;
      for (const Contact& c : r.contacts) {
        for (const Vec3& flush : config.flushNormals) {
          EXPECT_LT(std::abs(c.normal.dot(flush)), std::sin(normalTolerance))
              << what << ": pushes along a flush face, normal " << c.normal.transpose() << " at " << c.point.transpose();
        }
        if (config.faceNormal) {
          EXPECT_LT(angleBetween(c.normal, config.normal), normalTolerance) << what << ": normal " << c.normal.transpose();
          EXPECT_NEAR(c.depth, config.depth, depthRounding) << what << " at " << c.point.transpose();
        } else {
          EXPECT_GT(c.normal.z(), 0.5) << what << ": normal " << c.normal.transpose();
          EXPECT_NEAR(c.depth, config.depth, depthRounding) << what;
        }
        EXPECT_EQ(c.errorBound, 0.0) << what;
        deepest = std::max(deepest, c.depth);
      }
      EXPECT_GE(deepest, config.depth - depthRounding) << what;
      // Spread: a contact at each corner of the overlap. Two parallel edges overlap in a strip
      // as wide as the penetration, seen along the 45-degree face normal: its corners lie within
      // that width of the edges' ends.
      const double cornerTolerance = 1e-6 + (config.faceNormal ? 0.0 : kPenetration);
      for (const Vec3& corner : config.corners) {
        EXPECT_LT(nearestInPlane(r, corner), cornerTolerance) << what << ": no contact at corner " << corner.transpose();
      }
    }
  }
}


TEST(FlushContact, EveryModelGivesTheAnalyticContactOfTwoBoxesAtFlushFaces) {
  expectAnalyticFlushContacts(bodies().unit, bodies().half);
}

// The same with tessellated boxes. Their faces are many triangles, so their sphere-trees' root
// patches held more than kMaxSpherePatchVertices vertices and no model saw two convex
// polyhedra: the contact tree sampled their fields, and in the corner and on parallel edges gave
// contacts 11 deg from a flush side's normal. A whole convex body's patch now lists its corners
// alone (CollisionBody::patchIsWholeConvexBody), and every model answers as for 12 triangles.
TEST(FlushContact, EveryModelGivesTheAnalyticContactOfTwoTessellatedBoxesAtFlushFaces) {
  ASSERT_TRUE(bodies().gridUnit.patchIsWholeConvexBody(0));
  EXPECT_EQ(bodies().gridUnit.spherePatchVertices(0).size(), 8u);
  expectAnalyticFlushContacts(bodies().gridUnit, bodies().gridHalf);
}

}  // namespace
}  // namespace clod
