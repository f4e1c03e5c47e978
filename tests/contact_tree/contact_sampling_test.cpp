// Contact sampling between two contact trees, on boxes whose contact has an analytic answer.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>

#include "clod/contact_sampling.h"
#include "clod/contact_tree_builder.h"
#include "clod/error.h"
#include "clod/primitives.h"
#include "clod/proximity.h"

namespace clod {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Boxes {
  Vec3 halfA = Vec3::Constant(0.5);  // the upper, smaller box
  Vec3 halfB = Vec3::Constant(1.0);  // the lower box, at the origin
  ContactTree treeA, treeB;
  Boxes() {
    ContactTreeSettings settings;
    settings.errorRel = 2e-3;
    treeA = buildContactTree(MeshDistance(makeBox(halfA)), settings);
    treeB = buildContactTree(MeshDistance(makeBox(halfB)), settings);
  }
};

const Boxes& boxes() {
  static const Boxes b;
  return b;
}

// Pose of A resting on B's top face with its bottom `penetration` below it, rotated by `yaw`
// about z and centred at (x, y).
Pose restingPose(double x, double y, double yaw, double penetration) {
  Pose pose;
  pose.rotation = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  pose.translation = Vec3(x, y, boxes().halfB.z() + boxes().halfA.z() - penetration);
  return pose;
}

// The overlap region of a resting A (wholly above B's top face) is A's bottom face.
std::vector<Vec3> bottomCorners(const Pose& pose) {
  const Vec3 h = boxes().halfA;
  std::vector<Vec3> corners;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) corners.push_back(pose.apply(Vec3(sx * h.x(), sy * h.y(), -h.z())));
  return corners;
}

void expectRestingContacts(const Pose& poseA, double penetration) {
  const Boxes& b = boxes();
  ContactSamplingSettings settings;
  std::vector<ContactPoint> contacts;
  ContactQueryStats stats;
  findContacts(b.treeA, poseA, b.treeB, Pose{}, settings, contacts, &stats);
  // Raw samples cover the whole face; thinning leaves one patch of four.
  EXPECT_GT(stats.rawContacts, 20u);
  ASSERT_GE(contacts.size(), 4u);
  EXPECT_LE(contacts.size(), 8u);
  const double tolerance = b.treeB.errorAbs + b.treeA.errorAbs;
  for (const ContactPoint& c : contacts) {
    EXPECT_GT(c.normal.z(), std::cos(kPi / 180.0)) << "normal " << c.normal.transpose() << " at " << c.point.transpose();
    EXPECT_NEAR(c.depth, penetration, tolerance) << c.point.transpose();
  }
  // "Spread to the corners": each corner of the overlap has a contact within 5 % of the
  // overlap's side (1.0 here): the sampling spacing near a corner is a fraction of that.
  for (const Vec3& corner : bottomCorners(poseA)) {
    double nearest = 1e9;
    for (const ContactPoint& c : contacts) nearest = std::min(nearest, (c.point - corner).head<2>().norm());
    EXPECT_LT(nearest, 0.05) << "corner " << corner.transpose();
  }
}

TEST(ContactSampling, BoxRestingOnBoxGetsFourContactsAtTheOverlapCorners) {
  expectRestingContacts(restingPose(0.3, -0.2, 0.0, 1e-3), 1e-3);
}

TEST(ContactSampling, RotatedBoxRestingOnBoxKeepsFaceNormalsAndCorners) {
  expectRestingContacts(restingPose(0.1, 0.05, 30.0 * kPi / 180.0, 2e-3), 2e-3);
}

TEST(ContactSampling, TiltedLowerBoxStillGivesItsFaceNormal) {
  // The whole scene rotated: B tilted by 20 degrees about x, A resting on it.
  Pose tilt;
  tilt.rotation = Quat(Eigen::AngleAxisd(20.0 * kPi / 180.0, Vec3::UnitX()));
  const Pose poseA = tilt * restingPose(-0.1, 0.2, 0.4, 1e-3);
  std::vector<ContactPoint> contacts;
  findContacts(boxes().treeA, poseA, boxes().treeB, tilt, ContactSamplingSettings{}, contacts);
  ASSERT_GE(contacts.size(), 4u);
  const Vec3 up = tilt.rotation * Vec3::UnitZ();
  for (const ContactPoint& c : contacts) EXPECT_GT(c.normal.dot(up), std::cos(kPi / 180.0));
}

TEST(ContactSampling, SeparatedBoxesGetContactsOnlyWithinTheMargin) {
  const Boxes& b = boxes();
  const Pose poseA = restingPose(0.0, 0.0, 0.0, -0.01);  // 0.01 gap
  std::vector<ContactPoint> contacts;
  findContacts(b.treeA, poseA, b.treeB, Pose{}, ContactSamplingSettings{}, contacts);
  EXPECT_TRUE(contacts.empty());
  ContactSamplingSettings withMargin;
  withMargin.marginAbs = 0.02;
  findContacts(b.treeA, poseA, b.treeB, Pose{}, withMargin, contacts);
  ASSERT_GE(contacts.size(), 4u);
  for (const ContactPoint& c : contacts) {
    EXPECT_NEAR(c.depth, -0.01, b.treeA.errorAbs + b.treeB.errorAbs);
    EXPECT_GT(c.normal.z(), std::cos(kPi / 180.0));
  }
}

TEST(ContactSampling, DeeplyInterpenetratingBoxesStillGetContacts) {
  // A sunk 0.3 into B: far outside the 1 % band, where only the coarse field exists.
  const Boxes& b = boxes();
  std::vector<ContactPoint> contacts;
  ContactQueryStats stats;
  findContacts(b.treeA, restingPose(0.0, 0.0, 0.0, 0.3), b.treeB, Pose{}, ContactSamplingSettings{}, contacts, &stats);
  ASSERT_FALSE(contacts.empty());
  bool upward = false;
  for (const ContactPoint& c : contacts) {
    EXPECT_GT(c.depth, 0.0);
    // No point of either box is deeper than 0.3 + the cells' error bounds inside the other.
    EXPECT_LE(c.depth, 0.3 + c.errorBound + 1e-6);
    upward = upward || (c.normal.z() > std::cos(kPi / 180.0) && std::abs(c.depth - 0.3) <= c.errorBound + 1e-3);
  }
  EXPECT_TRUE(upward) << "the bottom face must be pushed up by the penetration depth";
  // Inside, the coarse field's gradient turns between faces near the medial surfaces, so there
  // are more patches than faces, but thinning must still remove the bulk of the samples.
  EXPECT_LE(contacts.size() * 10, stats.rawContacts) << contacts.size() << " of " << stats.rawContacts;
}

// Two boxes crossed edge-on: B (the 1-box) turned 45 degrees about y, so its top edge runs
// along y at height sqrt(2); A (the 0.5-box) turned 45 degrees about x (then yawed), so its
// bottom edge is horizontal, sunk `penetration` below B's edge. Two crossing edges touch along
// their common perpendicular, which is +z here whatever the yaw: the analytic normal.
struct CrossedEdges {
  Pose poseA, poseB;
};
CrossedEdges crossedEdges(double yaw, double penetration) {
  CrossedEdges c;
  c.poseB.rotation = Quat(Eigen::AngleAxisd(kPi / 4.0, Vec3::UnitY()));
  c.poseA.rotation = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ())) * Quat(Eigen::AngleAxisd(kPi / 4.0, Vec3::UnitX()));
  c.poseA.translation = Vec3(0.0, 0.0, std::sqrt(2.0) * (boxes().halfB.x() + boxes().halfA.y()) - penetration);
  return c;
}

void expectEdgeEdgeNormalsVertical(double yaw) {
  // Deeper than both trees' eps_s (3.5e-3 and 6.9e-3), so the overlap is resolved by the fields.
  const double penetration = 1e-2;
  const CrossedEdges pose = crossedEdges(yaw, penetration);
  std::vector<ContactPoint> contacts;
  ContactQueryStats stats;
  findContacts(boxes().treeA, pose.poseA, boxes().treeB, pose.poseB, ContactSamplingSettings{}, contacts, &stats);
  ASSERT_FALSE(contacts.empty());
  EXPECT_GT(stats.edgeEdgeNormals, 0u);
  const Vec3 crossing(0.0, 0.0, std::sqrt(2.0) * boxes().halfB.x());
  for (const ContactPoint& c : contacts) {
    // 1 degree, as for faces: both box fields are exactly invariant along their edges (in the
    // box frames), so the estimated edge directions are exact up to float rounding.
    EXPECT_GT(c.normal.z(), std::cos(kPi / 180.0)) << "normal " << c.normal.transpose() << " at " << c.point.transpose();
    // The overlap is a tiny tetrahedron at the crossing; no contact may be deeper than the
    // penetration (plus both trees' eps) or far from it.
    EXPECT_LE(c.depth, penetration + boxes().treeA.errorAbs + boxes().treeB.errorAbs);
    EXPECT_LT((c.point - crossing).norm(), 0.05);
  }
}

TEST(ContactSampling, CrossedEdgesGetTheCommonPerpendicularAsNormal) { expectEdgeEdgeNormalsVertical(0.0); }

TEST(ContactSampling, SkewCrossedEdgesGetTheCommonPerpendicularAsNormal) { expectEdgeEdgeNormalsVertical(kPi / 6.0); }

// A's flat bottom face overhangs B's top edge x = 1, with A's own bottom edge parallel to it and
// 0.02..0.3 past it: only B has an edge at the samples along there, so the contact is
// face-on-edge and its normal is A's face normal, +z (analytic). Both edges lie within the
// edge-edge rule's probe radius, which must not take them for a touching edge pair (it did, and
// tilted these normals by 17..18 degrees). Thinning is turned off so that every raw contact is
// checked (it would otherwise hide tilted ones inside the face's patch). Excluded: contacts
// within 0.3 of the two points (1, +-0.5) where A's edges y = +-0.5 really cross B's edge --
// the rule's own case, tested above; 0.3 bounds its probe radius there (twice the leaf cell).
TEST(ContactSampling, FaceOverhangingAParallelEdgeKeepsTheFaceNormal) {
  ContactSamplingSettings settings;
  settings.maxContactsPerPatch = std::numeric_limits<std::uint32_t>::max();
  for (double overhang : {0.02, 0.05, 0.1, 0.3}) {
    const Pose poseA = restingPose(0.5 + overhang, 0.0, 0.0, 2e-3);
    std::vector<ContactPoint> contacts;
    findContacts(boxes().treeA, poseA, boxes().treeB, Pose{}, settings, contacts);
    int checked = 0;
    for (const ContactPoint& c : contacts) {
      if ((c.point.head<2>() - Eigen::Vector2d(1.0, std::copysign(0.5, c.point.y()))).norm() < 0.3) continue;
      ++checked;
      // 1 degree, as for resting faces above.
      EXPECT_GT(c.normal.z(), std::cos(kPi / 180.0))
          << "overhang " << overhang << " normal " << c.normal.transpose() << " at " << c.point.transpose();
    }
    EXPECT_GT(checked, 20) << overhang;  // the face contacts along the overhung edge are there
  }
}

TEST(ContactSampling, OneFieldGradientAloneTiltsCrossedEdgeNormals) {
  // Shows what the edge-edge rule repairs (and that the test above can fail): with it off,
  // the gradient of one body's field near its edge leans toward one of its faces.
  const CrossedEdges pose = crossedEdges(0.0, 1e-2);
  ContactSamplingSettings settings;
  settings.edgeEdgeNormals = false;
  std::vector<ContactPoint> contacts;
  findContacts(boxes().treeA, pose.poseA, boxes().treeB, pose.poseB, settings, contacts);
  ASSERT_FALSE(contacts.empty());
  double worst = 1.0;
  for (const ContactPoint& c : contacts) worst = std::min(worst, c.normal.z());
  EXPECT_LT(worst, std::cos(10.0 * kPi / 180.0));
}

// Leaf half-space pruning must only skip pairs that cannot produce a contact: the raw samples
// of the unpruned traversal (the oracle) are reproduced exactly, with fewer pairs visited.
void expectPruningChangesNothing(const ContactTree& a, const Pose& poseA, const ContactTree& b, const Pose& poseB,
                                 double margin) {
  ContactSamplingSettings on, off;
  on.marginAbs = off.marginAbs = margin;
  off.leafHalfSpacePruning = false;
  on.maxContactsPerPatch = off.maxContactsPerPatch = 1u << 30;  // no thinning: compare every sample
  std::vector<ContactPoint> withPruning, without;
  ContactQueryStats statsOn, statsOff;
  findContacts(a, poseA, b, poseB, on, withPruning, &statsOn);
  findContacts(a, poseA, b, poseB, off, without, &statsOff);
  ASSERT_FALSE(without.empty());
  ASSERT_EQ(withPruning.size(), without.size());
  auto key = [](const ContactPoint& c) { return std::make_tuple(c.point.x(), c.point.y(), c.point.z(), c.sampledBody); };
  auto byKey = [&](const ContactPoint& x, const ContactPoint& y) { return key(x) < key(y); };
  std::sort(withPruning.begin(), withPruning.end(), byKey);
  std::sort(without.begin(), without.end(), byKey);
  for (std::size_t i = 0; i < without.size(); ++i) {
    ASSERT_EQ(withPruning[i].point, without[i].point);
    ASSERT_EQ(withPruning[i].normal, without[i].normal);
    ASSERT_EQ(withPruning[i].depth, without[i].depth);
  }
  EXPECT_GT(statsOn.halfSpacePrunes, 0u);
  EXPECT_EQ(statsOff.halfSpacePrunes, 0u);
  EXPECT_LT(statsOn.cellPairsVisited, statsOff.cellPairsVisited);
}

TEST(ContactSampling, LeafHalfSpacePruningKeepsEverySampleOfRestingBoxes) {
  expectPruningChangesNothing(boxes().treeA, restingPose(0.3, -0.2, 0.5, 1e-3), boxes().treeB, Pose{}, 0.0);
}

TEST(ContactSampling, LeafHalfSpacePruningKeepsEverySampleWithAMargin) {
  expectPruningChangesNothing(boxes().treeA, restingPose(0.1, 0.1, 0.2, -5e-3), boxes().treeB, Pose{}, 0.01);
}

TEST(ContactSampling, LeafHalfSpacePruningKeepsEverySampleOfCrossedEdges) {
  const CrossedEdges pose = crossedEdges(kPi / 6.0, 1e-2);
  expectPruningChangesNothing(boxes().treeA, pose.poseA, boxes().treeB, pose.poseB, 0.0);
}

TEST(ContactReduction, PlanarGridKeepsItsFourCorners) {
  std::vector<ContactPoint> contacts;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) contacts.push_back({Vec3(i * 0.1, j * 0.1, 0.0), Vec3::UnitZ(), 0.01, 0.0, 0});
  reduceContacts(contacts, ContactSamplingSettings{});
  ASSERT_EQ(contacts.size(), 4u);
  for (const Vec3& corner : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}) {
    bool found = false;
    for (const ContactPoint& c : contacts) found = found || (c.point - corner).norm() < 1e-12;
    EXPECT_TRUE(found) << corner.transpose();
  }
}

TEST(ContactReduction, OpposingNormalsFormSeparatePatches) {
  std::vector<ContactPoint> contacts;
  for (int i = 0; i < 10; ++i) {
    contacts.push_back({Vec3(i, 0, 0), Vec3::UnitZ(), 0.1, 0.0, 0});
    contacts.push_back({Vec3(i, 5, 0), -Vec3::UnitZ(), 0.2, 0.0, 0});
  }
  ContactSamplingSettings settings;
  settings.maxContactsPerPatch = 2;
  reduceContacts(contacts, settings);
  ASSERT_EQ(contacts.size(), 4u);
  int up = 0;
  for (const ContactPoint& c : contacts) up += c.normal.z() > 0;
  EXPECT_EQ(up, 2);
}

TEST(ContactSampling, RejectsOutOfRangeSettings) {
  ContactSamplingSettings settings;
  settings.samplesPerCellAxis = 0;
  std::vector<ContactPoint> contacts;
  try {
    findContacts(boxes().treeA, Pose{}, boxes().treeB, Pose{}, settings, contacts);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("samplesPerCellAxis"), std::string::npos);
  }
}

}  // namespace
}  // namespace clod
