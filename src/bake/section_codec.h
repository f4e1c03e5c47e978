#pragma once
// Small helpers shared by the section codecs of the bake file (not public API).

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "clod/byte_stream.h"
#include "clod/error.h"

namespace clod::detail {

/// Writes an array (u64 count + elements) followed by zero padding to 8 bytes, so the next
/// array starts 8-aligned within the section.
template <class T>
void writeAlignedArray(ByteWriter& writer, const std::vector<T>& values) {
  writer.writeArray(values);
  writer.align(8);
}

/// Consumes padding to 8 bytes and insists it is zero: the writer always writes zeros, and
/// accepting anything else would let two different files decode to the same contents.
inline void skipZeroPadding(ByteReader& reader) {
  while (reader.offset() % 8 != 0) {
    if (reader.read<std::uint8_t>() != 0) reader.fail("non-zero padding byte at offset " + std::to_string(reader.offset() - 1));
  }
}

template <class T>
std::vector<T> readAlignedArray(ByteReader& reader) {
  std::vector<T> values = reader.readArray<T>();
  skipZeroPadding(reader);
  return values;
}

/// Throws Error(code, context + ": " + what). Lets one checker serve both the encoder
/// (kInvalidArgument: the caller handed us bad contents) and the decoder (kBakeCorrupt).
struct Complaint {
  ErrorCode code;
  std::string context;
  [[noreturn]] void operator()(const std::string& what) const { throw Error(code, context + ": " + what); }
};

}  // namespace clod::detail
