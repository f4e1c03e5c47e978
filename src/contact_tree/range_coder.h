#pragma once
// Adaptive binary range coder for the contact-tree codec (contact_tree_codec.cpp).
//
// Every symbol is coded as a sequence of binary decisions. A decision either uses an adaptive
// probability (a 12-bit estimate of P(bit = 0) that moves 1/32 of the way towards each coded bit)
// or is a "direct" bit at probability 1/2. The coder keeps a 32-bit range and a 64-bit low end
// with carry propagation (the classic range-coder construction of G. N. N. Martin, "Range
// encoding", 1979). Integers are binarised as zero flag, sign, an Exp-Golomb class in unary and
// the mantissa bits (the first adaptive, the rest direct), so small residuals cost a few bits.
//
// Bounds a decoder relies on: a probability stays in [31, 4065] of 4096, so every decision costs
// at least -log2(4065/4096) > 0.0109 bits; the decoder never reads past its buffer (running out
// throws kBakeTruncated); integers are capped at 2^48 in magnitude.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "clod/error.h"

namespace clod::detail {

inline constexpr int kProbBits = 12;
inline constexpr std::uint32_t kProbOne = 1u << kProbBits;
inline constexpr int kAdaptShift = 5;
inline constexpr std::uint32_t kTopValue = 1u << 24;
/// Largest Exp-Golomb class: |value| < 2^kMaxIntClass.
inline constexpr int kMaxIntClass = 48;

/// One adaptive probability (of a 0 bit).
struct BitModel {
  std::uint16_t p = kProbOne / 2;
  void update(unsigned bit) {
    if (bit) p = static_cast<std::uint16_t>(p - (p >> kAdaptShift));
    else p = static_cast<std::uint16_t>(p + ((kProbOne - p) >> kAdaptShift));
  }
};

/// Context of a signed integer: zero flag, sign, class (unary) and first mantissa bit per class.
struct IntModel {
  BitModel zero, sign;
  BitModel cls[kMaxIntClass + 1];
  BitModel mantissa[kMaxIntClass + 1];
};

class RangeEncoder {
public:
  void encodeBit(BitModel& m, unsigned bit) {
    const std::uint32_t bound = (range_ >> kProbBits) * m.p;
    if (bit == 0) {
      range_ = bound;
    } else {
      low_ += bound;
      range_ -= bound;
    }
    m.update(bit);
    while (range_ < kTopValue) {
      range_ <<= 8;
      shiftLow();
    }
  }
  /// `count` (<= 32) low bits of `bits`, most significant first, each at probability 1/2.
  void encodeDirect(std::uint64_t bits, int count) {
    for (int i = count - 1; i >= 0; --i) {
      range_ >>= 1;
      if ((bits >> i) & 1u) low_ += range_;
      while (range_ < kTopValue) {
        range_ <<= 8;
        shiftLow();
      }
    }
  }
  /// Signed integer, |v| < 2^kMaxIntClass (precondition, checked by the caller).
  void encodeInt(IntModel& m, std::int64_t v) {
    encodeBit(m.zero, v == 0 ? 0u : 1u);
    if (v == 0) return;
    encodeBit(m.sign, v < 0 ? 1u : 0u);
    const std::uint64_t mag = static_cast<std::uint64_t>(v < 0 ? -v : v);  // >= 1
    int cls = 0;
    while ((mag >> (cls + 1)) != 0) ++cls;  // mag in [2^cls, 2^(cls+1))
    for (int c = 0; c < cls; ++c) encodeBit(m.cls[c], 1u);
    if (cls < kMaxIntClass) encodeBit(m.cls[cls], 0u);
    if (cls == 0) return;
    encodeBit(m.mantissa[cls], static_cast<unsigned>((mag >> (cls - 1)) & 1u));
    if (cls > 1) encodeDirect(mag & ((std::uint64_t{1} << (cls - 1)) - 1), cls - 1);
  }
  /// Unsigned value of `bits` bits through a binary tree of adaptive models (tree.size() must
  /// be 2^bits).
  void encodeTree(std::span<BitModel> tree, int bits, std::uint32_t value) {
    std::uint32_t node = 1;
    for (int i = bits - 1; i >= 0; --i) {
      const unsigned bit = (value >> i) & 1u;
      encodeBit(tree[node], bit);
      node = 2 * node + bit;
    }
  }
  /// Flushes the coder and returns the bytes.
  std::vector<std::byte> finish() {
    for (int i = 0; i < 5; ++i) shiftLow();
    return std::move(out_);
  }

private:
  void shiftLow() {
    if (low_ < 0xff000000ull || low_ >= (1ull << 32)) {
      const auto carry = static_cast<std::uint8_t>(low_ >> 32);
      std::uint8_t byte = cache_;
      do {
        out_.push_back(static_cast<std::byte>(static_cast<std::uint8_t>(byte + carry)));
        byte = 0xff;
      } while (--cacheSize_ != 0);
      cache_ = static_cast<std::uint8_t>(low_ >> 24);
    }
    ++cacheSize_;
    low_ = (low_ & 0x00ffffffull) << 8;
  }

  std::uint64_t low_ = 0;
  std::uint32_t range_ = 0xffffffffu;
  std::uint8_t cache_ = 0;
  std::uint64_t cacheSize_ = 1;
  std::vector<std::byte> out_;
};

class RangeDecoder {
public:
  /// `context` prefixes error messages. The first byte the encoder writes is always 0.
  RangeDecoder(std::span<const std::byte> in, std::string context) : in_(in), context_(std::move(context)) {
    for (int i = 0; i < 5; ++i) code_ = (code_ << 8) | nextByte();
  }
  unsigned decodeBit(BitModel& m) {
    const std::uint32_t bound = (range_ >> kProbBits) * m.p;
    unsigned bit;
    if (code_ < bound) {
      range_ = bound;
      bit = 0;
    } else {
      code_ -= bound;
      range_ -= bound;
      bit = 1;
    }
    m.update(bit);
    while (range_ < kTopValue) {
      range_ <<= 8;
      code_ = (code_ << 8) | nextByte();
    }
    return bit;
  }
  std::uint64_t decodeDirect(int count) {
    std::uint64_t value = 0;
    for (int i = 0; i < count; ++i) {
      range_ >>= 1;
      unsigned bit = 0;
      if (code_ >= range_) {
        code_ -= range_;
        bit = 1;
      }
      value = (value << 1) | bit;
      while (range_ < kTopValue) {
        range_ <<= 8;
        code_ = (code_ << 8) | nextByte();
      }
    }
    return value;
  }
  std::int64_t decodeInt(IntModel& m) {
    if (decodeBit(m.zero) == 0) return 0;
    const bool negative = decodeBit(m.sign) != 0;
    int cls = 0;
    while (cls < kMaxIntClass && decodeBit(m.cls[cls]) != 0) ++cls;
    std::uint64_t mag = 1;
    if (cls > 0) {
      mag = (mag << 1) | decodeBit(m.mantissa[cls]);
      if (cls > 1) mag = (mag << (cls - 1)) | decodeDirect(cls - 1);
    }
    const auto v = static_cast<std::int64_t>(mag);
    return negative ? -v : v;
  }
  std::uint32_t decodeTree(std::span<BitModel> tree, int bits) {
    std::uint32_t node = 1;
    for (int i = 0; i < bits; ++i) node = 2 * node + decodeBit(tree[node]);
    return node - (1u << bits);
  }
  /// Bytes consumed so far (the encoder's flush makes a decoder read exactly all of them).
  std::size_t consumed() const { return pos_; }

private:
  std::uint32_t nextByte() {
    if (pos_ >= in_.size())
      throw Error(ErrorCode::kBakeTruncated, context_ + ": the coded stream ends early (" + std::to_string(in_.size()) + " bytes)");
    return static_cast<std::uint32_t>(in_[pos_++]);
  }

  std::span<const std::byte> in_;
  std::string context_;
  std::size_t pos_ = 0;
  std::uint32_t code_ = 0;
  std::uint32_t range_ = 0xffffffffu;
};

}  // namespace clod::detail
