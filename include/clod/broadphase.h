#pragma once
// Broad phase: which pairs of bodies may touch, from their world-space bounding boxes.
//
// Method: sweep and prune on one axis (Baraff 1992, "Dynamic simulation of non-penetrating
// rigid bodies", ch. 7). The box intervals are sorted by their minimum on the axis of largest
// spread of the box centres, swept once, and every interval overlap is checked on the other two
// axes. Sorting is O(n log n) (std::sort; insertion sort would exploit coherence but the sort is
// not the cost that matters next to the narrow phase), the sweep O(n + k) for k overlaps on the
// sweep axis.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "clod/math.h"

namespace clod {

/// A candidate pair, first < second (indices into the box array).
using BodyPair = std::array<std::uint32_t, 2>;

/// Reusable working memory of findOverlappingPairs (no allocation once grown).
struct BroadPhaseScratch {
  std::vector<std::uint32_t> order;
  std::vector<double> keys;
};

/// Appends to `pairs` (cleared first) every pair (i, j), i < j, whose boxes overlap (closed
/// intervals on all three axes) and for which `active` is null or active[i] || active[j] (so
/// pairs of two static bodies can be left out). Output sorted lexicographically, so it does not
/// depend on the sweep axis. Empty boxes (Aabb::empty) overlap nothing. `active`, when given,
/// has boxes.size() entries (CLOD_ASSERT). Throws nothing.
/// Stops and returns false once more than `maxPairs` pairs are found (then `pairs` holds
/// maxPairs + 1 of them, unsorted): n bodies piled at one point make n(n-1)/2 pairs, and a
/// caller with a memory limit learns it before the list grows to that size.
bool findOverlappingPairs(std::span<const Aabb> boxes, const std::uint8_t* active,
                          std::vector<BodyPair>& pairs, BroadPhaseScratch& scratch,
                          std::size_t maxPairs = std::numeric_limits<std::size_t>::max());

}  // namespace clod
