#pragma once
// The 3x3x3 lattice of a split cell: lattice point (i, j, k), i, j, k in {0, 1, 2}, has linear
// index i + 3j + 9k. The 8 points with all coordinates even are the cell's corners; the other
// 19 are stored per interior node, in linear-index order ("pool slot").

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "clod/contact_tree.h"

namespace clod::detail {

inline constexpr int kLatticeSize = 27;

constexpr bool isCellCorner(int l) { return (l % 3) % 2 == 0 && ((l / 3) % 3) % 2 == 0 && (l / 9) % 2 == 0; }

/// Linear lattice index of corner c (bits x, y, z) of child octant o.
constexpr int childCornerLattice(int o, int c) {
  return ((o & 1) + (c & 1)) + 3 * (((o >> 1) & 1) + ((c >> 1) & 1)) + 9 * (((o >> 2) & 1) + ((c >> 2) & 1));
}

/// Linear lattice index of the parent's corner c.
constexpr int parentCornerLattice(int c) { return 2 * (c & 1) + 6 * ((c >> 1) & 1) + 18 * ((c >> 2) & 1); }

/// Pool slot (0..18) of each lattice point, -1 for the 8 cell corners.
constexpr std::array<int, kLatticeSize> makeLatticeSlots() {
  std::array<int, kLatticeSize> slots{};
  int next = 0;
  for (int l = 0; l < kLatticeSize; ++l) slots[l] = isCellCorner(l) ? -1 : next++;
  return slots;
}
inline constexpr std::array<int, kLatticeSize> kLatticeSlot = makeLatticeSlots();

/// kChildCornerSlot[o][c]: pool slot of child o's corner c. The one corner a child shares with
/// its parent (c == o) has no slot; it maps to slot 0 and the caller keeps the parent's value.
constexpr std::array<std::array<std::uint8_t, 8>, 8> makeChildCornerSlots() {
  std::array<std::array<std::uint8_t, 8>, 8> table{};
  for (int o = 0; o < 8; ++o)
    for (int c = 0; c < 8; ++c) {
      const int slot = kLatticeSlot[childCornerLattice(o, c)];
      table[o][c] = static_cast<std::uint8_t>(slot < 0 ? 0 : slot);
    }
  return table;
}
inline constexpr std::array<std::array<std::uint8_t, 8>, 8> kChildCornerSlot = makeChildCornerSlots();

/// The step of the values a split node of this depth stores: tree.valueStep() (q), divided by 8
/// per octave by which the cell side exceeds 16 errorAbs (by at most 2^24). Coarse cells are
/// few, and a value rounded there would be inherited by every descendant whose field trilinear
/// interpolation reproduces exactly (a flat face away from its edges): with the finer step
/// those stay within ~1e-6 of the diagonal. Always <= q.
inline double latticeStep(const ContactTree& tree, std::uint32_t depth) {
  const double q = tree.valueStep();
  const double ratio = tree.cellSize(depth) / (16.0 * tree.errorAbs);
  if (!(q > 0.0) || !(ratio >= 2.0)) return q;
  const int octaves = std::min(3 * std::ilogb(ratio), 24);  // floor(log2(ratio)) >= 1
  return std::ldexp(q, -octaves);
}

/// The trilinear value at lattice point l of a cell with these corner values: the mean of the
/// corners that share l's even coordinates (exact in double for the float corners of a tree).
inline double latticePrediction(const std::array<float, 8>& corners, int l) {
  const int i = l % 3, j = (l / 3) % 3, k = l / 9;
  double sum = 0.0;
  int n = 0;
  for (int c = 0; c < 8; ++c) {
    const int x = 2 * (c & 1), y = 2 * ((c >> 1) & 1), z = 2 * ((c >> 2) & 1);
    if ((i != 1 && i != x) || (j != 1 && j != y) || (k != 1 && k != z)) continue;
    sum += corners[c];
    ++n;
  }
  return sum / n;
}

/// A stored value: its prediction plus an integer number of steps (the bake file stores the
/// integer). Builder and decoder both compute it with this function, so they agree bit for bit.
inline float storedValue(double prediction, std::int64_t units, double step) {
  return static_cast<float>(prediction + static_cast<double>(units) * step);
}
/// The integer that brings the prediction nearest to `exact`: |storedValue - exact| <= step / 2
/// (plus the float rounding of the result).
inline std::int64_t residualUnits(double exact, double prediction, double step) { return std::llround((exact - prediction) / step); }

static_assert(kLatticeSlot[25] == 18 && kLatticeSlot[26] == -1, "19 slots");
static_assert(childCornerLattice(7, 7) == 26 && childCornerLattice(0, 0) == 0);

}  // namespace clod::detail
