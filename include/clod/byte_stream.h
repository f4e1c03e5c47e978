#pragma once
// Explicit little-endian binary encoding, shared by every section of the bake file.
// ByteWriter appends; ByteReader consumes with bounds checks, so a truncated or corrupted
// buffer becomes a clod::Error (kBakeTruncated / kBakeCorrupt), never an out-of-bounds read.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "clod/error.h"

namespace clod {

static_assert(std::endian::native == std::endian::little,
              "clod's bake files are little-endian; a big-endian port must byte-swap in ByteWriter/ByteReader");

class ByteWriter {
public:
  /// Appends one arithmetic value in little-endian order.
  template <class T>
    requires std::is_arithmetic_v<T>
  void write(T value) {
    const auto* bytes = reinterpret_cast<const std::byte*>(&value);
    buffer_.insert(buffer_.end(), bytes, bytes + sizeof(T));
  }
  /// Appends a u64 element count followed by the elements.
  template <class T>
    requires std::is_trivially_copyable_v<T>
  void writeArray(const std::vector<T>& values) {
    write<std::uint64_t>(values.size());
    const auto* bytes = reinterpret_cast<const std::byte*>(values.data());
    buffer_.insert(buffer_.end(), bytes, bytes + values.size() * sizeof(T));
  }
  void writeString(std::string_view text) {
    write<std::uint64_t>(text.size());
    const auto* bytes = reinterpret_cast<const std::byte*>(text.data());
    buffer_.insert(buffer_.end(), bytes, bytes + text.size());
  }
  /// Appends raw bytes as they are (no count prefix).
  void writeBytes(std::span<const std::byte> bytes) { buffer_.insert(buffer_.end(), bytes.begin(), bytes.end()); }
  /// Pads with zero bytes to a multiple of `alignment`.
  void align(std::size_t alignment) {
    while (buffer_.size() % alignment != 0) buffer_.push_back(std::byte{0});
  }

  std::size_t size() const { return buffer_.size(); }
  const std::vector<std::byte>& bytes() const { return buffer_; }
  std::vector<std::byte> take() { return std::move(buffer_); }

private:
  std::vector<std::byte> buffer_;
};

class ByteReader {
public:
  /// `context` names what is being read (e.g. "sphere-tree section"), for error messages.
  ByteReader(const std::byte* data, std::size_t size, std::string context)
      : data_(data), size_(size), context_(std::move(context)) {}

  template <class T>
    requires std::is_arithmetic_v<T>
  T read() {
    require(sizeof(T));
    T value;
    std::memcpy(&value, data_ + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  /// Reads a u64 count and that many elements. Rejects counts that exceed the remaining bytes
  /// before allocating, so a corrupted count cannot trigger a huge allocation.
  template <class T>
    requires std::is_trivially_copyable_v<T>
  std::vector<T> readArray() {
    const auto count = read<std::uint64_t>();
    if (count > remaining() / sizeof(T)) {
      throw Error(ErrorCode::kBakeTruncated, context_ + ": array of " + std::to_string(count) +
                                                 " elements exceeds the " + std::to_string(remaining()) +
                                                 " bytes left");
    }
    std::vector<T> values(count);
    if (count) std::memcpy(values.data(), data_ + offset_, count * sizeof(T));
    offset_ += count * sizeof(T);
    return values;
  }
  std::string readString() {
    const auto count = read<std::uint64_t>();
    require(count);
    std::string text(reinterpret_cast<const char*>(data_ + offset_), count);
    offset_ += count;
    return text;
  }
  /// Consumes `count` raw bytes and returns a view of them (valid as long as the buffer is).
  std::span<const std::byte> readBytes(std::uint64_t count) {
    require(count);
    std::span<const std::byte> view(data_ + offset_, static_cast<std::size_t>(count));
    offset_ += static_cast<std::size_t>(count);
    return view;
  }
  void skipAlignment(std::size_t alignment) {
    const std::size_t pad = (alignment - offset_ % alignment) % alignment;
    require(pad);
    offset_ += pad;
  }

  std::size_t offset() const { return offset_; }
  std::size_t remaining() const { return size_ - offset_; }
  bool atEnd() const { return offset_ == size_; }
  const std::string& context() const { return context_; }

  /// Throws kBakeCorrupt with the context prepended; for consistency checks by decoders.
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(ErrorCode::kBakeCorrupt, context_ + ": " + what);
  }

private:
  void require(std::uint64_t bytes) const {
    if (bytes > remaining()) {
      throw Error(ErrorCode::kBakeTruncated, context_ + ": needs " + std::to_string(bytes) +
                                                 " more bytes at offset " + std::to_string(offset_) +
                                                 " but only " + std::to_string(remaining()) + " remain");
    }
  }

  const std::byte* data_;
  std::size_t size_;
  std::size_t offset_ = 0;
  std::string context_;
};

}  // namespace clod
