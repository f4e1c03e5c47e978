// unitQuaternion (clod/math.h): the rotation a quaternion of any finite, nonzero magnitude points
// to. Oracle: the unit quaternions written down by hand for each direction.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "clod/quaternion.h"

namespace clod {
namespace {

// Unit quaternions are compared component by component: a few ulps of rounding in the scaling
// and the square root, nothing more.
constexpr double kUlps = 4e-16;

void expectQuaternion(const std::optional<Quat>& got, double w, double x, double y, double z) {
  ASSERT_TRUE(got.has_value());
  EXPECT_NEAR(got->w(), w, kUlps);
  EXPECT_NEAR(got->x(), x, kUlps);
  EXPECT_NEAR(got->y(), y, kUlps);
  EXPECT_NEAR(got->z(), z, kUlps);
}

TEST(UnitQuaternion, NormalisesEveryFiniteNonzeroMagnitude) {
  const double half = std::sqrt(0.5);
  expectQuaternion(unitQuaternion(1.0, 0.0, 0.0, 0.0), 1.0, 0.0, 0.0, 0.0);
  expectQuaternion(unitQuaternion(2.0, 0.0, 0.0, 2.0), half, 0.0, 0.0, half);
  // The norm of (1e200, 1e200, 0, 0) overflows to infinity, and the squared norm of
  // (1e-200, 0, 0, 0) underflows to zero: both are plain rotations.
  expectQuaternion(unitQuaternion(1e200, 1e200, 0.0, 0.0), half, half, 0.0, 0.0);
  expectQuaternion(unitQuaternion(0.0, -1e-200, 0.0, 1e-200), 0.0, -half, 0.0, half);
  expectQuaternion(unitQuaternion(std::numeric_limits<double>::max(), 0.0, std::numeric_limits<double>::max(), 0.0),
                   half, 0.0, half, 0.0);
  expectQuaternion(unitQuaternion(std::numeric_limits<double>::denorm_min(), 0.0, 0.0, 0.0), 1.0, 0.0, 0.0, 0.0);
}

TEST(UnitQuaternion, RefusesZeroAndNonFiniteQuaternions) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(unitQuaternion(0.0, 0.0, 0.0, 0.0).has_value());
  EXPECT_FALSE(unitQuaternion(-0.0, 0.0, -0.0, 0.0).has_value());
  EXPECT_FALSE(unitQuaternion(inf, 0.0, 0.0, 0.0).has_value());
  // NaN in any place, also after a larger component (a max over the magnitudes alone can skip it).
  EXPECT_FALSE(unitQuaternion(nan, 1.0, 0.0, 0.0).has_value());
  EXPECT_FALSE(unitQuaternion(1.0, 0.0, 0.0, nan).has_value());
}

}  // namespace
}  // namespace clod
