#include "clod/contact_tree.h"

#include <algorithm>
#include <bit>
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
  return nodeWords.size() * sizeof(ContactTreeNodeWord) + errorCode.size() * sizeof(std::uint16_t) +
         levelOffsets.size() * sizeof(std::uint32_t) +
         lattice.size() * sizeof(float) + halfSpaces.size() * sizeof(ContactHalfSpace) + sizeof(rootCorners) +
         gridNode.size() * sizeof(std::uint32_t) + gridCorners.size() * sizeof(float) +
         flatSurface.size() * sizeof(std::uint64_t) + supportOffsets.size() * sizeof(std::uint32_t) +
         supportPoints.size() * sizeof(Vec3);
}

std::uint16_t ContactTree::encodeErrorRatio(double ratio, int mantissaBits) {
  CLOD_ASSERT(ratio >= 0.0 && mantissaBits >= 1 && mantissaBits <= 7);
  // The low bits of a bfloat16 that a code with `mantissaBits` leaves zero.
  const int dropped = 16 + 7 - mantissaBits;
  const std::uint32_t largest = (0x7f7fffffu >> dropped) << (dropped - 16);  // largest finite code
  // Ratios above 1 occur only where the builder found the field discontinuous (open meshes);
  // they must stay representable, or the bound would understate the error there.
  if (!(ratio < 3.0e38)) return static_cast<std::uint16_t>(largest);
  // Round up twice: double -> float, then float -> its upper bits. Both steps only make the
  // bound larger, so the decoded bound stays a bound.
  float f = static_cast<float>(ratio);
  if (static_cast<double>(f) < ratio) f = std::nextafter(f, 2.0f);
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
  std::uint32_t kept = bits >> dropped;
  if ((bits & ((1u << dropped) - 1)) != 0) ++kept;  // positive floats: a larger bit pattern is a larger value
  return static_cast<std::uint16_t>(std::min<std::uint32_t>(kept << (dropped - 16), largest));
}

void ContactTree::assignNodeBits(const std::vector<std::uint8_t>& interior, const std::vector<std::uint8_t>& surface) {
  const std::size_t n = interior.size();
  CLOD_ASSERT(surface.size() == n);
  nodeWords.assign((n + 63) / 64, ContactTreeNodeWord{});
  std::uint32_t interiorCount = 0, surfaceCount = 0;
  for (std::size_t w = 0; w < nodeWords.size(); ++w) {
    ContactTreeNodeWord& word = nodeWords[w];
    word.interiorBefore = interiorCount;
    word.surfaceBefore = surfaceCount;
    for (std::size_t b = 0; b < 64 && 64 * w + b < n; ++b) {
      if (interior[64 * w + b]) word.interior |= std::uint64_t{1} << b;
      if (surface[64 * w + b]) word.surface |= std::uint64_t{1} << b;
    }
    interiorCount += static_cast<std::uint32_t>(std::popcount(word.interior));
    surfaceCount += static_cast<std::uint32_t>(std::popcount(word.surface));
  }
}

namespace {

// Whether the planes of a cell and of one of its children agree within the tree's error over
// the parent cell: normals within errorAbs / h (a tilt moves the plane by angle x h across the
// cell), and the child's plane point within errorAbs of the parent's plane.
bool coplanar(const ContactTree& t, const ContactCell& parent, const ContactHalfSpace& hp, const ContactCell& child,
              const ContactHalfSpace& hc) {
  const Vec3 np(hp.normal[0], hp.normal[1], hp.normal[2]), nc(hc.normal[0], hc.normal[1], hc.normal[2]);
  const double h = t.cellSize(parent.depth);
  if (np.cross(nc).norm() * h > t.errorAbs || np.dot(nc) <= 0.0) return false;
  const Vec3 onChildPlane = t.cellCenter(child) + double(hc.offset) * nc;
  return std::abs(np.dot(onChildPlane - t.cellCenter(parent)) - double(hp.offset)) <= t.errorAbs;
}

bool markFlatSurfaces(ContactTree& t, const ContactCell& cell) {
  const ContactHalfSpace* hs = t.halfSpace(cell.node);
  bool flat = hs != nullptr;
  if (t.isLeaf(cell.node)) {
    flat = flat && double(hs->fitError) <= t.errorAbs;
  } else {
    bool anySurface = false;
    for (std::uint32_t o = 0; o < 8; ++o) {
      const ContactCell child = t.childCell(cell, o);
      const bool childFlat = markFlatSurfaces(t, child);  // every child is visited: each gets its bit
      const ContactHalfSpace* hc = t.halfSpace(child.node);
      if (!hc) continue;
      anySurface = true;
      flat = flat && childFlat && coplanar(t, cell, *hs, child, *hc);
    }
    flat = flat && anySurface;
  }
  if (flat) t.flatSurface[cell.node >> 6] |= std::uint64_t{1} << (cell.node & 63);
  return flat;
}

}  // namespace

void ContactTree::deriveFlatSurfaces() {
  flatSurface.assign((std::size_t{nodeCount()} + 63) / 64, 0);
  if (nodeCount() > 0) markFlatSurfaces(*this, rootCell());
}

void ContactTree::buildLookupGrid(std::uint32_t depthCap) {
  CLOD_ASSERT(depthCap <= 8);
  gridDepth = 0;
  gridNode.clear();
  gridCorners.clear();
  std::uint32_t d = 0;
  // With 32-bit child indices (codec version 1) a depth-5 grid measured 13-20 % slower than
  // none: the node array did not fit in L2 either way. With the shape bitmap (3 bits per node)
  // the descent is L2-resident and the grid saves its top levels: depth 5 measured fastest.
  while (d < depthCap && d + 1 < depthCount() && (std::uint64_t{1} << (3 * (d + 1))) <= nodeCount() / 8) ++d;
  if (d == 0) return;
  gridDepth = d;
  const std::uint32_t n = 1u << d, m = n + 1;
  gridNode.assign(std::size_t{n} * n * n, 0);
  gridCorners.assign(std::size_t{m} * m * m, 0.0f);
  // Depth-first walk over the cells down to depth d; O(8^d).
  ContactCell stack[8 * 8];
  int top = 0;
  stack[top++] = rootCell();
  while (top > 0) {
    const ContactCell cell = stack[--top];
    if (cell.depth == d) {
      const auto& i = cell.index;
      gridNode[i[0] + n * (i[1] + std::size_t{n} * i[2])] = cell.node;
      for (std::uint32_t c = 0; c < 8; ++c)
        gridCorners[(i[0] + (c & 1)) + m * ((i[1] + ((c >> 1) & 1)) + std::size_t{m} * (i[2] + (c >> 2)))] = cell.corners[c];
      continue;
    }
    if (isLeaf(cell.node)) continue;
    for (std::uint32_t o = 0; o < 8; ++o) stack[top++] = childCell(cell, o);
  }
}

double ContactTree::valueStep() const {
  if (!(errorAbs > 0.0) || !std::isfinite(errorAbs)) return 0.0;
  // The largest power of two <= errorAbs / 8: exact in binary, so a multiple k q is exact in
  // double and, while |k| < 2^24, in float.
  int exponent = 0;
  (void)std::frexp(errorAbs / 8.0, &exponent);  // errorAbs / 8 = m 2^exponent, m in [0.5, 1)
  return std::ldexp(1.0, exponent - 1);
}

bool ContactTree::provenFar(const std::array<float, 8>& corners, std::uint32_t depth) const {
  // Every point x of the cell is within half a diagonal of its nearest corner c, so |d(x)| >=
  // |d(c)| - D/2 >= |v_c| - q/2 - D/2. The relative slack covers the float rounding of the
  // corner values (it was the only slack before values were rounded to q).
  float minAbs = std::abs(corners[0]);
  bool sameSign = true;
  for (int c = 1; c < 8; ++c) {
    minAbs = std::min(minAbs, std::abs(corners[c]));
    sameSign = sameSign && ((corners[c] < 0.0f) == (corners[0] < 0.0f));
  }
  const double halfDiagonal = cellRadius(depth);
  return sameSign && double(minAbs) * (1.0 - 1e-6) - 0.5 * valueStep() > bandAbs + halfDiagonal;
}

std::uint16_t ContactTree::farErrorCode(std::uint32_t depth) const {
  // |d(x) - sum w_i v_i| <= sum w_i |x - c_i| + max |d(c_i) - v_i| <= D/2 + q/2.
  // All 7 mantissa bits: the cap is one coded bit in the bake file, and far cells, the most
  // numerous, keep their Lipschitz bound within 0.8 %.
  return encodeErrorRatio(1.0 + 0.5 * valueStep() / cellRadius(depth), 7);
}

ContactCell ContactTree::rootCell() const {
  CLOD_ASSERT(nodeCount() > 0);
  ContactCell cell;
  cell.corners = rootCorners;
  return cell;
}

ContactCell ContactTree::childCell(const ContactCell& cell, std::uint32_t octant) const {
  const std::uint32_t first = firstChild(cell.node);
  CLOD_ASSERT(octant < 8 && first != 0);
  const float* pool = lattice.data() + std::size_t{(first - 1) / 8} * kContactTreeLatticePerNode;
  ContactCell child;
  child.node = first + octant;
  child.depth = cell.depth + 1;
  for (int a = 0; a < 3; ++a) child.index[a] = 2 * cell.index[a] + ((octant >> a) & 1);
  for (int c = 0; c < 8; ++c) child.corners[c] = pool[kChildCornerSlot[octant][c]];
  child.corners[octant] = cell.corners[octant];
  return child;
}

ContactCell ContactTree::cellAt(const Vec3& p, std::uint32_t maxDepthQuery) const {
  CLOD_ASSERT(nodeCount() > 0 && p.allFinite());
  const Vec3 u = ((p - origin) / rootSize).cwiseMax(0.0).cwiseMin(1.0);
  ContactCell cell = rootCell();
  while (cell.depth < maxDepthQuery && !isLeaf(cell.node)) {
    std::uint32_t octant = 0;
    const double cells = static_cast<double>(1u << (cell.depth + 1));
    for (int a = 0; a < 3; ++a) {
      // Half-open cells, the upper root faces belong to the last cell (as in sample()).
      const double x = std::min(u[a] * cells, cells - 0.5);
      if (static_cast<std::uint32_t>(x) > 2 * cell.index[a]) octant |= 1u << a;
    }
    cell = childCell(cell, octant);
  }
  return cell;
}

double ContactTree::minDistance(const ContactCell& cell) const {
  return *std::min_element(cell.corners.begin(), cell.corners.end()) - errorBound(cell.node, cell.depth);
}

double ContactTree::maxDistance(const ContactCell& cell) const {
  return *std::max_element(cell.corners.begin(), cell.corners.end()) + errorBound(cell.node, cell.depth);
}

ContactFieldSample ContactTree::sample(const Vec3& p, std::uint32_t maxDepthQuery) const {
  CLOD_ASSERT(nodeCount() > 0 && p.allFinite());
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
  // the parent's block unless c == o, in which case it is the parent's own corner c, found by
  // walking back to the deepest level whose octant differs.
  //
  // Measured (docs/benchmarks/contact_tree.md): the descent itself is cheap -- the rank
  // bitmap is 3 bits per node and stays in L2 -- and the query's cost is the cache miss on the
  // final lattice block. Each level's block is therefore prefetched as soon as its address is
  // known, so the last block's miss overlaps the last levels of the descent.
  const float* blocks[32];
  std::uint8_t octants[32];
  std::uint32_t node = 0;
  std::uint32_t depth = 0;
  std::uint32_t startDepth = 0;
  std::size_t gridCell = 0;
  if (gridDepth != 0 && maxDepthQuery >= gridDepth) {
    const std::uint32_t shift = 31 - gridDepth;
    gridCell = (fixed[0] >> shift) + ((std::size_t{fixed[1] >> shift} + (std::size_t{fixed[2] >> shift} << gridDepth)) << gridDepth);
    const std::uint32_t start = gridNode[gridCell];
    if (start != 0) node = start, depth = startDepth = gridDepth;
  }
  const ContactTreeNodeWord* words = nodeWords.data();
  const float* pool = lattice.data();
  while (depth < maxDepthQuery) {
    const ContactTreeNodeWord& w = words[node >> 6];
    const std::uint32_t b = node & 63;
    if (((w.interior >> b) & 1u) == 0) break;
    // Rank of this interior node = interior nodes before it; its children start at 1 + 8 rank.
    const std::uint64_t below = w.interior & ((std::uint64_t{1} << b) - 1);
    const std::uint32_t rank = w.interiorBefore + detail::popcount64(below);
    const float* block = pool + std::size_t{rank} * kContactTreeLatticePerNode;
    __builtin_prefetch(block);
    __builtin_prefetch(block + kContactTreeLatticePerNode - 1);
    const std::uint32_t bit = 30 - depth;
    const std::uint32_t octant =
        ((fixed[0] >> bit) & 1u) | (((fixed[1] >> bit) & 1u) << 1) | (((fixed[2] >> bit) & 1u) << 2);
    ++depth;
    blocks[depth] = block;
    octants[depth] = static_cast<std::uint8_t>(octant);
    node = 1 + 8 * rank + octant;
  }
  std::array<float, 8> corners;
  if (depth == startDepth) {
    if (startDepth == 0) {
      corners = rootCorners;
    } else {
      const std::size_t n = std::size_t{1} << gridDepth, m = n + 1;
      const std::size_t ix = gridCell % n, iy = (gridCell / n) % n, iz = gridCell / (n * n);
      for (std::uint32_t c = 0; c < 8; ++c)
        corners[c] = gridCorners[(ix + (c & 1)) + m * ((iy + ((c >> 1) & 1)) + m * (iz + (c >> 2)))];
    }
  } else {
    // Seven corners come from the last block (kChildCornerSlot maps the eighth, o, to a valid
    // slot whose value is then replaced), without a data-dependent branch per corner.
    const std::uint32_t o = octants[depth];
    const float* last = blocks[depth];
    for (std::uint32_t c = 0; c < 8; ++c) corners[c] = last[kChildCornerSlot[o][c]];
    std::uint32_t level = depth - 1;
    while (level > startDepth && octants[level] == o) --level;
    if (level > startDepth) {
      corners[o] = blocks[level][kChildCornerSlot[octants[level]][o]];
    } else if (startDepth == 0) {
      corners[o] = rootCorners[o];
    } else {
      // Corner o of the grid cell (rare: every octant below the grid equals o).
      const std::size_t n = std::size_t{1} << gridDepth, m = n + 1;
      const std::size_t ix = gridCell % n, iy = (gridCell / n) % n, iz = gridCell / (n * n);
      corners[o] = gridCorners[(ix + (o & 1)) + m * ((iy + ((o >> 1) & 1)) + m * (iz + (o >> 2)))];
    }
  }
  const double cells = static_cast<double>(1u << depth);
  Vec3 t;
  for (int a = 0; a < 3; ++a) {
    const double index = static_cast<double>(fixed[a] >> (31 - depth));
    t[a] = std::clamp(u[a] * cells - index, 0.0, 1.0);
  }
  Vec3 gradientLocal;
  out.distance = interpolateTrilinear(corners, t, &gradientLocal);
  const double cellsPerLength = cells / rootSize;
  out.gradient = gradientLocal * cellsPerLength;
  out.errorBound = errorBound(node, depth);
  out.node = node;
  out.depth = depth;
  if (!out.insideRoot) {
    out.distance += outsideDistance;
    out.errorBound += 2.0 * outsideDistance;
  }
  return out;
}

}  // namespace clod
