#include "clod/bake_file.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack: no allocation, no failure path
#include <xxhash.h>

#include "clod/byte_stream.h"
#include "clod/error.h"

namespace clod {

namespace {

constexpr char kMagic[8] = {'C', 'L', 'O', 'D', 'B', 'A', 'K', 'E'};
// Bytes of the header the header checksum covers (everything before the checksum field).
constexpr std::size_t kHeaderHashedBytes = 40;

std::uint64_t alignUp(std::uint64_t value) {
  return (value + kBakeSectionAlignment - 1) / kBakeSectionAlignment * kBakeSectionAlignment;
}

std::string hex(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(value));
  return text;
}

template <class T>
T loadLittleEndian(const std::byte* data) {
  T value;
  std::memcpy(&value, data, sizeof(T));  // byte_stream.h asserts a little-endian host
  return value;
}

// Header checksum over [0, 40) and the table, as if they were one contiguous buffer.
std::uint64_t headerChecksum(const std::byte* header, const std::byte* table, std::size_t tableBytes) {
  XXH3_state_t state;
  XXH3_INITSTATE(&state);
  XXH3_64bits_reset(&state);
  XXH3_64bits_update(&state, header, kHeaderHashedBytes);
  XXH3_64bits_update(&state, table, tableBytes);
  return XXH3_64bits_digest(&state);
}

[[noreturn]] void fail(ErrorCode code, const std::string& what) { throw Error(code, "bake file: " + what); }

}  // namespace

std::string bakeSectionTagName(BakeSectionTag tag) {
  std::string name;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<unsigned char>((tag >> (8 * i)) & 0xffu);
    if (c >= 0x20 && c < 0x7f) {
      name += static_cast<char>(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", c);
      name += escaped;
    }
  }
  return name;
}

std::uint64_t bakeChecksum(std::span<const std::byte> bytes) noexcept {
  return XXH3_64bits(bytes.data(), bytes.size());
}

void BakeFileWriter::addSection(BakeSectionTag tag, std::uint32_t version, std::vector<std::byte> payload) {
  CLOD_ASSERT(version >= 1);
  CLOD_ASSERT(std::none_of(sections_.begin(), sections_.end(), [&](const Pending& s) { return s.tag == tag; }));
  CLOD_ASSERT(sections_.size() < kBakeMaxSections);
  sections_.push_back({tag, version, std::move(payload)});
}

std::vector<std::byte> BakeFileWriter::encode() const {
  const auto count = static_cast<std::uint32_t>(sections_.size());
  std::vector<BakeSectionEntry> entries(count);
  std::uint64_t cursor = alignUp(kBakeHeaderSize + std::uint64_t{count} * kBakeTableEntrySize);
  for (std::uint32_t i = 0; i < count; ++i) {
    const Pending& s = sections_[i];
    entries[i] = {s.tag, s.version, cursor, s.payload.size(), bakeChecksum(s.payload)};
    cursor = alignUp(cursor + s.payload.size());
  }
  const std::uint64_t fileSize = cursor;

  ByteWriter header;
  for (char c : kMagic) header.write(static_cast<std::uint8_t>(c));
  header.write<std::uint32_t>(kBakeFormatVersion);
  header.write<std::uint32_t>(0);  // flags
  header.write<std::uint32_t>(count);
  header.write<std::uint32_t>(kBakeHeaderSize);
  header.write<std::uint64_t>(fileSize);
  header.write<std::uint64_t>(0);  // reserved
  ByteWriter table;
  for (const BakeSectionEntry& e : entries) {
    table.write(e.tag);
    table.write(e.version);
    table.write(e.offset);
    table.write(e.size);
    table.write(e.checksum);
  }
  CLOD_ASSERT(header.size() == kHeaderHashedBytes);
  header.write<std::uint64_t>(headerChecksum(header.bytes().data(), table.bytes().data(), table.size()));
  CLOD_ASSERT(header.size() == kBakeHeaderSize);

  // Zero-filled, so the padding between parts is zero as the format requires.
  std::vector<std::byte> file(fileSize, std::byte{0});
  std::memcpy(file.data(), header.bytes().data(), header.size());
  if (table.size()) std::memcpy(file.data() + kBakeHeaderSize, table.bytes().data(), table.size());
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!sections_[i].payload.empty()) {
      std::memcpy(file.data() + entries[i].offset, sections_[i].payload.data(), sections_[i].payload.size());
    }
  }
  return file;
}

std::size_t checkBakeFileStart(std::span<const std::byte> start, std::uint64_t fileBytes) {
  const std::byte* data = start.data();
  const std::uint64_t size = fileBytes;
  // Whatever the caller holds of the file, never more than the file.
  const std::uint64_t have = std::min<std::uint64_t>(start.size(), fileBytes);
  const std::uint64_t headerBytes = std::min<std::uint64_t>(size, kBakeHeaderSize);
  if (have < headerBytes) return std::size_t(headerBytes);

  // The magic first: a file that is not a bake at all should say so, even when short.
  const std::size_t magicBytes = std::min(size, sizeof(kMagic));
  if (magicBytes > 0 && std::memcmp(data, kMagic, magicBytes) != 0) {
    fail(ErrorCode::kBakeCorrupt, "not a clod bake file (magic \"CLODBAKE\" missing)");
  }
  if (size < kBakeHeaderSize) {
    fail(ErrorCode::kBakeTruncated, "file has " + std::to_string(size) + " bytes, shorter than the " +
                                        std::to_string(kBakeHeaderSize) + "-byte header");
  }
  // The version decides the layout of everything after it, so it is checked before the
  // header checksum (a newer format may checksum differently).
  const auto formatVersion = loadLittleEndian<std::uint32_t>(data + 8);
  if (formatVersion == 0) fail(ErrorCode::kBakeCorrupt, "format version 0 is invalid");
  if (formatVersion > kBakeFormatVersion) {
    fail(ErrorCode::kBakeVersion, "format version " + std::to_string(formatVersion) +
                                      " is newer than the newest this build reads (" +
                                      std::to_string(kBakeFormatVersion) + ")");
  }
  const auto flags = loadLittleEndian<std::uint32_t>(data + 12);
  const auto count = loadLittleEndian<std::uint32_t>(data + 16);
  const auto headerSize = loadLittleEndian<std::uint32_t>(data + 20);
  const auto fileSize = loadLittleEndian<std::uint64_t>(data + 24);
  const auto reserved = loadLittleEndian<std::uint64_t>(data + 32);
  const auto storedHeaderHash = loadLittleEndian<std::uint64_t>(data + 40);

  // The count bounds how much we read next; check it before trusting the table.
  if (count > kBakeMaxSections) {
    fail(ErrorCode::kBakeCorrupt, "section count " + std::to_string(count) + " exceeds the maximum " +
                                      std::to_string(kBakeMaxSections));
  }
  if (headerSize != kBakeHeaderSize) {
    fail(ErrorCode::kBakeCorrupt, "header size " + std::to_string(headerSize) + " != " +
                                      std::to_string(kBakeHeaderSize) + " for format version 1");
  }
  const std::size_t tableBytes = std::size_t{count} * kBakeTableEntrySize;
  if (size < kBakeHeaderSize + tableBytes) {
    fail(ErrorCode::kBakeTruncated, "file has " + std::to_string(size) + " bytes, but its section table of " +
                                        std::to_string(count) + " entries ends at byte " +
                                        std::to_string(kBakeHeaderSize + tableBytes));
  }
  if (have < kBakeHeaderSize + tableBytes) return kBakeHeaderSize + tableBytes;
  const std::uint64_t computedHeaderHash = headerChecksum(data, data + kBakeHeaderSize, tableBytes);
  if (computedHeaderHash != storedHeaderHash) {
    fail(ErrorCode::kBakeCorrupt, "header checksum mismatch (stored " + hex(storedHeaderHash) + ", computed " +
                                      hex(computedHeaderHash) + ")");
  }
  // From here the header and table are what the writer wrote; what remains is a file cut
  // short or extended, or a writer that broke the rules.
  if (flags != 0) fail(ErrorCode::kBakeCorrupt, "flags " + hex(flags) + " set, but version 1 defines none");
  if (reserved != 0) fail(ErrorCode::kBakeCorrupt, "reserved header field is " + hex(reserved) + ", not 0");
  if (fileSize > size) {
    fail(ErrorCode::kBakeTruncated, "file has " + std::to_string(size) + " bytes, but its header declares " +
                                        std::to_string(fileSize));
  }
  if (fileSize < size) {
    fail(ErrorCode::kBakeCorrupt, "file has " + std::to_string(size) + " bytes, more than the " +
                                      std::to_string(fileSize) + " its header declares");
  }
  return 0;
}

BakeFileReader::BakeFileReader(std::span<const std::byte> bytes) : bytes_(bytes) {
  const std::byte* data = bytes.data();
  const std::size_t size = bytes.size();
  // The whole file is here, so the start check always has what it needs.
  checkBakeFileStart(bytes, size);
  formatVersion_ = loadLittleEndian<std::uint32_t>(data + 8);
  const auto count = loadLittleEndian<std::uint32_t>(data + 16);
  const auto fileSize = loadLittleEndian<std::uint64_t>(data + 24);
  const std::size_t tableBytes = std::size_t{count} * kBakeTableEntrySize;

  entries_.resize(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::byte* e = data + kBakeHeaderSize + std::size_t{i} * kBakeTableEntrySize;
    BakeSectionEntry& entry = entries_[i];
    entry.tag = loadLittleEndian<std::uint32_t>(e);
    entry.version = loadLittleEndian<std::uint32_t>(e + 4);
    entry.offset = loadLittleEndian<std::uint64_t>(e + 8);
    entry.size = loadLittleEndian<std::uint64_t>(e + 16);
    entry.checksum = loadLittleEndian<std::uint64_t>(e + 24);
    const std::string name = "section " + std::to_string(i) + " '" + bakeSectionTagName(entry.tag) + "'";
    if (entry.version == 0) fail(ErrorCode::kBakeCorrupt, name + ": version 0 is invalid");
    if (entry.offset % kBakeSectionAlignment != 0) {
      fail(ErrorCode::kBakeCorrupt, name + ": offset " + std::to_string(entry.offset) + " is not a multiple of " +
                                        std::to_string(kBakeSectionAlignment));
    }
    if (entry.offset < kBakeHeaderSize + tableBytes) {
      fail(ErrorCode::kBakeCorrupt, name + ": offset " + std::to_string(entry.offset) +
                                        " lies inside the header or section table");
    }
    // Written as a subtraction so a huge size cannot overflow offset + size.
    if (entry.offset > fileSize || entry.size > fileSize - entry.offset) {
      fail(ErrorCode::kBakeCorrupt, name + ": bytes [" + std::to_string(entry.offset) + ", +" +
                                        std::to_string(entry.size) + ") run past the end of the " +
                                        std::to_string(fileSize) + "-byte file");
    }
    for (std::uint32_t j = 0; j < i; ++j) {
      if (entries_[j].tag == entry.tag) {
        fail(ErrorCode::kBakeCorrupt, name + ": tag already used by section " + std::to_string(j));
      }
    }
  }

  // Sections must not overlap, and every byte outside them is zero padding: then every byte
  // of the file is covered by a checksum or known to be zero, so no flipped bit goes unseen.
  std::vector<std::uint32_t> order(count);
  for (std::uint32_t i = 0; i < count; ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return entries_[a].offset < entries_[b].offset; });
  std::uint64_t cursor = kBakeHeaderSize + tableBytes;
  auto checkPadding = [&](std::uint64_t begin, std::uint64_t end) {
    for (std::uint64_t k = begin; k < end; ++k) {
      if (data[k] != std::byte{0}) fail(ErrorCode::kBakeCorrupt, "non-zero padding byte at offset " + std::to_string(k));
    }
  };
  for (std::uint32_t i : order) {
    const BakeSectionEntry& entry = entries_[i];
    if (entry.offset < cursor) {
      fail(ErrorCode::kBakeCorrupt, "section " + std::to_string(i) + " '" + bakeSectionTagName(entry.tag) +
                                        "' overlaps the previous section");
    }
    checkPadding(cursor, entry.offset);
    cursor = entry.offset + entry.size;
  }
  checkPadding(cursor, fileSize);

  for (std::uint32_t i = 0; i < count; ++i) {
    const BakeSectionEntry& entry = entries_[i];
    const std::uint64_t computed = bakeChecksum(bytes.subspan(entry.offset, entry.size));
    if (computed != entry.checksum) {
      fail(ErrorCode::kBakeCorrupt, "section '" + bakeSectionTagName(entry.tag) + "' checksum mismatch (stored " +
                                        hex(entry.checksum) + ", computed " + hex(computed) + ")");
    }
  }
}

std::optional<BakeSection> BakeFileReader::findSection(BakeSectionTag tag, std::uint32_t maxVersion) const {
  for (const BakeSectionEntry& entry : entries_) {
    if (entry.tag != tag) continue;
    if (entry.version > maxVersion) {
      fail(ErrorCode::kBakeVersion, "section '" + bakeSectionTagName(tag) + "' has version " +
                                        std::to_string(entry.version) + ", newer than the newest this build reads (" +
                                        std::to_string(maxVersion) + ")");
    }
    return BakeSection{entry.tag, entry.version, bytes_.subspan(entry.offset, entry.size)};
  }
  return std::nullopt;
}

BakeSection BakeFileReader::section(BakeSectionTag tag, std::uint32_t maxVersion) const {
  if (auto found = findSection(tag, maxVersion)) return *found;
  fail(ErrorCode::kBakeMissingSection, "required section '" + bakeSectionTagName(tag) + "' is missing");
}

}  // namespace clod
