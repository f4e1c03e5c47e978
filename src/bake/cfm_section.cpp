#include "cfm_section.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <string>

#include "../contact_tree/range_coder.h"
#include "clod/bake.h"
#include "clod/byte_stream.h"
#include "clod/error.h"
#include "section_codec.h"

namespace clod::detail {

namespace {

// Version 2 payload: the 16-byte header of version 1, then u64 count + bytes of one range-coded
// stream holding, each as its count and then its elements: levelStacks, sphereSingle,
// sphereOffset, codes16, codes32, averageNormals. Lossless: every array decodes bit for bit, so
// ClosestFeatureMap::fromData checks exactly what the encoder was given.
//
// Neighbouring samples of a sphere mostly see the same feature, and a mesh has few distinct
// normals near any one place, so a stored code (and an average normal, as its three float bit
// patterns) is coded as its position in a move-to-front list of the 16 most recent distinct
// values: position 0 (the previous value) costs one adaptive decision, positions 1..15 five;
// a value not in the list is coded as differences of its two halves (the octahedral u and v)
// from the previous value, or for an average normal as its raw 96 bits.
constexpr int kRecentBits = 4;
constexpr std::size_t kRecent = std::size_t{1} << kRecentBits;

struct RecentModels {
  BitModel same[2], inList;
  BitModel index[kRecent];
  IntModel high, low;
};

struct CfmModels {
  IntModel count, levelStacks, single, offset;
  RecentModels codes, normals;
};

// Move-to-front list of recent values.
template <class T>
struct RecentList {
  std::array<T, kRecent> values{};
  std::size_t size = 0;
  int lastSame = 0;
  // Position of `v` or kRecent.
  std::size_t find(const T& v) const {
    for (std::size_t k = 0; k < size; ++k)
      if (values[k] == v) return k;
    return kRecent;
  }
  void toFront(std::size_t k, const T& v) {
    if (k == kRecent) k = std::min(size, kRecent - 1), size = std::min(size + 1, kRecent);
    for (std::size_t j = k; j > 0; --j) values[j] = values[j - 1];
    values[0] = v;
  }
};

// Codes value `v` (encoder) or fills it (decoder) against the list; `codeMiss` handles a value
// not in the list.
template <class Coder, class T, class Miss>
void codeRecent(Coder& coder, RecentModels& m, RecentList<T>& list, T& v, Miss&& codeMiss) {
  std::size_t k = coder.encoding ? list.find(v) : 0;
  if (list.size > 0) {
    const bool same = coder.bit(m.same[list.lastSame], k == 0);
    list.lastSame = same ? 1 : 0;
    if (same) {
      k = 0;
    } else if (list.size > 1 && coder.bit(m.inList, k != kRecent)) {
      if (!coder.encoding) k = 0;
      k = coder.tree(m.index, static_cast<std::uint32_t>(k));
      if (k == 0 || k >= list.size) coder.fail("a recent-value index " + std::to_string(k) + " outside the list of " + std::to_string(list.size));
    } else {
      k = kRecent;
    }
  } else {
    k = kRecent;
  }
  if (k == kRecent) codeMiss(list.size > 0 ? list.values[0] : T{});
  else v = list.values[k];
  list.toFront(k, v);
}

template <class Coder>
void codeHalves(Coder& coder, RecentModels& m, std::uint32_t& code, std::uint32_t previous, int halfBits) {
  const std::uint32_t mask = (1u << halfBits) - 1u;
  std::int64_t high = coder.integer(m.high, std::int64_t{code >> halfBits} - std::int64_t{previous >> halfBits});
  std::int64_t low = coder.integer(m.low, std::int64_t{code & mask} - std::int64_t{previous & mask});
  high += previous >> halfBits;
  low += previous & mask;
  if (high < 0 || high > mask || low < 0 || low > mask) coder.fail("a normal code outside " + std::to_string(2 * halfBits) + " bits");
  code = static_cast<std::uint32_t>(high << halfBits | low);
}

template <class Coder>
void codeCfm(Coder& coder, ClosestFeatureMapData& data) {
  auto models = std::make_unique<CfmModels>();
  CfmModels& m = *models;
  auto u32Array = [&](std::vector<std::uint32_t>& values, const char* name, IntModel& model, auto&& predict) {
    coder.count(m.count, values, name);
    for (std::size_t j = 0; j < values.size(); ++j) {
      std::int64_t v = coder.integer(model, std::int64_t{values[j]} - predict(j)) + predict(j);
      if (v < 0 || v > 0xffffffffll) coder.fail(std::string(name) + " value " + std::to_string(v) + " does not fit 32 bits");
      values[j] = static_cast<std::uint32_t>(v);
    }
  };
  u32Array(data.levelStacks, "levelStacks", m.levelStacks, [&](std::size_t j) { return j ? std::int64_t{data.levelStacks[j - 1]} : 0; });
  coder.count(m.count, data.sphereSingle, "sphereSingle");
  for (std::size_t i = 0; i < data.sphereSingle.size(); ++i) {
    const std::int64_t v = coder.integer(m.single, std::int64_t{data.sphereSingle[i]});
    if (v < 0 || v > 255) coder.fail("sphereSingle value " + std::to_string(v) + " does not fit 8 bits");
    data.sphereSingle[i] = static_cast<std::uint8_t>(v);
  }
  // Offsets: predicted by the previous sphere's offset plus its stride (1 for a single normal,
  // else the last full sphere's stride), so a well-formed map codes zeros.
  std::int64_t fullStride = 0;
  u32Array(data.sphereOffset, "sphereOffset", m.offset, [&](std::size_t j) -> std::int64_t {
    if (j == 0) return 0;
    if (j >= 2 && !(j - 2 < data.sphereSingle.size() && data.sphereSingle[j - 2])) {
      fullStride = std::int64_t{data.sphereOffset[j - 1]} - data.sphereOffset[j - 2];
    }
    const bool single = j - 1 < data.sphereSingle.size() && data.sphereSingle[j - 1];
    return std::int64_t{data.sphereOffset[j - 1]} + (single ? 1 : fullStride);
  });
  {
    coder.count(m.count, data.codes16, "codes16");
    RecentList<std::uint32_t> list;
    for (std::uint16_t& stored : data.codes16) {
      std::uint32_t v = stored;
      codeRecent(coder, m.codes, list, v, [&](std::uint32_t previous) { codeHalves(coder, m.codes, v, previous, 8); });
      stored = static_cast<std::uint16_t>(v);
    }
  }
  {
    coder.count(m.count, data.codes32, "codes32");
    RecentList<std::uint32_t> list;
    for (std::uint32_t& v : data.codes32) {
      codeRecent(coder, m.codes, list, v, [&](std::uint32_t previous) { codeHalves(coder, m.codes, v, previous, 16); });
    }
  }
  coder.count(m.count, data.averageNormals, "averageNormals");
  if (data.averageNormals.size() % 3 != 0) {  // only hand-made broken maps: raw floats
    for (float& f : data.averageNormals) coder.rawFloat(f);
    return;
  }
  RecentList<std::array<float, 3>> list;
  for (std::size_t i = 0; i < data.averageNormals.size(); i += 3) {
    std::array<float, 3> v{data.averageNormals[i], data.averageNormals[i + 1], data.averageNormals[i + 2]};
    codeRecent(coder, m.normals, list, v, [&](const std::array<float, 3>&) {
      for (float& f : v) coder.rawFloat(f);
    });
    std::copy(v.begin(), v.end(), data.averageNormals.begin() + static_cast<std::ptrdiff_t>(i));
  }
}

struct CfmEncoder {
  static constexpr bool encoding = true;
  RangeEncoder enc;
  template <class T>
  void count(IntModel& model, const std::vector<T>& values, const char*) {
    enc.encodeInt(model, static_cast<std::int64_t>(values.size()));
  }
  bool bit(BitModel& model, bool value) {
    enc.encodeBit(model, value ? 1u : 0u);
    return value;
  }
  std::uint32_t tree(std::span<BitModel> models, std::uint32_t value) {
    enc.encodeTree(models, kRecentBits, value);
    return value;
  }
  std::int64_t integer(IntModel& model, std::int64_t value) {
    enc.encodeInt(model, value);
    return value;
  }
  void rawFloat(float& f) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof(bits));
    enc.encodeDirect(bits, 32);
  }
  [[noreturn]] void fail(const std::string& what) { throw Error(ErrorCode::kInvalidArgument, "closest feature map: " + what); }
};

struct CfmDecoder {
  static constexpr bool encoding = false;
  RangeDecoder& dec;
  const ByteReader& reader;
  std::size_t streamBytes;
  template <class T>
  void count(IntModel& model, std::vector<T>& values, const char* name) {
    const std::int64_t n = dec.decodeInt(model);
    // Every element costs at least one adaptive decision of > 0.0109 bits (range_coder.h).
    if (n < 0 || static_cast<double>(n) > 800.0 * static_cast<double>(streamBytes) + 64.0) {
      fail(std::string(name) + " count " + std::to_string(n) + " is impossible for a coded stream of " + std::to_string(streamBytes) + " bytes");
    }
    values.resize(static_cast<std::size_t>(n));
  }
  bool bit(BitModel& model, bool) { return dec.decodeBit(model) != 0; }
  std::uint32_t tree(std::span<BitModel> models, std::uint32_t) { return dec.decodeTree(models, kRecentBits); }
  std::int64_t integer(IntModel& model, std::int64_t) { return dec.decodeInt(model); }
  void rawFloat(float& f) {
    const auto bits = static_cast<std::uint32_t>(dec.decodeDirect(32));
    std::memcpy(&f, &bits, sizeof(f));
  }
  [[noreturn]] void fail(const std::string& what) const { reader.fail(what); }
};

std::array<std::byte, 16> cfmHeader(const ClosestFeatureMapData& data) {
  // The 16-byte header is assembled first and appended in one go: element-wise appends to a
  // fresh vector trip a false -Wstringop-overflow in GCC 12's inlined vector::insert.
  std::array<std::byte, 16> header{};
  header[0] = static_cast<std::byte>(data.settings.scheme);
  header[1] = static_cast<std::byte>(data.settings.codec);
  const std::int32_t stacks[2] = {data.settings.rootStacks, data.settings.minStacks};
  std::memcpy(header.data() + 4, stacks, sizeof(stacks));  // little-endian (byte_stream.h asserts it)
  return header;
}

}  // namespace

std::vector<std::byte> encodeCfmSection(const ClosestFeatureMap& map) {
  ClosestFeatureMapData data = map.data();
  ByteWriter writer;
  writer.writeBytes(cfmHeader(data));
  CfmEncoder coder;
  codeCfm(coder, data);
  writer.writeArray(coder.enc.finish());
  return writer.take();
}

ClosestFeatureMap decodeCfmSection(std::span<const std::byte> payload, const SphereTree& tree, std::uint32_t version) {
  ByteReader reader(payload.data(), payload.size(), "bake section 'CFMP'");
  if (version < kBakeCfmVersion) {
    throw Error(ErrorCode::kBakeVersion, reader.context() + ": version " + std::to_string(version) +
                                             " (uncompressed arrays): re-bake the mesh");
  }
  ClosestFeatureMapData data;
  data.settings.scheme = static_cast<SamplingScheme>(reader.read<std::uint8_t>());
  data.settings.codec = static_cast<NormalCodec>(reader.read<std::uint8_t>());
  if (reader.read<std::uint16_t>() != 0) reader.fail("reserved bytes after the codec are not 0");
  data.settings.rootStacks = reader.read<std::int32_t>();
  data.settings.minStacks = reader.read<std::int32_t>();
  if (reader.read<std::uint32_t>() != 0) reader.fail("reserved word after minStacks is not 0");
  const std::vector<std::byte> coded = reader.readArray<std::byte>();
  if (!reader.atEnd()) reader.fail(std::to_string(reader.remaining()) + " unexpected bytes after the coded stream");
  RangeDecoder dec(coded, reader.context());
  CfmDecoder coder{dec, reader, coded.size()};
  codeCfm(coder, data);
  if (dec.consumed() != coded.size()) reader.fail(std::to_string(coded.size() - dec.consumed()) + " unused bytes at the end of the coded stream");
  try {
    return ClosestFeatureMap::fromData(std::move(data), tree);
  } catch (const Error& e) {
    // fromData names the field; for a file that is corruption, not a bad argument.
    reader.fail(e.what());
  }
}

}  // namespace clod::detail
