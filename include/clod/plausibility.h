#pragma once
// A perceptual plausibility metric for one collision, after O'Sullivan, Dingliana, Giang & Kaiser,
// "Evaluating the visual fidelity of physically based animations", ACM TOG 22(3) 2003, as the
// closest-feature-map paper (Giang & O'Sullivan 2006, section 7 and Figure 5) uses it: a
// collision in a test animation is compared with the same collision in a reference animation
// (the `exact` model, unlimited budget), and every kind of distortion is mapped to a
// probability. docs/plausibility.md explains the choices below.
//
// Convention: every probability here is the probability that the test collision is JUDGED
// PLAUSIBLE (1 = indistinguishable from the reference, 0 = always noticed as wrong); the
// probability that the anomaly is noticed is 1 minus it.
//
// Structure (the 2003 paper's): one psychometric function per distortion kind --
//   * angular distortion of the post-collision direction, expansion and contraction separately,
//   * linear-velocity distortion, increase and decrease separately,
//   * angular-velocity distortion,
//   * gap between the surfaces at contact --
// each in a "looking" and a "not looking" (peripheral) variant, mixed per object by the
// probability that the viewer looks at it:  P = pLooking f_looking(x) + (1 - pLooking) f_not(x).
// The CFM paper sets pLooking = 1 for the moving object and 0 for the one initially at rest.
//
// The fitted constants of the 2003 paper were not reachable in public copies, so the functional
// form and every constant are ours, all in PlausibilityConstants (one table, each constant with
// its reasoning). The form is the log-logistic psychometric function
//   f(x) = 1 / (1 + (|x| / x50)^slope),
// which is 1 at no distortion, 1/2 at the 50 % point x50, and falls monotonically to 0.
//
// Also here: finding the first collision of a recorded two-body trajectory and its post-collision
// state (findFirstCollision), and the gap between two placed meshes (surfaceGap).
// Nothing here prints; only surfaceGap allocates.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>

#include "clod/math.h"
#include "clod/proximity.h"
#include "clod/rigid_body.h"

namespace clod {

/// Every constant of the metric (docs/plausibility.md). The 50 % points are "looking" values;
/// not looking multiplies each by notLookingScale. Angles in radians, velocities relative.
struct PlausibilityConstants {
  /// Post-collision direction turned FURTHER from the approach line than in the reference
  /// (expansion): 50 % at 30 deg. The 2003 paper found expansion tolerated better than
  /// contraction; 30 / 20 deg keep that order and put the 50 % points well above the ~1-5 deg
  /// discrimination thresholds for motion direction (De Bruyn & Orban 1988), because judging a
  /// collision plausible is far more lenient than discriminating two directions side by side.
  double angleExpansionHalfRad = 30.0 * std::numbers::pi / 180.0;
  /// Turned LESS far than in the reference (contraction): 50 % at 20 deg.
  double angleContractionHalfRad = 20.0 * std::numbers::pi / 180.0;
  double angleSlope = 3.0;
  /// Post-collision speed relative change (|v_test| - |v_ref|) / |v_ref|: increases are tolerated
  /// better than decreases (2003 paper, qualitatively): 50 % at +40 % and at -25 %. Speed
  /// discrimination Weber fractions are ~5-10 % (McKee 1981); plausibility is several times
  /// more lenient, as with angles.
  double speedIncreaseHalf = 0.40;
  double speedDecreaseHalf = 0.25;
  double speedSlope = 3.0;
  /// Angular-velocity distortion |w_test - w_ref| R / max(|w_ref| R, speedFloorRel v_approach)
  /// (R: the object's bounding radius, so w R is the rim speed): 50 % at 0.5, i.e. a rim speed
  /// off by half the reference's. One function for both signs (the 2003 paper reported no
  /// asymmetry we could find for rotation).
  double spinHalf = 0.5;
  double spinSlope = 2.0;
  /// Closest distance between the surfaces during the contact, relative to the smaller object's
  /// bounding-box diagonal: 50 % at 2 % (a few pixels for an object filling a quarter of a
  /// 1000-pixel view -- about where a gap starts to show).
  double gapHalfRel = 0.02;
  double gapSlope = 2.0;
  /// Peripheral (not looking) vision: every 50 % point times this (anomalies away from the
  /// fixation point are noticed less; the 2003 paper's eccentricity result, in direction only).
  double notLookingScale = 2.0;
  /// Relative velocity distortions divide by at least this fraction of the approach speed, so
  /// a reference at (nearly) rest does not turn a tiny absolute error into a huge relative one;
  /// below it the direction of motion is also ignored (too slow to see where it goes).
  double speedFloorRel = 0.1;
};

/// The constants the experiments use.
inline constexpr PlausibilityConstants kPlausibilityConstants{};

/// Whether the viewer is looking at the object (foveal) or not (peripheral).
enum class Gaze : std::uint8_t { kLooking = 0, kNotLooking = 1 };

/// The log-logistic psychometric function 1 / (1 + (|x| / halfPoint)^slope): 1 at x = 0, 1/2 at
/// |x| = halfPoint, -> 0 as |x| -> inf, monotonically decreasing in |x|. Preconditions
/// (CLOD_ASSERT): halfPoint > 0, slope > 0. NaN x gives NaN; infinite x gives 0. O(1).
double psychometricPlausibility(double x, double halfPoint, double slope);

/// Probability that an angular distortion of the post-collision direction is judged plausible.
/// signedAngleRad > 0: expansion (deflected further from the approach line than the
/// reference), < 0: contraction. O(1).
double angularDistortionPlausibility(double signedAngleRad, Gaze gaze,
                                     const PlausibilityConstants& k = kPlausibilityConstants);
/// Same for a relative speed change (> 0 faster than the reference, < 0 slower).
double linearVelocityPlausibility(double relativeChange, Gaze gaze,
                                  const PlausibilityConstants& k = kPlausibilityConstants);
/// Same for an angular-velocity distortion (>= 0, see PlausibilityConstants::spinHalf).
double angularVelocityPlausibility(double relativeDistortion, Gaze gaze,
                                   const PlausibilityConstants& k = kPlausibilityConstants);
/// Same for a gap (>= 0, relative to the smaller object's bounding-box diagonal).
double gapPlausibility(double gapRel, Gaze gaze, const PlausibilityConstants& k = kPlausibilityConstants);

/// An object's motion just after the collision (world frame; angular velocity in rad/s).
struct ObjectResponse {
  Vec3 velocity = Vec3::Zero();
  Vec3 angularVelocity = Vec3::Zero();
};

/// The scales a collision's distortions are measured against.
struct CollisionScale {
  /// Unit direction of the moving object's velocity before the collision (the approach line).
  Vec3 approachDirection = Vec3::UnitX();
  double approachSpeed = 1.0;   ///< its speed before the collision (> 0)
  double radius = 1.0;          ///< the object's bounding radius (> 0): turns spin into rim speed
  double size = 1.0;            ///< the smaller object's bounding-box diagonal (> 0): gap unit
};

/// One object's distortions, test vs reference.
struct ResponseDistortion {
  /// Angle between the test and reference post-collision directions (radians, >= 0 in
  /// magnitude), signed + when the test's deflection from the approach line is larger
  /// (expansion) and - when smaller (contraction). 0 when either speed is below
  /// speedFloorRel * approachSpeed (no direction to judge).
  double angleRad = 0.0;
  /// (|v_test| - |v_ref|) / max(|v_ref|, speedFloorRel * approachSpeed).
  double linearRel = 0.0;
  /// |w_test - w_ref| R / max(|w_ref| R, speedFloorRel * approachSpeed), >= 0.
  double angularRel = 0.0;
  /// Test gap / size (>= 0; a negative or NaN gap counts as 0: touching or not measured).
  double gapRel = 0.0;
};

/// Distortions of one object (see ResponseDistortion). `gapAbs` is the test animation's closest
/// surface distance during the contact (length units). Preconditions (CLOD_ASSERT): the scale's
/// speeds and lengths positive and finite, approachDirection unit. O(1).
ResponseDistortion measureDistortion(const ObjectResponse& test, const ObjectResponse& reference, double gapAbs,
                                     const CollisionScale& scale,
                                     const PlausibilityConstants& k = kPlausibilityConstants);

/// Per-component probabilities of one object, each mixed over gaze, and their product.
struct PlausibilityScores {
  double angular = 1.0;
  double linearVelocity = 1.0;
  double angularVelocity = 1.0;
  double gap = 1.0;
  /// angular * linearVelocity * angularVelocity * gap: the animation is judged plausible only
  /// if no component is noticed, the components taken as independent (our assumption).
  double overall = 1.0;
};

/// P_c = pLooking f_c(looking) + (1 - pLooking) f_c(not looking) for every component c.
/// Precondition (CLOD_ASSERT): pLooking in [0, 1]. O(1).
PlausibilityScores scorePlausibility(const ResponseDistortion& distortion, double pLooking,
                                     const PlausibilityConstants& k = kPlausibilityConstants);

/// One recorded step of a two-body animation (bodies a and b, state after the step).
struct TrajectoryFrame {
  double time = 0.0;
  RigidBodyState a, b;
  bool contact = false;  ///< the narrow phase reported contacts between a and b in this step
  /// Closest surface distance in this step (surfaceGap), NaN when not measured.
  double gap = std::numeric_limits<double>::quiet_NaN();
};

/// The first collision of a trajectory.
struct CollisionEvent {
  bool found = false;          ///< some frame has contact
  std::size_t firstContact = 0;///< first frame with contact
  /// First frame after firstContact without contact (frames.size() if contact never ends).
  std::size_t contactEnd = 0;
  /// Frame of the post-collision state: contactEnd + settleFrames, clamped to the last frame.
  std::size_t post = 0;
  /// Smallest measured gap over [firstContact, contactEnd); NaN when none was measured.
  double minGap = std::numeric_limits<double>::quiet_NaN();
};

/// Finds the first collision and its post-collision frame. Not found (found = false, the rest
/// 0 / NaN) when no frame has contact or `frames` is empty. O(frames).
CollisionEvent findFirstCollision(std::span<const TrajectoryFrame> frames, std::size_t settleFrames);

/// Closest distance between the surfaces of mesh A placed by xfWorldFromA and mesh B placed by
/// xfWorldFromB, to within toleranceAbs (> 0, length units; CLOD_ASSERT): the result d satisfies
/// true <= d <= true + toleranceAbs. Exact in structure: the closest pair of two disjoint
/// triangle meshes always lies on an edge of one of them, so the minimum over both meshes' edges
/// of the distance to the other surface is the answer; each edge is searched by branch and bound
/// (the distance is 1-Lipschitz along it). Meshes whose surfaces cross give (about) 0: an edge
/// of one passes through the other. One mesh wholly inside the other is not detected (unsigned
/// distances). Cost: O(V log T) closest-point queries for the vertices plus a few per edge near
/// the closest approach; allocates two per-vertex arrays.
double surfaceGap(const MeshDistance& a, const Pose& xfWorldFromA, const MeshDistance& b, const Pose& xfWorldFromB,
                  double toleranceAbs);

}  // namespace clod
