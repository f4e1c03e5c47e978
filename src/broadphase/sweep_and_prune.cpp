#include <algorithm>
#include <numeric>

#include "clod/broadphase.h"
#include "clod/error.h"

namespace clod {

bool findOverlappingPairs(std::span<const Aabb> boxes, const std::uint8_t* active,
                          std::vector<BodyPair>& pairs, BroadPhaseScratch& scratch, std::size_t maxPairs) {
  pairs.clear();
  const std::size_t n = boxes.size();
  if (n < 2) return true;
  // Sweep along the axis on which the centres spread most: fewest false overlaps there.
  Vec3 mean = Vec3::Zero();
  Vec3 meanSq = Vec3::Zero();
  std::size_t counted = 0;
  for (const Aabb& b : boxes) {
    if (b.empty()) continue;
    const Vec3 c = b.center();
    mean += c;
    meanSq += c.cwiseProduct(c);
    ++counted;
  }
  int axis = 0;
  if (counted > 0) {
    const Vec3 var = meanSq / double(counted) - (mean / double(counted)).cwiseAbs2();
    var.maxCoeff(&axis);
  }
  scratch.order.clear();
  for (std::uint32_t i = 0; i < n; ++i)
    if (!boxes[i].empty()) scratch.order.push_back(i);
  std::sort(scratch.order.begin(), scratch.order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const double ka = boxes[a].min[axis], kb = boxes[b].min[axis];
    return ka < kb || (ka == kb && a < b);
  });
  const auto& order = scratch.order;
  for (std::size_t s = 0; s < order.size(); ++s) {
    const Aabb& a = boxes[order[s]];
    for (std::size_t t = s + 1; t < order.size(); ++t) {
      const Aabb& b = boxes[order[t]];
      if (b.min[axis] > a.max[axis]) break;
      const std::uint32_t i = std::min(order[s], order[t]);
      const std::uint32_t j = std::max(order[s], order[t]);
      if (active && !active[i] && !active[j]) continue;
      bool overlap = true;
      for (int k = 0; k < 3; ++k)
        if (a.min[k] > b.max[k] || b.min[k] > a.max[k]) overlap = false;
      if (!overlap) continue;
      pairs.push_back({i, j});
      if (pairs.size() > maxPairs) return false;
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return true;
}

}  // namespace clod
