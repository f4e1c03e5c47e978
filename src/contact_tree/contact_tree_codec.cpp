#include "clod/contact_tree_codec.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "clod/error.h"
#include "half_space_code.h"
#include "lattice.h"
#include "range_coder.h"

namespace clod {

namespace {

using detail::BitModel;
using detail::IntModel;
using detail::kLatticeSize;
using detail::kLatticeSlot;

// Integers the codec handles stay below 2^46 in magnitude, far inside int64 and the coder's
// 2^48 cap, so sums of eight of them cannot overflow.
constexpr double kMaxUnits = 70368744177664.0;  // 2^46
constexpr int kDepthContexts = 16;
// An error code is its high byte (7 bits: the exponent's upper 7) and then the exponent's last
// bit and the kErrorMantissaBits mantissa bits; the bits below are zero (isCoarseErrorCode).
constexpr int kErrorLowBits = 1 + ContactTree::kErrorMantissaBits;
constexpr int kErrorLowShift = 8 - kErrorLowBits;
constexpr int kErrorLowCodes = 1 << kErrorLowBits;
constexpr int kFitLowBits = 1 + detail::kFitMantissaBits;
constexpr int kFitLowShift = 8 - kFitLowBits;

// What the residuals of a split node coded so far say about the next one: their mean magnitude
// (the field's curvature at this cell's scale: an edge or a bend gives large residuals all
// over the block, a flat face zeros) and the sign of the last nonzero one (convex or concave).
struct LatticeActivity {
  static constexpr int kContexts = 7 * 3;
  std::uint64_t sum = 0;
  int count = 0;
  int lastSign = 0;  // 0 none yet, 1 positive, 2 negative
  int context() const {
    const int magnitude = count == 0 ? 6 : std::min(5, static_cast<int>(std::bit_width(sum / static_cast<std::uint64_t>(count))));
    return magnitude * 3 + lastSign;
  }
  void add(std::int64_t u) {
    sum += static_cast<std::uint64_t>(std::min<std::int64_t>(u < 0 ? -u : u, std::int64_t{1} << 40));
    ++count;
    if (u != 0) lastSign = u > 0 ? 1 : 2;
  }
};

// Adaptive models of everything the stream holds; encoder and decoder start from the same
// state and update them identically. Contexts: what the decoder already knows about a node
// (its depth, whether it is split, where the field's zero set is).
struct Models {
  BitModel interior[kDepthContexts];
  BitModel surface[2][3][2];  // [split][|centre estimate| / radius bucket][corner signs differ]
  BitModel errorFar[2][kDepthContexts];  // [split][depth]: the code is the Lipschitz cap farErrorCode
  BitModel errorHigh[2][2][kDepthContexts][128];  // [split][surface][depth]
  BitModel errorLow[2][8][kErrorLowCodes];  // [split][low 3 bits of the high byte]
  // [odd coordinates - 1: edge, face, centre][depth][LatticeActivity::context()]
  IntModel lattice[3][kDepthContexts][LatticeActivity::kContexts];
  IntModel normal[2][2];                // [split][component]
  IntModel offset[2];
  BitModel fitHigh[2][kDepthContexts][128];
  BitModel fitLow[2][8][1 << kFitLowBits];
  BitModel normalFromAncestor[2][2];  // [split][the cell has an ancestor with a half-space]
  BitModel sharedSame[kDepthContexts];  // a lattice point a neighbour coded holds its value
  // [split][surface][candidates: 1, 2, 3+]: the error code is one of the neighbours'
  BitModel errorSame[2][2][3];
  BitModel errorPick[2][4];  // [candidates - 2]: which one
  BitModel normalSame[2][3];  // [split][candidates: 1, 2, 3+]
  BitModel normalPick[2][4];
  IntModel offsetFromNeighbour[2];
  IntModel fitFromNeighbour[2];
};

int depthContext(std::uint32_t depth) { return depth < kDepthContexts ? static_cast<int>(depth) : kDepthContexts - 1; }

// The integer residual of a stored value (storedValue(prediction, units, step) == value), or
// false if there is none in range.
bool unitsOf(float value, double prediction, double step, std::int64_t& units) {
  const double u = (double(value) - prediction) / step;
  if (!(std::abs(u) < kMaxUnits)) return false;
  units = std::llround(u);
  return detail::storedValue(prediction, units, step) == value;
}

int latticeClass(int l) { return (l % 3 == 1) + ((l / 3) % 3 == 1) + (l / 9 == 1) - 1; }

struct NodeGuess {
  int surfaceBucket = 0;
  int signChange = 0;
  double centre = 0.0;  // trilinear value at the cell centre
  std::array<std::int32_t, 2> normal{0, 0};
};

// What the corners say about a node before anything of it is read.
NodeGuess guessNode(const ContactTree& tree, const std::array<float, 8>& corners, std::uint32_t depth) {
  NodeGuess g;
  double sum = 0.0, gx = 0.0, gy = 0.0, gz = 0.0;
  for (int c = 0; c < 8; ++c) {
    const double v = corners[c];
    sum += v;
    gx += (c & 1) ? v : -v;
    gy += ((c >> 1) & 1) ? v : -v;
    gz += ((c >> 2) & 1) ? v : -v;
    g.signChange |= (corners[c] < 0.0f) != (corners[0] < 0.0f);
  }
  g.centre = sum / 8.0;
  const double ratio = std::abs(g.centre) / tree.cellRadius(depth);
  g.surfaceBucket = ratio < 0.5 ? 0 : ratio < 1.5 ? 1 : 2;
  g.normal = detail::encodeOctNormal(gx, gy, gz);  // direction of the trilinear gradient at the centre
  return g;
}

// A node of the level being coded: its corners and the normal code of its nearest ancestor
// with a half-space (the surface that crosses a cell crosses its parent, and its normal varies
// little between them, so it predicts the node's normal better than the corners do).
struct LevelCell {
  std::array<float, 8> corners{};
  std::array<std::int32_t, 2> ancestorNormal{0, 0};
  bool hasAncestorNormal = false;
};

// What a node of the level being coded left for its neighbours: its error code and half-space.
struct CodedCell {
  std::uint16_t errorCode = 0;
  std::uint16_t fitCode = 0;
  std::array<std::int32_t, 2> normal{0, 0};  // octahedral code
  float offset = 0.0f;
  bool hasHalfSpace = false;
  bool predicts = false;  // coded, with an error code below the cap or a half-space
};

// A face neighbour of the same depth coded before the node, and where it lies: the node's
// position plus `sign` along `axis`.
struct Neighbour {
  CodedCell cell;
  int axis;
  int sign;
};

// The nodes of one depth in coding order, with their face neighbours of that depth. A level lists
// the children of the level above in its order and in octant order, which is Morton order: a
// node's -x, -y and -z neighbours come before it, the others after. A node's neighbour on a side
// is its sibling or the child of its parent's neighbour on that side, so the links of a level
// follow from the level above in O(1) per node.
//
// What the neighbours give the codec (version 6): (1) a lattice point on a split node's boundary
// that a split neighbour coded before holds the same value (the builder rounds the same exact
// distance against the same prediction: an edge's or a face's trilinear value depends on that
// edge's or face's corners alone), so it costs one bit; in a band of split cells each node's 18
// boundary values were coded up to four times. (2) Neighbours of one surface lie on the same
// face of a faceted mesh (bunny-1500: 61 % of its surface cells have a coded neighbour whose
// half-space normal is the node's, to the last bit), so a neighbour predicts the normal exactly,
// the offset from its plane and the fit error; error bounds of neighbours often agree too.
class Level {
public:
  std::vector<LevelCell> cells;

  static Level root(const std::array<float, 8>& corners) {
    Level level;
    level.cells.push_back({corners});
    level.links_.push_back(kNoLinks);
    level.startCoding();
    return level;
  }
  std::size_t size() const { return cells.size(); }
  bool empty() const { return cells.empty(); }

  // Sizes the per-node records; links_ are already set (root, or linkChildren).
  void startCoding() {
    firstChild_.assign(cells.size(), -1);
    block_.assign(cells.size(), -1);
    coded_.assign(cells.size(), CodedCell{});
  }
  // Node j is split: its lattice block is `block` (index of its 19 values in the tree's pool)
  // and its children, with corners from the 27 lattice values, go to the next level.
  void pushChildren(std::size_t j, const LevelCell& cell, const std::array<float, kLatticeSize>& lattice, std::int32_t block,
                    Level& next) {
    firstChild_[j] = static_cast<std::int32_t>(next.cells.size());
    block_[j] = block;
    for (int o = 0; o < 8; ++o) {
      LevelCell child;
      for (int c = 0; c < 8; ++c) child.corners[c] = lattice[detail::childCornerLattice(o, c)];
      child.ancestorNormal = cell.ancestorNormal;
      child.hasAncestorNormal = cell.hasAncestorNormal;
      next.cells.push_back(child);
    }
  }
  void record(std::size_t j, const CodedCell& coded) { coded_[j] = coded; }
  // The coded face neighbours of node j that have something to predict, in the order -x, -y, -z.
  int gather(std::size_t j, std::array<Neighbour, 3>& out) const {
    int count = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const std::int32_t q = links_[j][2 * axis];
      if (q >= 0 && coded_[q].predicts) out[count++] = {coded_[q], axis, -1};
    }
    return count;
  }
  // The value that the first split node of this level sharing lattice point l of node j stored
  // there, if that node was coded before j (`pool`: the tree's lattice values so far).
  bool sharedValue(std::size_t j, int l, const std::vector<float>& pool, float& value) const {
    const std::array<int, 3> at{l % 3, (l / 3) % 3, l / 9};
    std::int64_t first = -1;
    int firstL = 0;
    // Offsets -1 / 0 / +1 per axis toward the cells that share the point (0 only where the
    // point lies in the cell's middle along that axis).
    for (int dz = at[2] == 0 ? -1 : 0; dz <= (at[2] == 2 ? 1 : 0); ++dz)
      for (int dy = at[1] == 0 ? -1 : 0; dy <= (at[1] == 2 ? 1 : 0); ++dy)
        for (int dx = at[0] == 0 ? -1 : 0; dx <= (at[0] == 2 ? 1 : 0); ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const std::int64_t q = walk(j, {dx, dy, dz});
          if (q < 0 || q >= static_cast<std::int64_t>(j) || block_[q] < 0 || (first >= 0 && q >= first)) continue;
          first = q;
          firstL = (at[0] - 2 * dx) + 3 * (at[1] - 2 * dy) + 9 * (at[2] - 2 * dz);
        }
    if (first < 0) return false;
    value = pool[std::size_t(block_[first]) * kContactTreeLatticePerNode + std::size_t(detail::kLatticeSlot[firstL])];
    return true;
  }
  // Sets the links of `next` (this level's children) once every node of this level is coded.
  void linkChildren(Level& next) const {
    next.links_.assign(next.cells.size(), kNoLinks);
    for (std::size_t p = 0; p < cells.size(); ++p) {
      if (firstChild_[p] < 0) continue;
      for (int o = 0; o < 8; ++o)
        for (int side = 0; side < 6; ++side) {
          const int bit = 1 << (side / 2);
          const bool toSibling = (side % 2 == 0) == ((o & bit) != 0);  // -x side of an x = 1 child, ...
          const std::int32_t q = toSibling ? static_cast<std::int32_t>(p) : links_[p][side];
          if (q >= 0 && firstChild_[q] >= 0) next.links_[std::size_t(firstChild_[p] + o)][side] = firstChild_[q] + (o ^ bit);
        }
    }
    next.startCoding();
  }

private:
  static constexpr std::array<std::int32_t, 6> kNoLinks{-1, -1, -1, -1, -1, -1};
  // The node at offset d (each -1, 0 or +1) from node j, or -1: along the axes in either order
  // (a diagonal neighbour may be reachable through one face neighbour and not the other).
  std::int64_t walk(std::size_t j, const std::array<int, 3>& d) const {
    for (int order = 0; order < 2; ++order) {
      std::int64_t q = static_cast<std::int64_t>(j);
      for (int k = 0; k < 3 && q >= 0; ++k) {
        const int axis = order == 0 ? k : 2 - k;
        if (d[axis] != 0) q = links_[std::size_t(q)][2 * axis + (d[axis] > 0)];
      }
      if (q >= 0) return q;
    }
    return -1;
  }

  std::vector<std::array<std::int32_t, 6>> links_;  // per node: the neighbour on -x, +x, -y, +y, -z, +z
  std::vector<std::int32_t> firstChild_;            // per node: its first child's index in the next level
  std::vector<std::int32_t> block_;                 // per node: its lattice block, -1 if not split
  std::vector<CodedCell> coded_;
};

// Distinct values among the neighbours (first occurrence kept, in the neighbours' order): the
// candidates a node's value is picked from.
template <class Value, class Of>
int distinctCandidates(const std::array<Neighbour, 3>& nbs, int count, Of of, std::array<Value, 3>& values,
                       std::array<int, 3>& from) {
  int n = 0;
  for (int k = 0; k < count; ++k) {
    Value v{};
    if (!of(nbs[k].cell, v)) continue;
    bool seen = false;
    for (int i = 0; i < n && !seen; ++i) seen = values[i] == v;
    if (seen) continue;
    values[n] = v;
    from[n++] = k;
  }
  return n;
}

int candidateContext(int n) { return std::min(n, 3) - 1; }

// The offset a neighbour's plane predicts at this node's centre: the plane n.(x - c) = offset of
// a cell centred at c is n.(x - c') = offset + n.(c - c') at c', and c - c' = sign h e_axis.
double offsetFromNeighbour(const Neighbour& nb, const std::array<float, 3>& normal, double h) {
  return double(nb.cell.offset) + nb.sign * h * double(normal[nb.axis]);
}

// Whether a value is one of n <= 3 candidates (index, or -1 for none), and which: one adaptive
// bit, then the index through a tree of models for that n.
void encodeChoice(detail::RangeEncoder& enc, BitModel& same, BitModel (&pick)[2][4], int n, int index) {
  enc.encodeBit(same, index >= 0 ? 1u : 0u);
  if (index >= 0 && n > 1) enc.encodeTree(pick[n - 2], 2, static_cast<std::uint32_t>(index));
}
// -1 for none; an index >= n is returned for the caller to refuse.
int decodeChoice(detail::RangeDecoder& dec, BitModel& same, BitModel (&pick)[2][4], int n) {
  if (dec.decodeBit(same) == 0) return -1;
  return n > 1 ? static_cast<int>(dec.decodeTree(pick[n - 2], 2)) : 0;
}

// The steps from the anchor that a neighbour's plane predicts (bounded: a corrupt stream's
// neighbour may lie anywhere).
std::int64_t neighbourUnits(const Neighbour& nb, const std::array<float, 3>& normal, double h, double anchor, double step) {
  return std::llround(std::clamp((offsetFromNeighbour(nb, normal, h) - anchor) / step, -kMaxUnits, kMaxUnits));
}

bool sameBits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

// The residual a shared value would have had against this node's prediction, for the lattice
// contexts (bounded: a neighbour's value in a corrupt stream may lie anywhere).
std::int64_t sharedUnits(float value, double prediction, double step) {
  return std::llround(std::clamp((double(value) - prediction) / step, -kMaxUnits, kMaxUnits));
}

[[noreturn]] void refuse(const std::string& what) { throw Error(ErrorCode::kInvalidArgument, "contact tree: " + what); }

}  // namespace

void encodeContactTree(const ContactTree& tree, ByteWriter& out) {
  // The tree's shape must be consistent before the walk below can index its arrays.
  const std::uint64_t n = tree.nodeCount();
  if (n == 0 || tree.levelOffsets.front() != 0 || tree.levelOffsets[1] != 1) refuse("levelOffsets must start 0, 1");
  if (tree.nodeWords.size() != (n + 63) / 64 || tree.errorCode.size() != n) refuse("per-node arrays do not match the node count");
  if (tree.depthCount() > tree.maxDepth + 1) refuse("deeper than maxDepth");
  std::uint64_t interiorCount = 0, surfaceCount = 0;
  for (std::uint32_t d = 0; d < tree.depthCount(); ++d) {
    std::uint64_t split = 0;
    if (tree.levelOffsets[d + 1] <= tree.levelOffsets[d]) refuse("levelOffsets do not increase");
    for (std::uint32_t i = tree.levelOffsets[d]; i < tree.levelOffsets[d + 1]; ++i) {
      split += !tree.isLeaf(i);
      surfaceCount += tree.halfSpaceIndex(i) != kNoHalfSpace;
    }
    interiorCount += split;
    const std::uint64_t nextSize = d + 1 < tree.depthCount() ? tree.levelOffsets[d + 2] - tree.levelOffsets[d + 1] : 0;
    if (8 * split != nextSize) refuse("level " + std::to_string(d + 1) + " does not hold 8 children per interior node of level " + std::to_string(d));
  }
  if (tree.lattice.size() != interiorCount * kContactTreeLatticePerNode) refuse("lattice size does not match the interior nodes");
  if (tree.halfSpaces.size() != surfaceCount) refuse("halfSpaces size does not match the surface bitmap");
  if (!(tree.valueStep() > 0.0)) refuse("errorAbs is not finite and > 0");
  for (float v : tree.rootCorners)
    if (!std::isfinite(v)) refuse("root corner value is not finite");

  out.write<std::uint32_t>(kContactTreeCodecVersion);
  for (int a = 0; a < 3; ++a) out.write<double>(tree.origin[a]);
  out.write<double>(tree.rootSize);
  out.write<double>(tree.meshDiagonal);
  out.write<double>(tree.errorAbs);
  out.write<double>(tree.bandAbs);
  out.write<std::uint32_t>(tree.maxDepth);
  for (float v : tree.rootCorners) out.write<float>(v);
  out.write<std::uint32_t>(static_cast<std::uint32_t>(n));
  out.write<std::uint32_t>(tree.depthCount());

  auto models = std::make_unique<Models>();
  detail::RangeEncoder enc;
  Level level = Level::root(tree.rootCorners), next;
  std::array<float, kLatticeSize> lattice{};
  for (std::uint32_t d = 0; d < tree.depthCount(); ++d) {
    next.cells.clear();
    const int dc = depthContext(d);
    const double h = tree.cellSize(d);
    const std::uint16_t farCode = tree.farErrorCode(d);
    const double step = detail::latticeStep(tree, d), hsStep = step / detail::kOffsetStepDivisor;
    for (std::uint32_t j = 0; j < level.size(); ++j) {
      const std::uint32_t node = tree.levelOffsets[d] + j;
      LevelCell cell = level.cells[j];
      const std::array<float, 8>& corners = cell.corners;
      const bool split = !tree.isLeaf(node);
      const ContactHalfSpace* hs = tree.halfSpace(node);
      const std::uint16_t code = tree.errorCode[node];
      auto bad = [&](const std::string& what) { refuse("node " + std::to_string(node) + ": " + what); };
      if (tree.provenFar(corners, d)) {
        // Derived by the decoder: a proven-far cell is a leaf without a half-space.
        if (split || hs || code != farCode) bad("its corners prove it far from the surface, but it is split, has a half-space or another error bound");
        continue;
      }
      if (d == tree.maxDepth && split) bad("split at maxDepth");
      if (d < tree.maxDepth) enc.encodeBit(models->interior[dc], split ? 1u : 0u);
      const NodeGuess guess = guessNode(tree, corners, d);
      enc.encodeBit(models->surface[split][guess.surfaceBucket][guess.signChange], hs ? 1u : 0u);
      std::array<Neighbour, 3> nbs{};
      const int nbCount = level.gather(j, nbs);
      CodedCell self{.errorCode = code, .hasHalfSpace = hs != nullptr};
      // The Lipschitz cap (one bit), one of the neighbours' codes, or the code's two bytes.
      const bool isFar = code == farCode;
      enc.encodeBit(models->errorFar[split][dc], isFar ? 1u : 0u);
      if (!isFar) {
        if (!ContactTree::isCoarseErrorCode(code)) bad("error code is not a finite bound the codec stores");
        std::array<std::uint16_t, 3> codes{};
        std::array<int, 3> from{};
        const int count = distinctCandidates(nbs, nbCount, [&](const CodedCell& c, std::uint16_t& v) { v = c.errorCode; return c.errorCode != farCode; }, codes, from);
        int index = -1;
        for (int i = 0; i < count && index < 0; ++i)
          if (codes[i] == code) index = i;
        if (count > 0) encodeChoice(enc, models->errorSame[split][hs ? 1 : 0][candidateContext(count)], models->errorPick, count, index);
        if (index < 0) {
          enc.encodeTree(models->errorHigh[split][hs ? 1 : 0][dc], 7, code >> 8);
          enc.encodeTree(models->errorLow[split][(code >> 8) & 7u], kErrorLowBits, (code & 0xffu) >> kErrorLowShift);
        }
      }

      // The neighbour whose half-space normal this node's is, if any: it predicts the offset and
      // the fit error too.
      const Neighbour* planeNeighbour = nullptr;
      if (hs) {
        std::array<std::int32_t, 2> oct{};
        if (!detail::findOctCode(hs->normal, oct)) bad("half-space normal is not one the octahedral code stores");
        std::array<std::array<std::int32_t, 2>, 3> normals{};
        std::array<int, 3> from{};
        const int count = distinctCandidates(nbs, nbCount, [](const CodedCell& c, std::array<std::int32_t, 2>& v) { v = c.normal; return c.hasHalfSpace; }, normals, from);
        int index = -1;
        for (int i = 0; i < count && index < 0; ++i)
          if (normals[i] == oct) index = i;
        if (count > 0) encodeChoice(enc, models->normalSame[split][candidateContext(count)], models->normalPick, count, index);
        if (index >= 0) {
          planeNeighbour = &nbs[from[index]];
        } else {
          // Predicted by the nearest ancestor's normal or by the trilinear gradient, whichever
          // is closer (one adaptive bit says which).
          const auto gap = [&](const std::array<std::int32_t, 2>& p) { return std::abs(oct[0] - p[0]) + std::abs(oct[1] - p[1]); };
          const bool fromAncestor = cell.hasAncestorNormal && gap(cell.ancestorNormal) <= gap(guess.normal);
          enc.encodeBit(models->normalFromAncestor[split][cell.hasAncestorNormal], fromAncestor ? 1u : 0u);
          const std::array<std::int32_t, 2> prior = fromAncestor ? cell.ancestorNormal : guess.normal;
          enc.encodeInt(models->normal[split][0], oct[0] - prior[0]);
          enc.encodeInt(models->normal[split][1], oct[1] - prior[1]);
        }
        cell.ancestorNormal = oct;
        cell.hasAncestorNormal = true;
        self.normal = oct;
      }
      if (split) {
        const std::uint32_t block = (tree.firstChild(node) - 1) / 8;
        LatticeActivity activity;
        for (int l = 0; l < kLatticeSize; ++l) {
          if (kLatticeSlot[l] < 0) continue;
          const float v = tree.lattice[std::size_t{block} * kContactTreeLatticePerNode + kLatticeSlot[l]];
          const double prediction = detail::latticePrediction(corners, l);
          lattice[l] = v;
          if (float known = 0.0f; l != 13 && level.sharedValue(j, l, tree.lattice, known)) {
            const bool same = sameBits(known, v);
            enc.encodeBit(models->sharedSame[dc], same ? 1u : 0u);
            if (same) {
              activity.add(sharedUnits(v, prediction, step));
              continue;
            }
          }
          std::int64_t u = 0;
          if (!unitsOf(v, prediction, step, u)) bad("lattice value is not its prediction plus a multiple of the value step");
          enc.encodeInt(models->lattice[latticeClass(l)][dc][activity.context()], u);
          activity.add(u);
        }
        for (int c = 0; c < 8; ++c) lattice[detail::parentCornerLattice(c)] = corners[c];
        level.pushChildren(j, cell, lattice, static_cast<std::int32_t>(block), next);
      }
      if (hs) {
        // Offset = -d(centre), on the grid anchored at the stored centre value of a split cell,
        // else at the trilinear value at the centre; where a neighbour has the same normal, its
        // plane predicts the number of steps.
        std::int64_t offsetUnits = 0;
        std::uint16_t fitCode = 0;
        const double anchor = detail::offsetPrediction(corners, split, lattice[13]);
        if (!unitsOf(hs->offset, anchor, hsStep, offsetUnits))
          bad("half-space offset is not its prediction plus a multiple of the half-space step");
        if (!detail::findFitCode(hs->fitError, h, fitCode)) bad("half-space fit error is not one the codec stores");
        if (planeNeighbour) {
          enc.encodeInt(models->offsetFromNeighbour[split], offsetUnits - neighbourUnits(*planeNeighbour, hs->normal, h, anchor, hsStep));
          enc.encodeInt(models->fitFromNeighbour[split], std::int64_t{fitCode} - planeNeighbour->cell.fitCode);
        } else {
          enc.encodeInt(models->offset[split], offsetUnits);
          enc.encodeTree(models->fitHigh[split][dc], 7, fitCode >> 8u);
          enc.encodeTree(models->fitLow[split][(fitCode >> 8) & 7u], kFitLowBits, (fitCode & 0xffu) >> kFitLowShift);
        }
        self.offset = hs->offset;
        self.fitCode = fitCode;
      }
      self.predicts = self.hasHalfSpace || code != farCode;
      level.record(j, self);
    }
    level.linkChildren(next);
    std::swap(level, next);
  }
  const std::vector<std::byte> coded = enc.finish();
  out.writeArray(coded);
}

ContactTree decodeContactTree(ByteReader& in) {
  auto fail = [&](const std::string& what) { in.fail("contact tree: " + what); };
  const auto version = in.read<std::uint32_t>();
  if (version != kContactTreeCodecVersion) {
    throw Error(ErrorCode::kBakeVersion, in.context() + ": contact tree: version " + std::to_string(version) +
                                             " is not the supported version " + std::to_string(kContactTreeCodecVersion) +
                                             (version < 3 ? " (an older, uncompressed layout): re-bake the mesh"
                                              : version < kContactTreeCodecVersion ? " (an older coding): re-bake the mesh"
                                                                                   : ""));
  }
  ContactTree tree;
  for (int a = 0; a < 3; ++a) tree.origin[a] = in.read<double>();
  tree.rootSize = in.read<double>();
  tree.meshDiagonal = in.read<double>();
  tree.errorAbs = in.read<double>();
  tree.bandAbs = in.read<double>();
  tree.maxDepth = in.read<std::uint32_t>();
  for (float& v : tree.rootCorners) v = in.read<float>();
  const std::uint32_t n = in.read<std::uint32_t>();
  const std::uint32_t depths = in.read<std::uint32_t>();
  const std::vector<std::byte> coded = in.readArray<std::byte>();

  if (!tree.origin.allFinite()) fail("origin is not finite");
  if (!(std::isfinite(tree.rootSize) && tree.rootSize > 0.0)) fail("rootSize " + std::to_string(tree.rootSize) + " is not finite and > 0");
  if (!(std::isfinite(tree.meshDiagonal) && tree.meshDiagonal >= 0.0)) fail("meshDiagonal is not finite and >= 0");
  if (!(std::isfinite(tree.errorAbs) && tree.errorAbs > 0.0)) fail("errorAbs is not finite and > 0");
  if (!(std::isfinite(tree.bandAbs) && tree.bandAbs >= 0.0)) fail("bandAbs is not finite and >= 0");
  if (tree.maxDepth < 1 || tree.maxDepth > 20) fail("maxDepth " + std::to_string(tree.maxDepth) + " is outside 1..20");
  if (depths < 1 || depths > tree.maxDepth + 1) fail(std::to_string(depths) + " depths for maxDepth " + std::to_string(tree.maxDepth));
  // Every split node codes at least 20 adaptive decisions of > 0.0109 bits each and brings 8
  // nodes, so a stream of B bytes holds fewer than 1 + 8 * 8B / 0.218 < 300 B + 64 nodes: a
  // larger count is refused before anything of that size is allocated.
  if (n < 1 || n > 0xfffffff0u || n > 320.0 * double(coded.size()) + 64.0)
    fail("node count " + std::to_string(n) + " is impossible for a coded stream of " + std::to_string(coded.size()) + " bytes");
  for (int c = 0; c < 8; ++c)
    if (!std::isfinite(tree.rootCorners[c])) fail("rootCorners[" + std::to_string(c) + "] is not finite");

  auto models = std::make_unique<Models>();
  detail::RangeDecoder dec(coded, in.context() + ": contact tree");
  std::vector<std::uint8_t> interiorFlags, surfaceFlags;
  interiorFlags.reserve(n);
  surfaceFlags.reserve(n);
  tree.errorCode.reserve(n);
  tree.levelOffsets.push_back(0);
  Level level = Level::root(tree.rootCorners), next;
  std::array<float, kLatticeSize> lattice{};
  std::uint64_t decoded = 0;
  for (std::uint32_t d = 0; !level.empty(); ++d) {
    if (d >= depths) fail("the tree is deeper than its " + std::to_string(depths) + " declared depths");
    if (decoded + level.size() > n) fail("the coded stream holds more than the declared " + std::to_string(n) + " nodes");
    next.cells.clear();
    const int dc = depthContext(d);
    const double h = tree.cellSize(d);
    const std::uint16_t farCode = tree.farErrorCode(d);
    const double step = detail::latticeStep(tree, d), hsStep = step / detail::kOffsetStepDivisor;
    for (std::size_t j = 0; j < level.size(); ++j) {
      LevelCell& cell = level.cells[j];
      const std::array<float, 8>& corners = cell.corners;
      const std::uint64_t node = decoded++;
      if (tree.provenFar(corners, d)) {
        tree.errorCode.push_back(farCode);
        interiorFlags.push_back(0);
        surfaceFlags.push_back(0);
        continue;
      }
      const bool split = d < tree.maxDepth && dec.decodeBit(models->interior[dc]) != 0;
      const NodeGuess guess = guessNode(tree, corners, d);
      const bool surface = dec.decodeBit(models->surface[split][guess.surfaceBucket][guess.signChange]) != 0;
      std::array<Neighbour, 3> nbs{};
      const int nbCount = level.gather(j, nbs);
      auto badPick = [&](const char* what) { fail("node " + std::to_string(node) + " picks a neighbour's " + what + " it does not have"); };
      std::uint32_t code = farCode;
      if (dec.decodeBit(models->errorFar[split][dc]) == 0) {
        std::array<std::uint16_t, 3> codes{};
        std::array<int, 3> from{};
        const int count = distinctCandidates(nbs, nbCount, [&](const CodedCell& c, std::uint16_t& v) { v = c.errorCode; return c.errorCode != farCode; }, codes, from);
        const int index = count > 0 ? decodeChoice(dec, models->errorSame[split][surface ? 1 : 0][candidateContext(count)], models->errorPick, count) : -1;
        if (index >= count) badPick("error code");
        if (index >= 0) {
          code = codes[index];
        } else {
          const std::uint32_t high = dec.decodeTree(models->errorHigh[split][surface ? 1 : 0][dc], 7);
          code = (high << 8) | (dec.decodeTree(models->errorLow[split][high & 7u], kErrorLowBits) << kErrorLowShift);
        }
        if (code > ContactTree::kMaxErrorCode) fail("errorCode[" + std::to_string(node) + "] is not a finite bound >= 0");
      }
      tree.errorCode.push_back(static_cast<std::uint16_t>(code));
      interiorFlags.push_back(split ? 1 : 0);
      surfaceFlags.push_back(surface ? 1 : 0);
      CodedCell self{.errorCode = static_cast<std::uint16_t>(code), .hasHalfSpace = surface};
      const Neighbour* planeNeighbour = nullptr;
      ContactHalfSpace hs{};
      if (surface) {
        std::array<std::array<std::int32_t, 2>, 3> normals{};
        std::array<int, 3> from{};
        const int count = distinctCandidates(nbs, nbCount, [](const CodedCell& c, std::array<std::int32_t, 2>& v) { v = c.normal; return c.hasHalfSpace; }, normals, from);
        const int index = count > 0 ? decodeChoice(dec, models->normalSame[split][candidateContext(count)], models->normalPick, count) : -1;
        if (index >= count) badPick("normal");
        if (index >= 0) {
          planeNeighbour = &nbs[from[index]];
          cell.ancestorNormal = normals[index];
        } else {
          const bool fromAncestor = dec.decodeBit(models->normalFromAncestor[split][cell.hasAncestorNormal]) != 0;
          if (fromAncestor && !cell.hasAncestorNormal) fail("node " + std::to_string(node) + " refers to an ancestor normal it does not have");
          const std::array<std::int32_t, 2> prior = fromAncestor ? cell.ancestorNormal : guess.normal;
          const std::int64_t a = prior[0] + dec.decodeInt(models->normal[split][0]);
          const std::int64_t b = prior[1] + dec.decodeInt(models->normal[split][1]);
          if (std::abs(a) > detail::kOctCodeMax || std::abs(b) > detail::kOctCodeMax) fail("half-space normal code of node " + std::to_string(node) + " is out of range");
          cell.ancestorNormal = {static_cast<std::int32_t>(a), static_cast<std::int32_t>(b)};
        }
        cell.hasAncestorNormal = true;
        self.normal = cell.ancestorNormal;
        hs.normal = detail::decodeOctNormal(cell.ancestorNormal[0], cell.ancestorNormal[1]);
      }
      if (split) {
        LatticeActivity activity;
        for (int l = 0; l < kLatticeSize; ++l) {
          if (kLatticeSlot[l] < 0) continue;
          const double prediction = detail::latticePrediction(corners, l);
          if (float known = 0.0f; l != 13 && level.sharedValue(j, l, tree.lattice, known) && dec.decodeBit(models->sharedSame[dc]) != 0) {
            lattice[l] = known;
            tree.lattice.push_back(known);
            activity.add(sharedUnits(known, prediction, step));
            continue;
          }
          const std::int64_t u = dec.decodeInt(models->lattice[latticeClass(l)][dc][activity.context()]);
          activity.add(u);
          const float v = detail::storedValue(prediction, u, step);
          if (!(std::abs(double(u)) < kMaxUnits) || !std::isfinite(v)) fail("lattice value of node " + std::to_string(node) + " is out of range");
          lattice[l] = v;
          tree.lattice.push_back(v);
        }
        for (int c = 0; c < 8; ++c) lattice[detail::parentCornerLattice(c)] = corners[c];
        level.pushChildren(j, cell, lattice, static_cast<std::int32_t>(tree.lattice.size() / kContactTreeLatticePerNode - 1), next);
      }
      if (surface) {
        const double anchor = detail::offsetPrediction(corners, split, lattice[13]);
        std::int64_t offsetUnits = 0, fitCode = 0;
        if (planeNeighbour) {
          offsetUnits = neighbourUnits(*planeNeighbour, hs.normal, h, anchor, hsStep) + dec.decodeInt(models->offsetFromNeighbour[split]);
          fitCode = planeNeighbour->cell.fitCode + dec.decodeInt(models->fitFromNeighbour[split]);
        } else {
          offsetUnits = dec.decodeInt(models->offset[split]);
          const std::uint32_t fitHigh = dec.decodeTree(models->fitHigh[split][dc], 7);
          fitCode = (fitHigh << 8) | (dec.decodeTree(models->fitLow[split][fitHigh & 7u], kFitLowBits) << kFitLowShift);
        }
        if (!(std::abs(double(offsetUnits)) < kMaxUnits) || fitCode < 0 || fitCode > 0x7f7f) fail("half-space of node " + std::to_string(node) + " is out of range");
        hs.offset = detail::storedValue(anchor, offsetUnits, hsStep);
        hs.fitError = detail::fitErrorFromCode(static_cast<std::uint16_t>(fitCode), h);
        if (!std::isfinite(hs.offset) || !std::isfinite(hs.fitError)) fail("half-space of node " + std::to_string(node) + " is not finite");
        tree.halfSpaces.push_back(hs);
        self.offset = hs.offset;
        self.fitCode = static_cast<std::uint16_t>(fitCode);
      }
      self.predicts = self.hasHalfSpace || code != farCode;
      level.record(j, self);
    }
    tree.levelOffsets.push_back(static_cast<std::uint32_t>(decoded));
    level.linkChildren(next);
    std::swap(level, next);
  }
  if (decoded != n) fail("the coded stream holds " + std::to_string(decoded) + " nodes, the header declares " + std::to_string(n));
  if (tree.depthCount() != depths) fail("the coded stream holds " + std::to_string(tree.depthCount()) + " depths, the header declares " + std::to_string(depths));
  if (dec.consumed() != coded.size()) fail(std::to_string(coded.size() - dec.consumed()) + " unused bytes at the end of the coded stream");
  tree.assignNodeBits(interiorFlags, surfaceFlags);
  tree.buildLookupGrid();
  tree.deriveFlatSurfaces();
  return tree;
}

}  // namespace clod
