#pragma once
// The container of a .clod bake file: a versioned header, a table of sections and the
// section payloads, each protected by an XXH3-64 checksum. This layer knows nothing about
// what a section holds; bake.h encodes meshes, sphere-trees (and later closest feature maps
// and contact trees) into sections and back. The byte layout is in docs/bake-format.md.
//
// Layout (all integers little-endian):
//
//   offset  size  field
//   0       8     magic "CLODBAKE"
//   8       4     u32 format version (kBakeFormatVersion)
//   12      4     u32 flags (0 in version 1; reserved)
//   16      4     u32 section count n
//   20      4     u32 header size (kBakeHeaderSize; where the section table starts)
//   24      8     u64 total file size in bytes
//   32      8     u64 reserved, 0
//   40      8     u64 XXH3-64 of bytes [0, 40) followed by the n table entries
//   48      32*n  section table, one entry per section:
//                   u32 tag (fourcc, e.g. 'MESH'), u32 section version,
//                   u64 payload offset (a multiple of 16), u64 payload size,
//                   u64 XXH3-64 of the payload
//   ...           payloads, each starting at a multiple of 16; the bytes between the table
//                 and the first payload, between payloads, and after the last payload up to
//                 the next multiple of 16 are zero.
//
// Adding a section: pick a new fourcc tag, give it version 1, encode its payload with
// ByteWriter (byte_stream.h), add it with BakeFileWriter::addSection, and read it back with
// BakeFileReader::findSection / section(tag, maxVersion). Readers skip tags they do not know,
// so old readers keep loading files that carry new sections (forward compatibility). Change a
// section's layout only by bumping its version; readers refuse newer versions (kBakeVersion).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "clod/error.h"

namespace clod {

/// A section tag: four ASCII characters packed little-endian, so the file shows them in order.
using BakeSectionTag = std::uint32_t;

/// Packs a four-character tag, e.g. makeBakeSectionTag("MESH").
constexpr BakeSectionTag makeBakeSectionTag(const char (&text)[5]) {
  return static_cast<BakeSectionTag>(static_cast<unsigned char>(text[0])) |
         static_cast<BakeSectionTag>(static_cast<unsigned char>(text[1])) << 8 |
         static_cast<BakeSectionTag>(static_cast<unsigned char>(text[2])) << 16 |
         static_cast<BakeSectionTag>(static_cast<unsigned char>(text[3])) << 24;
}

/// The tag as text for messages: printable characters as is, others as \xNN.
std::string bakeSectionTagName(BakeSectionTag tag);

/// The container format version this build writes and the newest it reads.
inline constexpr std::uint32_t kBakeFormatVersion = 1;
/// Bytes of the fixed header, i.e. the offset of the section table.
inline constexpr std::uint32_t kBakeHeaderSize = 48;
/// Bytes of one section-table entry.
inline constexpr std::uint32_t kBakeTableEntrySize = 32;
/// Every payload starts at a multiple of this many bytes (so arrays can be used in place).
inline constexpr std::uint32_t kBakeSectionAlignment = 16;
/// The most sections a file may declare; more is treated as corruption (bounds the table).
inline constexpr std::uint32_t kBakeMaxSections = 1024;

/// One entry of the section table, as stored.
struct BakeSectionEntry {
  BakeSectionTag tag = 0;
  std::uint32_t version = 0;
  std::uint64_t offset = 0;    ///< from the start of the file; a multiple of kBakeSectionAlignment
  std::uint64_t size = 0;      ///< payload bytes
  std::uint64_t checksum = 0;  ///< XXH3-64 of the payload (seed 0)
};

/// A section found in a file: its tag, version and payload bytes (a view into the file).
struct BakeSection {
  BakeSectionTag tag = 0;
  std::uint32_t version = 0;
  std::span<const std::byte> payload;
};

/// Assembles a bake file from section payloads. Sections are written in the order added.
class BakeFileWriter {
public:
  /// Adds a section. `tag` must not have been added before and `version` must be >= 1
  /// (CLOD_ASSERT). O(payload size) to copy the bytes.
  void addSection(BakeSectionTag tag, std::uint32_t version, std::vector<std::byte> payload);

  /// The complete file: header, table, aligned payloads with zero padding. Deterministic:
  /// the same sections in the same order always give the same bytes. O(total size).
  std::vector<std::byte> encode() const;

private:
  struct Pending {
    BakeSectionTag tag;
    std::uint32_t version;
    std::vector<std::byte> payload;
  };
  std::vector<Pending> sections_;
};

/// The checks BakeFileReader makes first -- magic, format version, section count, header size,
/// header checksum (which covers the section table), flags, reserved field and declared size
/// == `fileBytes` -- made on the first bytes of a file whose whole size is `fileBytes`, so a
/// loader can refuse a file that is not a bake (or not of the size its header declares)
/// before it reads, or allocates, the rest: loadBake reads a 1 GiB file of zeros as 48 bytes.
/// Returns 0 when `start` sufficed; otherwise the number of first bytes the check needs
/// (at most kBakeHeaderSize + kBakeMaxSections * kBakeTableEntrySize, never more than
/// `fileBytes`): call again with that many. Throws clod::Error exactly as BakeFileReader
/// would for the same file. O(section count).
std::size_t checkBakeFileStart(std::span<const std::byte> start, std::uint64_t fileBytes);

/// Reads the header and section table of a bake file held in memory and checks everything the
/// container promises before any section is used: magic, format version, header checksum,
/// total size, every table entry (offset aligned, offset + size inside the file, no overlaps,
/// no duplicate tags, version >= 1), zero padding, and every payload's checksum (unknown
/// sections included). After construction every payload is known to be intact.
///
/// Non-owning: the reader and the BakeSection views it hands out point into `bytes`, which
/// must outlive them. O(file size) (checksums run at several GB/s).
///
/// Throws clod::Error: kBakeTruncated when the file ends before its header, table or declared
/// size; kBakeCorrupt for a wrong magic, a checksum mismatch, an inconsistent table, trailing
/// bytes or non-zero padding; kBakeVersion when the format version is newer than
/// kBakeFormatVersion. Messages name the field, e.g. "bake file: section 'STRE' checksum
/// mismatch (stored 0x..., computed 0x...)".
class BakeFileReader {
public:
  explicit BakeFileReader(std::span<const std::byte> bytes);

  std::uint32_t formatVersion() const { return formatVersion_; }
  /// The table entries in file order.
  std::span<const BakeSectionEntry> entries() const { return entries_; }

  /// The section with `tag`, or nullopt if the file has none. Throws kBakeVersion if its
  /// version is newer than `maxVersion` (the newest this caller can decode).
  std::optional<BakeSection> findSection(BakeSectionTag tag, std::uint32_t maxVersion) const;
  /// As findSection, but a missing section throws kBakeMissingSection naming the tag.
  BakeSection section(BakeSectionTag tag, std::uint32_t maxVersion) const;

private:
  std::span<const std::byte> bytes_;
  std::uint32_t formatVersion_ = 0;
  std::vector<BakeSectionEntry> entries_;
};

/// XXH3-64 (seed 0) of a byte range: the checksum used throughout the bake file.
std::uint64_t bakeChecksum(std::span<const std::byte> bytes) noexcept;

}  // namespace clod
