#include "sphere_tree_section.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "../contact_tree/range_coder.h"
#include "clod/bake.h"

namespace clod::detail {

namespace {

std::string str(std::uint64_t value) { return std::to_string(value); }

}  // namespace

void checkSphereTree(const SphereTree& tree, const SphereTreeSettings& settings, std::uint32_t triangleCount,
                     const Complaint& complain) {
  if (settings.method != SphereTreeMethod::kOctree && settings.method != SphereTreeMethod::kMedial) {
    complain("unknown sphere-tree method " + str(static_cast<std::uint32_t>(settings.method)));
  }
  if (settings.medialReduction != MedialReduction::kBest && settings.medialReduction != MedialReduction::kMergeBurst &&
      settings.medialReduction != MedialReduction::kKMeans) {
    complain("unknown medial reduction " + str(static_cast<std::uint32_t>(settings.medialReduction)));
  }
  const std::size_t n = tree.radius.size();
  if (n == 0) complain("the sphere-tree has no spheres");
  if (n >= kNoSphere) complain("sphere count " + str(n) + " does not fit 32 bits");
  auto checkSize = [&](const char* name, std::size_t size, std::size_t expected) {
    if (size != expected) complain(std::string(name) + " has " + str(size) + " entries, expected " + str(expected));
  };
  checkSize("centerX", tree.centerX.size(), n);
  checkSize("centerY", tree.centerY.size(), n);
  checkSize("centerZ", tree.centerZ.size(), n);
  checkSize("parent", tree.parent.size(), n);
  checkSize("firstChild", tree.firstChild.size(), n);
  checkSize("childCount", tree.childCount.size(), n);
  checkSize("triangleOffsets", tree.triangleOffsets.size(), n + 1);
  if (tree.triangleList.size() >= 0xffffffffull) complain("triangleList size " + str(tree.triangleList.size()) + " does not fit 32 bits");

  const auto& levels = tree.levelOffsets;
  if (levels.size() < 2) complain("levelOffsets has " + str(levels.size()) + " entries, needs at least 2 (a root level)");
  if (levels[0] != 0) complain("levelOffsets[0] is " + str(levels[0]) + ", not 0");
  if (levels[1] != 1) complain("levelOffsets[1] is " + str(levels[1]) + ": level 0 must hold exactly one root sphere");
  for (std::size_t l = 1; l < levels.size(); ++l) {
    if (levels[l] <= levels[l - 1]) {
      complain("levelOffsets not strictly increasing at level " + str(l - 1) + " (" + str(levels[l - 1]) + " then " + str(levels[l]) + ")");
    }
  }
  if (levels.back() != n) complain("levelOffsets ends at " + str(levels.back()) + ", not at the sphere count " + str(n));

  if (tree.triangleOffsets[0] != 0) complain("triangleOffsets[0] is " + str(tree.triangleOffsets[0]) + ", not 0");
  for (std::size_t i = 0; i < n; ++i) {
    if (tree.triangleOffsets[i + 1] < tree.triangleOffsets[i]) {
      complain("triangleOffsets decreases at sphere " + str(i) + " (" + str(tree.triangleOffsets[i]) + " then " +
               str(tree.triangleOffsets[i + 1]) + ")");
    }
  }
  if (tree.triangleOffsets[n] != tree.triangleList.size()) {
    complain("triangleOffsets ends at " + str(tree.triangleOffsets[n]) + ", not at the triangleList size " + str(tree.triangleList.size()));
  }
  for (std::size_t k = 0; k < tree.triangleList.size(); ++k) {
    if (tree.triangleList[k] >= triangleCount) {
      complain("triangleList[" + str(k) + "] = " + str(tree.triangleList[k]) + " >= mesh triangle count " + str(triangleCount));
    }
  }

  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(tree.centerX[i]) || !std::isfinite(tree.centerY[i]) || !std::isfinite(tree.centerZ[i])) {
      complain("sphere " + str(i) + " has a non-finite centre");
    }
    if (!std::isfinite(tree.radius[i]) || !(tree.radius[i] >= 0.0)) {
      complain("sphere " + str(i) + " has radius " + std::to_string(tree.radius[i]) + " (must be finite and >= 0)");
    }
  }

  // Parent and child links: every child range lies in the next level, every sphere's parent
  // lies in the previous level and its child range contains the sphere. Both directions are
  // checked, so traversal code may follow either without bounds checks.
  const std::size_t levelCount = levels.size() - 1;
  for (std::size_t l = 0; l < levelCount; ++l) {
    for (std::size_t i = levels[l]; i < levels[l + 1]; ++i) {
      const std::uint32_t p = tree.parent[i];
      if (l == 0) {
        if (p != kNoSphere) complain("root sphere 0 has parent " + str(p) + ", expected none");
      } else {
        if (p < levels[l - 1] || p >= levels[l]) {
          complain("sphere " + str(i) + " on level " + str(l) + " has parent " + str(p) + " outside level " + str(l - 1));
        }
        const std::uint64_t first = tree.firstChild[p];
        if (tree.childCount[p] == 0 || i < first || i >= first + tree.childCount[p]) {
          complain("sphere " + str(i) + " is not among the children of its parent " + str(p));
        }
      }
      const std::uint64_t count = tree.childCount[i];
      if (count == 0) continue;
      if (l + 1 == levelCount) complain("sphere " + str(i) + " on the deepest level has " + str(count) + " children");
      const std::uint64_t first = tree.firstChild[i];
      if (first < levels[l + 1] || first + count > levels[l + 2]) {
        complain("sphere " + str(i) + " has children [" + str(first) + ", " + str(first + count) + ") outside level " + str(l + 1));
      }
      for (std::uint64_t c = first; c < first + count; ++c) {
        if (tree.parent[c] != i) complain("sphere " + str(c) + " is a child of sphere " + str(i) + " but names parent " + str(tree.parent[c]));
      }
    }
  }
}

// ---- Version 2 payload: sphere values quantised conservatively, everything range-coded. ----
//
// Layout: the 16-byte settings header of version 1, then u64 count + bytes of one range-coded
// stream (range_coder.h). The stream holds, in order: the count and the elements of
// levelOffsets, childCount, firstChild, parent, triangleOffsets and triangleList (each element
// as a signed integer difference from a prediction both sides can make from what is already
// decoded), then the sphere values. Structure arrays are lossless for any u32 values, so the
// decoder's checks (checkSphereTree) see exactly what the encoder was given.
//
// Sphere values: the root (and any sphere whose parent does not precede it) is stored as four
// raw f64. Any other sphere i with parent p is, unless an escape bit says "raw", put on a grid
// of step h = 2^(ilogb(r_p) - kSphereGridBits) (r_p: p's decoded radius): its centre rounds to
// the nearest grid point c' and its radius becomes r' = h * ceil((r + |c' - c|) / h), so the
// decoded ball contains the original one (|x - c'| <= |x - c| + |c - c'| <= r + |c - c'| <= r').
// Decoded values are grid points, so encoding them again gives the same integers: the codec is
// idempotent (encodeBake(decodeBake(f)) == f) although the first encoding is lossy.

namespace {

// |value| below this many grid steps keeps k * h exact in a double (53-bit significand).
constexpr double kMaxGridIndex = 0x1p50;

struct SphereModels {
  IntModel count, levelOffsets, childCount[8], firstChild, leafFirstChild, parent, triangleOffsets[8], triangleFirst,
      triangleNext, centre, radius;
  BitModel escape;
};

std::uint64_t doubleBits(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof(bits));
  return bits;
}
double bitsDouble(std::uint64_t bits) {
  double v;
  std::memcpy(&v, &bits, sizeof(v));
  return v;
}

void encodeRaw(RangeEncoder& enc, double v) {
  const std::uint64_t bits = doubleBits(v);
  enc.encodeDirect(bits >> 32, 32);
  enc.encodeDirect(bits & 0xffffffffu, 32);
}
double decodeRaw(RangeDecoder& dec) {
  const std::uint64_t high = dec.decodeDirect(32);
  return bitsDouble((high << 32) | dec.decodeDirect(32));
}

// Level of each sphere from levelOffsets (clamped; a broken array gives level 7 to the rest,
// the checks reject it later). Only picks coding contexts.
std::vector<std::uint8_t> sphereLevels(const std::vector<std::uint32_t>& levelOffsets, std::size_t n) {
  std::vector<std::uint8_t> level(n, 7);
  for (std::size_t l = 0; l + 1 < levelOffsets.size(); ++l) {
    const std::size_t begin = std::min<std::size_t>(levelOffsets[l], n), end = std::min<std::size_t>(levelOffsets[l + 1], n);
    for (std::size_t i = begin; i < end; ++i) level[i] = static_cast<std::uint8_t>(std::min<std::size_t>(l, 7));
  }
  return level;
}

// The parent each sphere would have if the child ranges tile the levels in sphere order (what
// the builders write); O(n) for any input.
std::vector<std::uint32_t> derivedParents(const SphereTree& tree, std::size_t n) {
  std::vector<std::uint32_t> parent(n, kNoSphere);
  std::uint64_t cursor = 1;
  const std::size_t m = std::min(tree.firstChild.size(), tree.childCount.size());
  for (std::size_t i = 0; i < m; ++i) {
    const std::uint64_t first = std::max<std::uint64_t>(tree.firstChild[i], cursor);
    const std::uint64_t end = std::min<std::uint64_t>(std::uint64_t{tree.firstChild[i]} + tree.childCount[i], n);
    for (std::uint64_t k = first; k < end; ++k) parent[k] = static_cast<std::uint32_t>(i);
    cursor = std::max(cursor, end);
  }
  return parent;
}

// The grid a sphere's values are coded on, or none (then they are stored raw).
struct SphereGrid {
  bool ok = false;
  double step = 0.0;
  double predicted[3] = {};  // parent centre in grid steps (rounded)
};

SphereGrid sphereGrid(const SphereTree& tree, std::size_t i) {
  SphereGrid grid;
  if (i == 0 || i >= tree.parent.size()) return grid;
  const std::uint32_t p = tree.parent[i];
  if (p >= i) return grid;
  const double rp = tree.radius[p];
  if (!(std::isfinite(rp) && rp > 0.0)) return grid;
  grid.step = std::ldexp(1.0, std::max(std::ilogb(rp) - kSphereGridBits, -1000));
  const double pc[3] = {tree.centerX[p], tree.centerY[p], tree.centerZ[p]};
  for (int a = 0; a < 3; ++a) {
    const double q = pc[a] / grid.step;
    if (!(std::abs(q) < kMaxGridIndex)) return grid;
    grid.predicted[a] = std::nearbyint(q);
  }
  grid.ok = true;
  return grid;
}

// Integer prediction of a sphere's radius in grid steps: its previous sibling's radius if that
// sphere shares the parent, else half the parent's.
std::int64_t predictedRadius(const SphereTree& tree, std::size_t i, double step) {
  const std::uint32_t p = tree.parent[i];
  const double r = (i > 1 && tree.parent[i - 1] == p) ? tree.radius[i - 1] : 0.5 * tree.radius[p];
  const double q = r / step;
  return std::abs(q) < kMaxGridIndex ? static_cast<std::int64_t>(std::nearbyint(q)) : 0;
}

std::size_t decodeCount(RangeDecoder& dec, IntModel& countModel, std::size_t streamBytes, const ByteReader& reader,
                        const char* name) {
  const std::int64_t count = dec.decodeInt(countModel);
  // Every element costs at least one adaptive decision of > 0.0109 bits (range_coder.h), so a
  // stream of B bytes holds fewer than 8 B / 0.0109 < 800 B elements per array.
  if (count < 0 || static_cast<double>(count) > 800.0 * static_cast<double>(streamBytes) + 64.0) {
    reader.fail(std::string(name) + " count " + std::to_string(count) + " is impossible for a coded stream of " +
                std::to_string(streamBytes) + " bytes");
  }
  return static_cast<std::size_t>(count);
}

// Both directions share one walk over the arrays, so encoder and decoder cannot disagree on the
// order or the predictions. `Coder` is a small adaptor around RangeEncoder / RangeDecoder.
template <class Coder>
void codeSphereTree(Coder& coder, SphereTree& tree) {
  auto models = std::make_unique<SphereModels>();
  SphereModels& m = *models;
  auto codeU32Array = [&](const char* name, std::vector<std::uint32_t>& values, auto&& predict, auto&& model) {
    coder.count(m.count, values, name);
    for (std::size_t j = 0; j < values.size(); ++j) coder.u32(model(j), values[j], predict(j));
  };
  codeU32Array("levelOffsets", tree.levelOffsets, [&](std::size_t j) { return j ? std::int64_t{tree.levelOffsets[j - 1]} : 0; },
               [&](std::size_t) -> IntModel& { return m.levelOffsets; });
  coder.count(m.count, tree.childCount, "childCount");
  const std::vector<std::uint8_t> level = sphereLevels(tree.levelOffsets, tree.childCount.size());
  for (std::size_t i = 0; i < tree.childCount.size(); ++i) {
    const bool sameLevel = i > 0 && level[i - 1] == level[i];
    coder.u32(m.childCount[level[i]], tree.childCount[i], sameLevel ? std::int64_t{tree.childCount[i - 1]} : 0);
  }
  coder.count(m.count, tree.firstChild, "firstChild");
  std::int64_t nextChild = tree.levelOffsets.size() > 1 ? tree.levelOffsets[1] : 1, lastLeaf = 0;
  for (std::size_t i = 0; i < tree.firstChild.size(); ++i) {
    const bool leaf = i >= tree.childCount.size() || tree.childCount[i] == 0;
    coder.u32(leaf ? m.leafFirstChild : m.firstChild, tree.firstChild[i], leaf ? lastLeaf : nextChild);
    if (leaf) lastLeaf = tree.firstChild[i];
    else nextChild = std::int64_t{tree.firstChild[i]} + tree.childCount[i];
  }
  coder.count(m.count, tree.parent, "parent");
  {
    const std::vector<std::uint32_t> derived = derivedParents(tree, tree.parent.size());
    for (std::size_t i = 0; i < tree.parent.size(); ++i) coder.u32(m.parent, tree.parent[i], std::int64_t{derived[i]});
  }
  coder.count(m.count, tree.triangleOffsets, "triangleOffsets");
  for (std::size_t i = 0; i < tree.triangleOffsets.size(); ++i) {
    const std::uint8_t ctx = i < level.size() ? level[i] : 7;
    coder.u32(m.triangleOffsets[ctx], tree.triangleOffsets[i], i ? std::int64_t{tree.triangleOffsets[i - 1]} : 0);
  }
  coder.count(m.count, tree.triangleList, "triangleList");
  {
    // First entry of a sphere's list: predicted by the previous sphere's first entry; the rest:
    // by the entry before plus one (lists of consecutive triangles cost one decision each).
    std::vector<std::uint8_t> starts(tree.triangleList.size() + 1, 0);
    for (std::uint32_t offset : tree.triangleOffsets) starts[std::min<std::size_t>(offset, tree.triangleList.size())] = 1;
    std::int64_t lastFirst = 0;
    for (std::size_t j = 0; j < tree.triangleList.size(); ++j) {
      if (starts[j] || j == 0) {
        coder.u32(m.triangleFirst, tree.triangleList[j], lastFirst);
        lastFirst = tree.triangleList[j];
      } else {
        coder.u32(m.triangleNext, tree.triangleList[j], std::int64_t{tree.triangleList[j - 1]} + 1);
      }
    }
  }

  // Sphere values.
  coder.count(m.count, tree.centerX, "centerX");
  coder.count(m.count, tree.centerY, "centerY");
  coder.count(m.count, tree.centerZ, "centerZ");
  coder.count(m.count, tree.radius, "radius");
  const std::size_t n = tree.radius.size();
  const bool gridded = tree.centerX.size() == n && tree.centerY.size() == n && tree.centerZ.size() == n && tree.parent.size() == n;
  if (!gridded) {  // only hand-made broken trees: every value raw, the checks will name the culprit
    for (auto* values : {&tree.centerX, &tree.centerY, &tree.centerZ, &tree.radius})
      for (double& v : *values) coder.raw(v);
    return;
  }
  double* centre[3] = {tree.centerX.data(), tree.centerY.data(), tree.centerZ.data()};
  for (std::size_t i = 0; i < n; ++i) {
    const SphereGrid grid = sphereGrid(tree, i);
    if (!grid.ok || coder.escape(m.escape, tree, i, grid)) {
      for (int a = 0; a < 3; ++a) coder.raw(centre[a][i]);
      coder.raw(tree.radius[i]);
      continue;
    }
    coder.gridSphere(m.centre, m.radius, tree, i, grid, predictedRadius(tree, i, grid.step));
  }
}

struct SphereEncoder {
  RangeEncoder enc;
  void count(IntModel& model, const auto& values, const char*) { enc.encodeInt(model, static_cast<std::int64_t>(values.size())); }
  void u32(IntModel& model, std::uint32_t value, std::int64_t predicted) { enc.encodeInt(model, std::int64_t{value} - predicted); }
  void raw(double v) { encodeRaw(enc, v); }
  // The encoder quantises in place (the walk reads decoded values of earlier spheres, exactly
  // as the decoder will); the caller passes a copy.
  bool escape(BitModel& model, SphereTree& tree, std::size_t i, const SphereGrid& grid) {
    const double c[3] = {tree.centerX[i], tree.centerY[i], tree.centerZ[i]};
    const double r = tree.radius[i];
    bool fits = std::isfinite(r) && r >= 0.0;
    double k[3] = {};
    double shift2 = 0.0;
    for (int a = 0; a < 3 && fits; ++a) {
      const double q = c[a] / grid.step;
      fits = std::abs(q) < kMaxGridIndex;
      if (!fits) break;
      k[a] = std::nearbyint(q);
      const double d = k[a] * grid.step - c[a];
      shift2 += d * d;
    }
    double kr = 0.0;
    if (fits) {
      // Rounded up twice: sqrt and the sum may each round down by half an ulp.
      const double shift = shift2 > 0.0 ? std::nextafter(std::sqrt(shift2) * (1.0 + 0x1p-50), HUGE_VAL) : 0.0;
      const double grown = shift > 0.0 ? std::nextafter(r + shift, HUGE_VAL) : r;
      kr = std::ceil(grown / grid.step);
      fits = kr < kMaxGridIndex;
    }
    enc.encodeBit(model, fits ? 0u : 1u);
    if (!fits) return true;
    for (int a = 0; a < 3; ++a) pending_[a] = k[a];
    pending_[3] = kr;
    return false;
  }
  void gridSphere(IntModel& centreModel, IntModel& radiusModel, SphereTree& tree, std::size_t i, const SphereGrid& grid,
                  std::int64_t radiusPrediction) {
    double* centre[3] = {tree.centerX.data(), tree.centerY.data(), tree.centerZ.data()};
    for (int a = 0; a < 3; ++a) {
      enc.encodeInt(centreModel, static_cast<std::int64_t>(pending_[a] - grid.predicted[a]));
      centre[a][i] = pending_[a] * grid.step;
    }
    enc.encodeInt(radiusModel, static_cast<std::int64_t>(pending_[3]) - radiusPrediction);
    tree.radius[i] = pending_[3] * grid.step;
  }
  double pending_[4] = {};
};

struct SphereDecoder {
  RangeDecoder& dec;
  const ByteReader& reader;
  std::size_t streamBytes;
  template <class T>
  void count(IntModel& model, std::vector<T>& values, const char* name) {
    values.resize(decodeCount(dec, model, streamBytes, reader, name));
  }
  void u32(IntModel& model, std::uint32_t& value, std::int64_t predicted) {
    const std::int64_t v = predicted + dec.decodeInt(model);
    if (v < 0 || v > 0xffffffffll) reader.fail("a coded index " + std::to_string(v) + " does not fit 32 bits");
    value = static_cast<std::uint32_t>(v);
  }
  void raw(double& v) { v = decodeRaw(dec); }
  bool escape(BitModel& model, SphereTree&, std::size_t, const SphereGrid&) { return dec.decodeBit(model) != 0; }
  void gridSphere(IntModel& centreModel, IntModel& radiusModel, SphereTree& tree, std::size_t i, const SphereGrid& grid,
                  std::int64_t radiusPrediction) {
    double* centre[3] = {tree.centerX.data(), tree.centerY.data(), tree.centerZ.data()};
    for (int a = 0; a < 3; ++a) centre[a][i] = (grid.predicted[a] + static_cast<double>(dec.decodeInt(centreModel))) * grid.step;
    tree.radius[i] = static_cast<double>(radiusPrediction + dec.decodeInt(radiusModel)) * grid.step;
  }
};

void writeSettings(ByteWriter& writer, const SphereTreeSettings& settings) {
  writer.write<std::uint8_t>(static_cast<std::uint8_t>(settings.method));
  // Was a reserved 0 byte before the reduction was stored; 0 is kBest, the default of those builds.
  writer.write<std::uint8_t>(static_cast<std::uint8_t>(settings.medialReduction));
  writer.write<std::uint16_t>(0);
  writer.write<std::uint32_t>(settings.branching);
  writer.write<std::uint32_t>(settings.depth);
  writer.write<std::uint32_t>(settings.medialSamples);
}

}  // namespace

std::vector<std::byte> encodeSphereTreeSection(const SphereTree& tree, const SphereTreeSettings& settings) {
  ByteWriter writer;
  writeSettings(writer, settings);
  SphereTree copy = tree;
  SphereEncoder coder;
  codeSphereTree(coder, copy);
  writer.writeArray(coder.enc.finish());
  return writer.take();
}

SphereTree quantisedSphereTree(const SphereTree& tree) {
  SphereTree copy = tree;
  SphereEncoder coder;
  codeSphereTree(coder, copy);
  return copy;
}

DecodedSphereTreeSection decodeSphereTreeSection(std::span<const std::byte> payload, std::uint32_t triangleCount,
                                                 std::uint32_t version) {
  ByteReader reader(payload.data(), payload.size(), "bake section 'STRE'");
  if (version < kBakeSphereTreeVersion) {
    throw Error(ErrorCode::kBakeVersion, reader.context() + ": version " + std::to_string(version) +
                                             " (uncompressed f64 spheres): re-bake the mesh");
  }
  DecodedSphereTreeSection decoded;
  decoded.settings.method = static_cast<SphereTreeMethod>(reader.read<std::uint8_t>());
  decoded.settings.medialReduction = static_cast<MedialReduction>(reader.read<std::uint8_t>());
  if (reader.read<std::uint16_t>() != 0) reader.fail("reserved bytes after the medial reduction are not 0");
  decoded.settings.branching = reader.read<std::uint32_t>();
  decoded.settings.depth = reader.read<std::uint32_t>();
  decoded.settings.medialSamples = reader.read<std::uint32_t>();
  const std::vector<std::byte> coded = reader.readArray<std::byte>();
  if (!reader.atEnd()) reader.fail(std::to_string(reader.remaining()) + " unexpected bytes after the coded stream");
  RangeDecoder dec(coded, reader.context());
  SphereDecoder coder{dec, reader, coded.size()};
  codeSphereTree(coder, decoded.tree);
  if (dec.consumed() != coded.size()) reader.fail(std::to_string(coded.size() - dec.consumed()) + " unused bytes at the end of the coded stream");
  checkSphereTree(decoded.tree, decoded.settings, triangleCount, Complaint{ErrorCode::kBakeCorrupt, reader.context()});
  return decoded;
}

}  // namespace clod::detail
