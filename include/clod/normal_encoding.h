#pragma once
// Compact unit-vector (normal) encodings for closest feature maps and bake files.
//
// Octahedral encoding (Cigolle, Donow, Evangelakos, Mara, McGuire, Meyer, "A Survey of Efficient
// Representations for Independent Unit Vectors", JCGT 3(2), 2014, section 3.5): project the unit
// vector onto the octahedron |x|+|y|+|z| = 1, unfold the lower half onto the corners of the square
// [-1,1]^2, and quantise both square coordinates to b bits each (b = 8: 16-bit code, b = 16: 32-bit
// code). The square is covered uniformly, so the error is nearly the same in every direction.
//
// Code layout: bits [0, b) hold the quantised first square coordinate (from x), bits [b, 2b) the
// second (from y). Quantised value q in [0, 2^b - 1] stands for -1 + 2q / (2^b - 1): both ends
// -1 and 1 are exact, 0 is not (2^b - 1 is odd).
//
// Encoders pick, of the (up to) four codes around the vector's square position, the one whose
// decoded vector is closest in angle ("precise" variant of Cigolle et al.), so the error is the
// smallest any code gives for that vector. Cost: ~4 decodes; meant for build time, not queries.
// Decoders are branch-light and meant for the query path.
//
// Accuracy (radians; docs/sampling.md has the measured figures):
//   octahedralErrorBound(8)  = asin(3*sqrt(2)/255)   ~ 0.01664 rad ~ 0.953 deg   (16-bit code)
//   octahedralErrorBound(16) = asin(3*sqrt(2)/65535) ~ 6.47e-5 rad ~ 0.0037 deg  (32-bit code)
// tests/cfm/normal_encoding_test.cpp checks the measured maximum over dense direction sets against
// these bounds.

#include <cstdint>

#include "clod/math.h"

namespace clod {

/// Encodes a unit vector into 16 bits (8 + 8). Precondition (CLOD_ASSERT): finite and non-zero;
/// the vector need not be exactly unit length (only its direction is encoded). O(1).
std::uint16_t encodeOctahedral16(const Vec3& unitVector) noexcept;
/// Decodes a 16-bit octahedral code to a unit vector. Every code decodes to a unit vector. O(1).
Vec3 decodeOctahedral16(std::uint16_t code) noexcept;

/// Encodes a unit vector into 32 bits (16 + 16). Same contract as encodeOctahedral16.
std::uint32_t encodeOctahedral32(const Vec3& unitVector) noexcept;
/// Decodes a 32-bit octahedral code to a unit vector. O(1).
Vec3 decodeOctahedral32(std::uint32_t code) noexcept;

/// An upper bound on the angle (radians) between a unit vector and the decoding of its
/// octahedral encoding with `bitsPerAxis` bits per square coordinate (1..16):
/// asin(min(1, 3*sqrt(2) / (2^bits - 1))). Derivation: rounding moves the square position by at
/// most half a step, step = 2/(2^b - 1), in each coordinate (<= sqrt(2)/(2^b - 1) in length);
/// unfolding the square onto the octahedron is piecewise linear with Lipschitz constant sqrt(3);
/// every octahedron point is at least 1/sqrt(3) from the origin, and a displacement d of a point
/// at distance r turns its direction by at most asin(d / r).
double octahedralErrorBound(int bitsPerAxis) noexcept;

}  // namespace clod
