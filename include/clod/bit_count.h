#pragma once
// Population count of a 64-bit word, inlined on every target.
//
// Why not std::popcount: without -mpopcnt (Debian's x86-64 baseline has no POPCNT) GCC compiles it
// to a call of libgcc's __popcountdi2, which took 3.5 % of the contact tree's unlimited query
// (perf, bunny-1500's deep pair: the rank queries of ContactTree::firstChild and halfSpaceIndex).
// The bit-parallel sum below is a dozen inline instructions (Warren, "Hacker's Delight", 2nd ed.,
// section 5-1); with POPCNT available the instruction itself is used.

#include <bit>
#include <cstdint>

namespace clod::detail {

inline std::uint32_t popcount64(std::uint64_t x) noexcept {
#if defined(__POPCNT__)
  return static_cast<std::uint32_t>(std::popcount(x));
#else
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<std::uint32_t>((x * 0x0101010101010101ull) >> 56);
#endif
}

}  // namespace clod::detail
