// The psychometric functions and the distortion measures of plausibility.h.
#include "clod/plausibility.h"

#include <algorithm>
#include <cmath>

#include "clod/error.h"

namespace clod {

double psychometricPlausibility(double x, double halfPoint, double slope) {
  CLOD_ASSERT(halfPoint > 0.0 && slope > 0.0);
  const double ratio = std::abs(x) / halfPoint;
  if (std::isinf(ratio)) return 0.0;
  return 1.0 / (1.0 + std::pow(ratio, slope));
}

namespace {
double gazeScale(Gaze gaze, const PlausibilityConstants& k) {
  return gaze == Gaze::kLooking ? 1.0 : k.notLookingScale;
}
}  // namespace

double angularDistortionPlausibility(double signedAngleRad, Gaze gaze, const PlausibilityConstants& k) {
  const double half = signedAngleRad >= 0.0 ? k.angleExpansionHalfRad : k.angleContractionHalfRad;
  return psychometricPlausibility(signedAngleRad, half * gazeScale(gaze, k), k.angleSlope);
}

double linearVelocityPlausibility(double relativeChange, Gaze gaze, const PlausibilityConstants& k) {
  const double half = relativeChange >= 0.0 ? k.speedIncreaseHalf : k.speedDecreaseHalf;
  return psychometricPlausibility(relativeChange, half * gazeScale(gaze, k), k.speedSlope);
}

double angularVelocityPlausibility(double relativeDistortion, Gaze gaze, const PlausibilityConstants& k) {
  return psychometricPlausibility(relativeDistortion, k.spinHalf * gazeScale(gaze, k), k.spinSlope);
}

double gapPlausibility(double gapRel, Gaze gaze, const PlausibilityConstants& k) {
  return psychometricPlausibility(gapRel, k.gapHalfRel * gazeScale(gaze, k), k.gapSlope);
}

ResponseDistortion measureDistortion(const ObjectResponse& test, const ObjectResponse& reference, double gapAbs,
                                     const CollisionScale& scale, const PlausibilityConstants& k) {
  CLOD_ASSERT(scale.approachSpeed > 0.0 && std::isfinite(scale.approachSpeed));
  CLOD_ASSERT(scale.radius > 0.0 && std::isfinite(scale.radius) && scale.size > 0.0 && std::isfinite(scale.size));
  CLOD_ASSERT(std::abs(scale.approachDirection.norm() - 1.0) < 1e-6);
  ResponseDistortion d;
  const double floor = k.speedFloorRel * scale.approachSpeed;
  const double speedTest = test.velocity.norm();
  const double speedRef = reference.velocity.norm();
  if (speedTest > floor && speedRef > floor) {
    const Vec3 uTest = test.velocity / speedTest;
    const Vec3 uRef = reference.velocity / speedRef;
    // atan2 of |cross| and dot: accurate for small and near-pi angles alike.
    const double between = std::atan2(uTest.cross(uRef).norm(), uTest.dot(uRef));
    const double deflectTest = std::atan2(uTest.cross(scale.approachDirection).norm(), uTest.dot(scale.approachDirection));
    const double deflectRef = std::atan2(uRef.cross(scale.approachDirection).norm(), uRef.dot(scale.approachDirection));
    d.angleRad = deflectTest >= deflectRef ? between : -between;
  }
  d.linearRel = (speedTest - speedRef) / std::max(speedRef, floor);
  const double rimRef = reference.angularVelocity.norm() * scale.radius;
  d.angularRel = (test.angularVelocity - reference.angularVelocity).norm() * scale.radius / std::max(rimRef, floor);
  d.gapRel = std::isnan(gapAbs) ? 0.0 : std::max(0.0, gapAbs) / scale.size;
  return d;
}

PlausibilityScores scorePlausibility(const ResponseDistortion& d, double pLooking, const PlausibilityConstants& k) {
  CLOD_ASSERT(pLooking >= 0.0 && pLooking <= 1.0);
  const auto mix = [pLooking](double looking, double notLooking) {
    return pLooking * looking + (1.0 - pLooking) * notLooking;
  };
  PlausibilityScores s;
  s.angular = mix(angularDistortionPlausibility(d.angleRad, Gaze::kLooking, k),
                  angularDistortionPlausibility(d.angleRad, Gaze::kNotLooking, k));
  s.linearVelocity = mix(linearVelocityPlausibility(d.linearRel, Gaze::kLooking, k),
                         linearVelocityPlausibility(d.linearRel, Gaze::kNotLooking, k));
  s.angularVelocity = mix(angularVelocityPlausibility(d.angularRel, Gaze::kLooking, k),
                          angularVelocityPlausibility(d.angularRel, Gaze::kNotLooking, k));
  s.gap = mix(gapPlausibility(d.gapRel, Gaze::kLooking, k), gapPlausibility(d.gapRel, Gaze::kNotLooking, k));
  s.overall = s.angular * s.linearVelocity * s.angularVelocity * s.gap;
  return s;
}

}  // namespace clod
