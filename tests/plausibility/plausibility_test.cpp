// The plausibility metric (plausibility.h) on hand-computed cases: the log-logistic form
// f(x) = 1 / (1 + (|x| / x50)^slope) gives f(x50) = 1/2 and f(2 x50) = 1 / (1 + 2^slope), and the
// constants are the documented table (30 / 20 deg, +40 / -25 %, 0.5, 2 %, x2 when not looking).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "clod/plausibility.h"
#include "clod/primitives.h"

namespace clod {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Closed forms evaluated in double: only rounding differs.
constexpr double kTol = 1e-12;

TEST(Psychometric, IsOneAtZeroHalfAtTheHalfPointAndSymmetric) {
  EXPECT_DOUBLE_EQ(psychometricPlausibility(0.0, 1.0, 3.0), 1.0);
  EXPECT_NEAR(psychometricPlausibility(2.0, 2.0, 3.0), 0.5, kTol);
  EXPECT_NEAR(psychometricPlausibility(4.0, 2.0, 3.0), 1.0 / 9.0, kTol);   // 1 / (1 + 2^3)
  EXPECT_NEAR(psychometricPlausibility(-4.0, 2.0, 3.0), 1.0 / 9.0, kTol);
  EXPECT_NEAR(psychometricPlausibility(1.0, 2.0, 2.0), 0.8, kTol);         // 1 / (1 + 1/4)
  EXPECT_EQ(psychometricPlausibility(std::numeric_limits<double>::infinity(), 1.0, 2.0), 0.0);
  EXPECT_LT(psychometricPlausibility(1e6, 1.0, 2.0), 1e-11);
}

TEST(Psychometric, EveryComponentFallsMonotonicallyWithTheDistortion) {
  for (Gaze gaze : {Gaze::kLooking, Gaze::kNotLooking}) {
    double prev[7] = {2, 2, 2, 2, 2, 2, 2};
    for (int i = 0; i <= 400; ++i) {
      const double x = 0.005 * i;
      const double now[7] = {angularDistortionPlausibility(x, gaze), angularDistortionPlausibility(-x, gaze),
                             linearVelocityPlausibility(x, gaze),    linearVelocityPlausibility(-x, gaze),
                             angularVelocityPlausibility(x, gaze),   gapPlausibility(x, gaze),
                             gapPlausibility(x * 0.1, gaze)};
      for (int c = 0; c < 7; ++c) {
        EXPECT_LE(now[c], prev[c]) << "component " << c << " at " << x;
        EXPECT_GE(now[c], 0.0);
        EXPECT_LE(now[c], 1.0);
        prev[c] = now[c];
      }
    }
  }
}

TEST(AngularDistortion, ExpansionIsToleratedBetterThanContraction) {
  EXPECT_NEAR(angularDistortionPlausibility(30 * kDeg, Gaze::kLooking), 0.5, kTol);
  EXPECT_NEAR(angularDistortionPlausibility(-20 * kDeg, Gaze::kLooking), 0.5, kTol);
  // 20 deg expansion: 1 / (1 + (20/30)^3) = 1 / (1 + 8/27) = 27/35.
  EXPECT_NEAR(angularDistortionPlausibility(20 * kDeg, Gaze::kLooking), 27.0 / 35.0, kTol);
  for (double a : {5.0, 15.0, 45.0, 90.0}) {
    EXPECT_GT(angularDistortionPlausibility(a * kDeg, Gaze::kLooking), angularDistortionPlausibility(-a * kDeg, Gaze::kLooking)) << a;
  }
}

TEST(AngularDistortion, NotLookingDoublesTheHalfPoint) {
  EXPECT_NEAR(angularDistortionPlausibility(60 * kDeg, Gaze::kNotLooking), 0.5, kTol);
  // 30 deg expansion seen peripherally: 1 / (1 + (30/60)^3) = 8/9.
  EXPECT_NEAR(angularDistortionPlausibility(30 * kDeg, Gaze::kNotLooking), 8.0 / 9.0, kTol);
}

TEST(LinearVelocityDistortion, IncreaseIsToleratedBetterThanDecrease) {
  EXPECT_NEAR(linearVelocityPlausibility(0.40, Gaze::kLooking), 0.5, kTol);
  EXPECT_NEAR(linearVelocityPlausibility(-0.25, Gaze::kLooking), 0.5, kTol);
  // +25 %: 1 / (1 + (0.25/0.4)^3) = 1 / (1 + 125/512) = 512/637.
  EXPECT_NEAR(linearVelocityPlausibility(0.25, Gaze::kLooking), 512.0 / 637.0, kTol);
  // -50 % peripherally: half point 0.5 -> 1/2.
  EXPECT_NEAR(linearVelocityPlausibility(-0.5, Gaze::kNotLooking), 0.5, kTol);
}

TEST(AngularVelocityAndGap, HandComputedValues) {
  EXPECT_NEAR(angularVelocityPlausibility(0.5, Gaze::kLooking), 0.5, kTol);
  EXPECT_NEAR(angularVelocityPlausibility(1.0, Gaze::kLooking), 0.2, kTol);     // 1 / (1 + 2^2)
  EXPECT_NEAR(angularVelocityPlausibility(1.0, Gaze::kNotLooking), 0.5, kTol);
  EXPECT_NEAR(gapPlausibility(0.02, Gaze::kLooking), 0.5, kTol);
  EXPECT_NEAR(gapPlausibility(0.04, Gaze::kLooking), 0.2, kTol);
  EXPECT_NEAR(gapPlausibility(0.04, Gaze::kNotLooking), 0.5, kTol);
}

TEST(ScorePlausibility, MixesLookingAndNotLookingAndMultipliesComponents) {
  ResponseDistortion d;
  d.angleRad = 30 * kDeg;   // looking 1/2, not looking 8/9
  d.linearRel = -0.25;      // looking 1/2, not looking 1 / (1 + (1/2)^3) = 8/9
  d.angularRel = 1.0;       // looking 1/5, not looking 1/2
  d.gapRel = 0.0;           // 1 either way
  const PlausibilityScores moving = scorePlausibility(d, 1.0);
  EXPECT_NEAR(moving.angular, 0.5, kTol);
  EXPECT_NEAR(moving.linearVelocity, 0.5, kTol);
  EXPECT_NEAR(moving.angularVelocity, 0.2, kTol);
  EXPECT_NEAR(moving.gap, 1.0, kTol);
  EXPECT_NEAR(moving.overall, 0.05, kTol);
  const PlausibilityScores resting = scorePlausibility(d, 0.0);
  EXPECT_NEAR(resting.angular, 8.0 / 9.0, kTol);
  EXPECT_NEAR(resting.angularVelocity, 0.5, kTol);
  EXPECT_NEAR(resting.overall, 8.0 / 9.0 * 8.0 / 9.0 * 0.5, kTol);
  const PlausibilityScores half = scorePlausibility(d, 0.5);
  EXPECT_NEAR(half.angular, 0.5 * 0.5 + 0.5 * 8.0 / 9.0, kTol);
  // No distortion at all is fully plausible for any gaze.
  EXPECT_NEAR(scorePlausibility(ResponseDistortion{}, 0.3).overall, 1.0, kTol);
}

TEST(MeasureDistortion, SignsExpansionAndContractionAgainstTheApproachLine) {
  CollisionScale scale;
  scale.approachDirection = Vec3::UnitX();
  scale.approachSpeed = 2.0;
  scale.radius = 1.0;
  scale.size = 1.5;
  ObjectResponse straight{Vec3(1, 0, 0), Vec3::Zero()};
  ObjectResponse turned{Vec3(std::cos(30 * kDeg), std::sin(30 * kDeg), 0) * 1.2, Vec3::Zero()};
  ResponseDistortion d = measureDistortion(turned, straight, 0.03, scale);
  EXPECT_NEAR(d.angleRad, 30 * kDeg, 1e-12);   // deflected further: expansion
  EXPECT_NEAR(d.linearRel, 0.2, 1e-12);        // 1.2 vs 1
  EXPECT_NEAR(d.gapRel, 0.02, 1e-12);          // 0.03 / 1.5
  d = measureDistortion(straight, turned, std::numeric_limits<double>::quiet_NaN(), scale);
  EXPECT_NEAR(d.angleRad, -30 * kDeg, 1e-12);  // deflected less: contraction
  EXPECT_NEAR(d.linearRel, -0.2 / 1.2, 1e-12);
  EXPECT_EQ(d.gapRel, 0.0);                    // not measured
  EXPECT_EQ(measureDistortion(straight, turned, -0.5, scale).gapRel, 0.0);  // penetration: touching
}

TEST(MeasureDistortion, SlowAndRestingReferencesUseTheSpeedFloor) {
  CollisionScale scale;
  scale.approachSpeed = 2.0;  // floor 0.1 * 2 = 0.2
  scale.radius = 1.0;
  const ObjectResponse rest{};
  const ObjectResponse creeping{Vec3(0, 0.1, 0), Vec3(0, 0, 0.1)};
  const ResponseDistortion d = measureDistortion(creeping, rest, 0.0, scale);
  EXPECT_EQ(d.angleRad, 0.0);             // 0.1 < floor: no direction to judge
  EXPECT_NEAR(d.linearRel, 0.5, 1e-12);   // 0.1 / 0.2
  EXPECT_NEAR(d.angularRel, 0.5, 1e-12);  // rim speed 0.1 / 0.2
  // A spinning reference: relative to its own rim speed 1 * 2 (radius 2).
  scale.radius = 2.0;
  const ResponseDistortion s = measureDistortion(ObjectResponse{Vec3::Zero(), Vec3(0, 0, 1.5)},
                                                 ObjectResponse{Vec3::Zero(), Vec3(0, 0, 1.0)}, 0.0, scale);
  EXPECT_NEAR(s.angularRel, 0.5, 1e-12);  // |0.5| * 2 / (1 * 2)
}

std::vector<TrajectoryFrame> framesWithContacts(const std::vector<bool>& contact, const std::vector<double>& gaps) {
  std::vector<TrajectoryFrame> frames(contact.size());
  for (std::size_t i = 0; i < contact.size(); ++i) {
    frames[i].time = 0.1 * static_cast<double>(i);
    frames[i].contact = contact[i];
    frames[i].gap = gaps[i];
  }
  return frames;
}

TEST(FindFirstCollision, FindsTheFirstContactRunAndThePostFrame) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto frames = framesWithContacts({false, false, true, true, false, true, false},
                                         {nan, nan, 0.3, 0.1, 0.0, 0.05, nan});
  CollisionEvent e = findFirstCollision(frames, 1);
  ASSERT_TRUE(e.found);
  EXPECT_EQ(e.firstContact, 2u);
  EXPECT_EQ(e.contactEnd, 4u);
  EXPECT_EQ(e.post, 5u);
  EXPECT_DOUBLE_EQ(e.minGap, 0.1);  // only frames 2 and 3 belong to the first contact
  e = findFirstCollision(frames, 10);
  EXPECT_EQ(e.post, 6u);            // clamped to the last frame
}

TEST(FindFirstCollision, ContactThatNeverEndsAndNoContact) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CollisionEvent e = findFirstCollision(framesWithContacts({false, true, true}, {nan, nan, nan}), 3);
  ASSERT_TRUE(e.found);
  EXPECT_EQ(e.contactEnd, 3u);
  EXPECT_EQ(e.post, 2u);
  EXPECT_TRUE(std::isnan(e.minGap));
  EXPECT_FALSE(findFirstCollision(framesWithContacts({false, false}, {nan, nan}), 1).found);
  EXPECT_FALSE(findFirstCollision(std::span<const TrajectoryFrame>(), 1).found);
}

// Tolerance: surfaceGap promises true <= d <= true + tolerance; 1e-4 of the cubes' unit size
// (parallel faces make it halve edges down to ~tolerance, so much smaller costs time).
constexpr double kGapTol = 1e-4;

TEST(SurfaceGap, FaceToFaceAndEdgeToFaceCubes) {
  const MeshDistance cube(makeBox(Vec3(0.5, 0.5, 0.5)));
  const Pose origin;
  // Face to face, 0.3 apart.
  const double faces = surfaceGap(cube, origin, cube, Pose{Quat::Identity(), Vec3(1.3, 0, 0)}, kGapTol);
  EXPECT_GE(faces, 0.3 - 1e-12);
  EXPECT_LE(faces, 0.3 + kGapTol);
  // B turned 45 deg about z: its vertical edge points at A's +x face, 0.1 away.
  const Quat turn(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  const double reach = 0.5 * std::sqrt(2.0);
  const double edge = surfaceGap(cube, origin, cube, Pose{turn, Vec3(0.5 + reach + 0.1, 0, 0)}, kGapTol);
  EXPECT_GE(edge, 0.1 - 1e-12);
  EXPECT_LE(edge, 0.1 + kGapTol);
}

TEST(SurfaceGap, CrossedEdgesFarFromAnyVertexAreFound) {
  // A turned 45 deg about y: a top edge along y at height sqrt(2)/2. B turned 45 deg about x: a
  // bottom edge along x. Placed 0.1 apart, the edges cross at their midpoints, where no vertex
  // of either cube is near (the nearest vertex pair is ~0.5 away): the true gap is 0.1.
  const MeshDistance cube(makeBox(Vec3(0.5, 0.5, 0.5)));
  const double reach = 0.5 * std::sqrt(2.0);
  const Pose a{Quat(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitY())), Vec3::Zero()};
  const Pose b{Quat(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitX())), Vec3(0, 0, 2 * reach + 0.1)};
  const double gap = surfaceGap(cube, a, cube, b, kGapTol);
  EXPECT_GE(gap, 0.1 - 1e-12);
  EXPECT_LE(gap, 0.1 + kGapTol);
}

TEST(SurfaceGap, OverlappingCubesGiveZeroWithinTheTolerance) {
  const MeshDistance cube(makeBox(Vec3(0.5, 0.5, 0.5)));
  const Quat turn(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  EXPECT_LE(surfaceGap(cube, Pose{}, cube, Pose{turn, Vec3(0.9, 0.1, 0)}, 1e-3), 1e-3);
}

}  // namespace
}  // namespace clod
