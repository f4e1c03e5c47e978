#pragma once
// How a contact-tree half-space is rounded so that the bake file can store it in a few bytes
// and give back exactly the same floats (contact_tree_builder.cpp rounds, the codec stores the
// integers). docs/contact-tree.md, "Compact storage", has the precision argument.
//
//  * normal: octahedral map of the unit sphere onto [-1, 1]^2 (Meyer et al. 2010, "On
//    floating-point normal vectors"), each coordinate rounded to a multiple of 1/kOctScale;
//    the decoded normal is normalised in double and stored as float. Angular error < 2e-4 rad
//    (0.012 deg); axis directions are exact. The builder fits its plane to the rounded normal,
//    so the rounding shows in fitError, not as a hidden error.
//  * offset: the centre estimate (-centre value of a split cell, else -trilinear centre value)
//    plus an integer multiple of latticeStep / kOffsetStepDivisor (lattice.h), rounded to
//    nearest: the plane moves by at most 2^-14 eps_s (samples are placed on it, so it must stay
//    that close: a box face cell whose prediction comes from rounded corner values keeps its
//    face plane within 1e-6; a step of latticeStep / 32 moved it by 8e-6, ctest ContactTreeBox).
//  * fitError: fitError / h as an error code rounded up (ContactTree::encodeErrorRatio with
//    all 7 mantissa bits), so it stays an upper bound and keeps its relative precision (2^-7)
//    however small it is. (With the error bounds' 3 bits, cells near the contact sampler's
//    flat / edge threshold 0.1 h flip, and a sphere's manifold turned 6.2 degrees off the
//    centre line, ctest NarrowPhaseSpheres.)

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "clod/contact_tree.h"

namespace clod::detail {

inline constexpr std::int32_t kOctCodeMax = 8191;
inline constexpr double kOctScale = kOctCodeMax;
/// Mantissa bits of a fit error's code (ContactTree::encodeErrorRatio).
inline constexpr int kFitMantissaBits = 7;
/// Offsets are stored in steps of latticeStep / kOffsetStepDivisor.
inline constexpr double kOffsetStepDivisor = 1024.0;

/// Octahedral code of a direction (need not be unit; a zero vector gives +z).
inline std::array<std::int32_t, 2> encodeOctNormal(double x, double y, double z) {
  const double l1 = std::abs(x) + std::abs(y) + std::abs(z);
  if (!(l1 > 0.0)) return {0, 0};
  double u = x / l1, v = y / l1;
  if (z < 0.0) {
    const double u0 = u;
    u = (1.0 - std::abs(v)) * (u0 >= 0.0 ? 1.0 : -1.0);
    v = (1.0 - std::abs(u0)) * (v >= 0.0 ? 1.0 : -1.0);
  }
  return {static_cast<std::int32_t>(std::lround(u * kOctScale)), static_cast<std::int32_t>(std::lround(v * kOctScale))};
}

/// The unit normal (as floats) of an octahedral code; codes outside [-kOctCodeMax, kOctCodeMax] are the
/// caller's error (the decoder checks them).
inline std::array<float, 3> decodeOctNormal(std::int32_t a, std::int32_t b) {
  double u = a / kOctScale, v = b / kOctScale;
  const double z = 1.0 - std::abs(u) - std::abs(v);
  if (z < 0.0) {
    const double u0 = u;
    u = (1.0 - std::abs(v)) * (u0 >= 0.0 ? 1.0 : -1.0);
    v = (1.0 - std::abs(u0)) * (v >= 0.0 ? 1.0 : -1.0);
  }
  const double len = std::sqrt(u * u + v * v + z * z);  // >= 1/sqrt(3) on the octahedron
  return {static_cast<float>(u / len), static_cast<float>(v / len), static_cast<float>(z / len)};
}

/// The octahedral code whose decoded normal is exactly `n`, or false if there is none (a normal
/// the builder did not round).
inline bool findOctCode(const std::array<float, 3>& n, std::array<std::int32_t, 2>& code) {
  const std::array<std::int32_t, 2> guess = encodeOctNormal(n[0], n[1], n[2]);
  // Re-encoding a decoded normal returns its code except, rarely, one step off at a rounding
  // tie, or mirrored at the octahedron's corners and fold, where a component decodes as 0 and
  // the sign of the code that produced it (-0.0 or +0.0) is lost: try those too.
  for (int mirror = 0; mirror < 4; ++mirror)
    for (int da = -1; da <= 1; ++da)
      for (int db = -1; db <= 1; ++db) {
        const std::int32_t a = ((mirror & 1) ? -guess[0] : guess[0]) + da, b = ((mirror & 2) ? -guess[1] : guess[1]) + db;
        if (std::abs(a) > kOctCodeMax || std::abs(b) > kOctCodeMax) continue;
        // Bit for bit: a zero component may decode as -0.0 from one code and +0.0 from another.
        const std::array<float, 3> m = decodeOctNormal(a, b);
        if (std::memcmp(m.data(), n.data(), sizeof(m)) == 0) {
          code = {a, b};
          return true;
        }
      }
  return false;
}

/// The fit error stored for code `code` in a cell of side h: at least decodeErrorRatio(code) h.
inline float fitErrorFromCode(std::uint16_t code, double h) {
  const double v = double(ContactTree::decodeErrorRatio(code)) * h;
  float f = static_cast<float>(v);
  if (double(f) < v) f = std::nextafter(f, 3.0e38f);
  return f;
}
/// The code of a stored fit error, or false if no code gives exactly this value.
inline bool findFitCode(float fitError, double h, std::uint16_t& code) {
  if (!(fitError >= 0.0f) || !std::isfinite(fitError)) return false;
  // fitErrorFromCode rounds up, so the code is the re-encoded guess or a neighbour of it.
  const int codeStep = 1 << (7 - kFitMantissaBits);
  const std::uint16_t guess = ContactTree::encodeErrorRatio(double(fitError) / h, kFitMantissaBits);
  for (int c = int(guess) - codeStep; c <= int(guess) + codeStep; c += codeStep) {
    if (c < 0 || c > 0x7f7f) continue;
    if (fitErrorFromCode(static_cast<std::uint16_t>(c), h) == fitError) {
      code = static_cast<std::uint16_t>(c);
      return true;
    }
  }
  return false;
}

/// Offset prediction: minus the split cell's stored centre value, or minus the trilinear value
/// at the centre of a leaf.
inline double offsetPrediction(const std::array<float, 8>& corners, bool split, float centreValue) {
  if (split) return -double(centreValue);
  double sum = 0.0;
  for (float v : corners) sum += v;
  return -sum / 8.0;
}

}  // namespace clod::detail
