#include "clod/contact_tree.h"

#include <algorithm>
#include <cmath>

#include "clod/error.h"
#include "lattice.h"

namespace clod {

using detail::kChildCornerSlot;

double interpolateTrilinear(const std::array<float, 8>& c, const Vec3& t, Vec3* gradientLocal) noexcept {
  const double x = t.x(), y = t.y(), z = t.z();
  // Interpolate along x on the four x-edges, then y, then z; the gradient falls out of the
  // same differences.
  const double c00 = c[0] + x * (double(c[1]) - c[0]);
  const double c10 = c[2] + x * (double(c[3]) - c[2]);
  const double c01 = c[4] + x * (double(c[5]) - c[4]);
  const double c11 = c[6] + x * (double(c[7]) - c[6]);
  const double c0 = c00 + y * (c10 - c00);
  const double c1 = c01 + y * (c11 - c01);
  if (gradientLocal) {
    const double dx00 = double(c[1]) - c[0], dx10 = double(c[3]) - c[2];
    const double dx01 = double(c[5]) - c[4], dx11 = double(c[7]) - c[6];
    const double dx0 = dx00 + y * (dx10 - dx00);
    const double dx1 = dx01 + y * (dx11 - dx01);
    (*gradientLocal) << dx0 + z * (dx1 - dx0), (c10 - c00) + z * ((c11 - c01) - (c10 - c00)), c1 - c0;
  }
  return c0 + z * (c1 - c0);
}

std::size_t ContactTree::memoryBytes() const {
  return firstChild.size() * sizeof(std::uint32_t) + errorBound.size() * sizeof(float) +
         halfSpaceIndex.size() * sizeof(std::uint32_t) + levelOffsets.size() * sizeof(std::uint32_t) +
         lattice.size() * sizeof(float) + halfSpaces.size() * sizeof(ContactHalfSpace) + sizeof(rootCorners);
}

ContactCell ContactTree::rootCell() const {
  CLOD_ASSERT(!firstChild.empty());
  ContactCell cell;
  cell.corners = rootCorners;
  return cell;
}

ContactCell ContactTree::childCell(const ContactCell& cell, std::uint32_t octant) const {
  CLOD_ASSERT(octant < 8 && firstChild[cell.node] != 0);
  const std::uint32_t first = firstChild[cell.node];
  const float* pool = lattice.data() + std::size_t{(first - 1) / 8} * kContactTreeLatticePerNode;
  ContactCell child;
  child.node = first + octant;
  child.depth = cell.depth + 1;
  for (int a = 0; a < 3; ++a) child.index[a] = 2 * cell.index[a] + ((octant >> a) & 1);
  for (int c = 0; c < 8; ++c) child.corners[c] = pool[kChildCornerSlot[octant][c]];
  child.corners[octant] = cell.corners[octant];
  return child;
}

double ContactTree::minDistance(const ContactCell& cell) const {
  return *std::min_element(cell.corners.begin(), cell.corners.end()) - double(errorBound[cell.node]);
}

double ContactTree::maxDistance(const ContactCell& cell) const {
  return *std::max_element(cell.corners.begin(), cell.corners.end()) + double(errorBound[cell.node]);
}

ContactFieldSample ContactTree::sample(const Vec3& p, std::uint32_t maxDepthQuery) const {
  CLOD_ASSERT(!firstChild.empty() && p.allFinite());
  ContactFieldSample out;
  Vec3 u = (p - origin) / rootSize;
  const Vec3 uClamped = u.cwiseMax(0.0).cwiseMin(1.0);
  double outsideDistance = 0.0;
  if (uClamped != u) {
    outsideDistance = (u - uClamped).norm() * rootSize;
    out.insideRoot = false;
    u = uClamped;
  }
  // Fixed-point position, 31 fractional bits: bit (30 - d) of each coordinate selects the
  // octant at depth d. Depths are limited to 20 by the builder and the decoder.
  constexpr double kScale = 2147483648.0;  // 2^31
  std::uint32_t fixed[3];
  for (int a = 0; a < 3; ++a) {
    const double s = u[a] * kScale;
    fixed[a] = s >= kScale ? 0x7fffffffu : static_cast<std::uint32_t>(s);
  }
  // Descend without gathering corners: record each level's lattice block and octant, then
  // resolve the final cell's corners. Corner c of a cell entered through octant o comes from
  // the parent's block unless c == o, in which case it is the parent's own corner c -- so each
  // corner is found by walking back to the deepest level whose octant differs (1 step in 7 of
  // 8 cases), instead of copying 8 values at every level.
  const float* blocks[32];
  std::uint8_t octants[32];
  std::uint32_t node = 0;
  std::uint32_t depth = 0;
  const std::uint32_t* children = firstChild.data();
  const float* pool = lattice.data();
  while (depth < maxDepthQuery) {
    const std::uint32_t first = children[node];
    if (first == 0) break;
    const std::uint32_t bit = 30 - depth;
    const std::uint32_t octant =
        ((fixed[0] >> bit) & 1u) | (((fixed[1] >> bit) & 1u) << 1) | (((fixed[2] >> bit) & 1u) << 2);
    ++depth;
    blocks[depth] = pool + std::size_t{(first - 1) >> 3} * kContactTreeLatticePerNode;
    octants[depth] = static_cast<std::uint8_t>(octant);
    node = first + octant;
  }
  std::array<float, 8> corners;
  for (std::uint32_t c = 0; c < 8; ++c) {
    std::uint32_t level = depth;
    while (level > 0 && octants[level] == c) --level;
    corners[c] = level == 0 ? rootCorners[c] : blocks[level][kChildCornerSlot[octants[level]][c]];
  }
  const double cells = static_cast<double>(1u << depth);
  Vec3 t;
  for (int a = 0; a < 3; ++a) {
    const double index = static_cast<double>(fixed[a] >> (31 - depth));
    t[a] = std::clamp(u[a] * cells - index, 0.0, 1.0);
  }
  Vec3 gradientLocal;
  out.distance = interpolateTrilinear(corners, t, &gradientLocal);
  out.gradient = gradientLocal * (cells / rootSize);
  out.errorBound = errorBound[node];
  out.node = node;
  out.depth = depth;
  if (!out.insideRoot) {
    out.distance += outsideDistance;
    out.errorBound += 2.0 * outsideDistance;
  }
  return out;
}

}  // namespace clod
