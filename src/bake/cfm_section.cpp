#include "cfm_section.h"

#include <array>
#include <cstring>
#include <string>

#include "clod/byte_stream.h"
#include "clod/error.h"
#include "section_codec.h"

namespace clod::detail {

std::vector<std::byte> encodeCfmSection(const ClosestFeatureMap& map) {
  const ClosestFeatureMapData& data = map.data();
  // The 16-byte header is assembled first and appended in one go: element-wise appends to a
  // fresh vector trip a false -Wstringop-overflow in GCC 12's inlined vector::insert.
  std::array<std::byte, 16> header{};
  header[0] = static_cast<std::byte>(data.settings.scheme);
  header[1] = static_cast<std::byte>(data.settings.codec);
  const std::int32_t stacks[2] = {data.settings.rootStacks, data.settings.minStacks};
  std::memcpy(header.data() + 4, stacks, sizeof(stacks));  // little-endian (byte_stream.h asserts it)
  ByteWriter writer;
  writer.writeBytes(header);
  writeAlignedArray(writer, data.levelStacks);
  writeAlignedArray(writer, data.sphereOffset);
  writeAlignedArray(writer, data.sphereSingle);
  writeAlignedArray(writer, data.codes16);
  writeAlignedArray(writer, data.codes32);
  writeAlignedArray(writer, data.averageNormals);
  return writer.take();
}

ClosestFeatureMap decodeCfmSection(std::span<const std::byte> payload, const SphereTree& tree) {
  ByteReader reader(payload.data(), payload.size(), "bake section 'CFMP'");
  ClosestFeatureMapData data;
  data.settings.scheme = static_cast<SamplingScheme>(reader.read<std::uint8_t>());
  data.settings.codec = static_cast<NormalCodec>(reader.read<std::uint8_t>());
  if (reader.read<std::uint16_t>() != 0) reader.fail("reserved bytes after the codec are not 0");
  data.settings.rootStacks = reader.read<std::int32_t>();
  data.settings.minStacks = reader.read<std::int32_t>();
  if (reader.read<std::uint32_t>() != 0) reader.fail("reserved word after minStacks is not 0");
  data.levelStacks = readAlignedArray<std::uint32_t>(reader);
  data.sphereOffset = readAlignedArray<std::uint32_t>(reader);
  data.sphereSingle = readAlignedArray<std::uint8_t>(reader);
  data.codes16 = readAlignedArray<std::uint16_t>(reader);
  data.codes32 = readAlignedArray<std::uint32_t>(reader);
  data.averageNormals = readAlignedArray<float>(reader);
  if (!reader.atEnd()) reader.fail(std::to_string(reader.remaining()) + " unexpected bytes after averageNormals");
  try {
    return ClosestFeatureMap::fromData(std::move(data), tree);
  } catch (const Error& e) {
    // fromData names the field; for a file that is corruption, not a bad argument.
    reader.fail(e.what());
  }
}

}  // namespace clod::detail
