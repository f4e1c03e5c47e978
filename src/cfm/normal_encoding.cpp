// Octahedral unit-vector encoding (Cigolle et al., JCGT 3(2) 2014, section 3.5), 8+8 and 16+16 bits.
#include "clod/normal_encoding.h"

#include <algorithm>
#include <cmath>

#include "clod/error.h"

namespace clod {
namespace {

// sign with sign(0) = +1, so that the fold of the lower hemisphere is defined on the axes.
double signNotZero(double v) { return v >= 0.0 ? 1.0 : -1.0; }

// Square position [-1,1]^2 of a non-zero vector: octahedron projection, lower half folded out.
void toSquare(const Vec3& v, double& px, double& py) {
  const double l1 = std::abs(v.x()) + std::abs(v.y()) + std::abs(v.z());
  px = v.x() / l1;
  py = v.y() / l1;
  if (v.z() < 0.0) {
    const double fx = (1.0 - std::abs(py)) * signNotZero(px);
    const double fy = (1.0 - std::abs(px)) * signNotZero(py);
    px = fx;
    py = fy;
  }
}

Vec3 fromSquare(double px, double py) {
  Vec3 v(px, py, 1.0 - std::abs(px) - std::abs(py));
  if (v.z() < 0.0) {
    v.x() = (1.0 - std::abs(py)) * signNotZero(px);
    v.y() = (1.0 - std::abs(px)) * signNotZero(py);
  }
  return v.normalized();  // |v| >= 1/sqrt(3): never zero
}

Vec3 decode(std::uint32_t code, int bits) {
  const std::uint32_t mask = (1u << bits) - 1u;
  const double scale = static_cast<double>(mask);
  return fromSquare(-1.0 + 2.0 * (code & mask) / scale, -1.0 + 2.0 * ((code >> bits) & mask) / scale);
}

std::uint32_t encode(const Vec3& v, int bits) {
  CLOD_ASSERT(v.allFinite() && v.squaredNorm() > 0.0);
  const std::uint32_t mask = (1u << bits) - 1u;
  const double scale = static_cast<double>(mask);
  double px = 0.0, py = 0.0;
  toSquare(v, px, py);
  const double fx = (px + 1.0) * 0.5 * scale, fy = (py + 1.0) * 0.5 * scale;
  const auto qx0 = static_cast<std::uint32_t>(std::clamp(std::floor(fx), 0.0, scale));
  const auto qy0 = static_cast<std::uint32_t>(std::clamp(std::floor(fy), 0.0, scale));
  // Of the four codes around the position keep the one that decodes closest to v: rounding each
  // coordinate separately is not always the best because the unfolding bends the square.
  const Vec3 unit = v.normalized();
  std::uint32_t best = 0;
  double bestDot = -2.0;
  for (std::uint32_t dy = 0; dy <= 1; ++dy) {
    for (std::uint32_t dx = 0; dx <= 1; ++dx) {
      const std::uint32_t qx = std::min(qx0 + dx, mask), qy = std::min(qy0 + dy, mask);
      const std::uint32_t code = qx | (qy << bits);
      const double d = decode(code, bits).dot(unit);
      if (d > bestDot) {
        bestDot = d;
        best = code;
      }
    }
  }
  return best;
}

}  // namespace

std::uint16_t encodeOctahedral16(const Vec3& unitVector) noexcept {
  return static_cast<std::uint16_t>(encode(unitVector, 8));
}

Vec3 decodeOctahedral16(std::uint16_t code) noexcept { return decode(code, 8); }

std::uint32_t encodeOctahedral32(const Vec3& unitVector) noexcept { return encode(unitVector, 16); }

Vec3 decodeOctahedral32(std::uint32_t code) noexcept { return decode(code, 16); }

double octahedralErrorBound(int bitsPerAxis) noexcept {
  CLOD_ASSERT(bitsPerAxis >= 1 && bitsPerAxis <= 16);
  const double steps = std::ldexp(1.0, bitsPerAxis) - 1.0;
  return std::asin(std::min(1.0, 3.0 * std::sqrt(2.0) / steps));
}

}  // namespace clod
