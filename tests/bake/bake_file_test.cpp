// The bake container (bake_file.h): layout as documented, checks on the table, versions,
// missing and unknown sections. The layout test reads bytes by the documented offsets and
// recomputes the checksums with its own (header-only) xxHash, independent of the library.
#include <algorithm>
#include <cstring>

#include <gtest/gtest.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "bake_test_support.h"
#include "clod/bake_file.h"

namespace clod {
namespace {

using test::thrownCode;

template <class T>
T peek(const std::vector<std::byte>& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

std::vector<std::byte> toBytes(const std::string& text) {
  std::vector<std::byte> bytes(text.size());
  std::memcpy(bytes.data(), text.data(), text.size());
  return bytes;
}

// Rewrites the header checksum after a test edits the header or table on purpose, using
// the documented rule: XXH3-64 of bytes [0, 40) followed by the section table.
void resealHeader(std::vector<std::byte>& bytes) {
  const auto count = peek<std::uint32_t>(bytes, 16);
  std::vector<std::byte> hashed(bytes.begin(), bytes.begin() + 40);
  // A test may declare more entries than the file holds: hash what is there (the reader
  // rejects such a file before it looks at the checksum).
  const std::size_t tableEnd = std::min<std::size_t>(bytes.size(), 48 + std::size_t{32} * count);
  hashed.insert(hashed.end(), bytes.begin() + 48, bytes.begin() + static_cast<std::ptrdiff_t>(tableEnd));
  const std::uint64_t hash = XXH3_64bits(hashed.data(), hashed.size());
  std::memcpy(bytes.data() + 40, &hash, 8);
}

TEST(BakeFile, LayoutMatchesTheDocumentedFormat) {
  BakeFileWriter writer;
  writer.addSection(makeBakeSectionTag("AAAA"), 1, toBytes("hello"));
  writer.addSection(makeBakeSectionTag("BBBB"), 3, toBytes(std::string(37, 'x')));
  writer.addSection(makeBakeSectionTag("EMPT"), 1, {});
  const std::vector<std::byte> file = writer.encode();

  EXPECT_EQ(std::memcmp(file.data(), "CLODBAKE", 8), 0);
  EXPECT_EQ(peek<std::uint32_t>(file, 8), 1u);
  EXPECT_EQ(peek<std::uint32_t>(file, 12), 0u);
  ASSERT_EQ(peek<std::uint32_t>(file, 16), 3u);
  EXPECT_EQ(peek<std::uint32_t>(file, 20), 48u);
  EXPECT_EQ(peek<std::uint64_t>(file, 24), file.size());
  EXPECT_EQ(peek<std::uint64_t>(file, 32), 0u);
  std::vector<std::byte> copy = file;
  resealHeader(copy);
  EXPECT_EQ(copy, file) << "header checksum differs from XXH3 of header[0,40) + table";

  // The tag bytes read as text in file order.
  EXPECT_EQ(std::memcmp(file.data() + 48, "AAAA", 4), 0);
  const std::size_t sizes[3] = {5, 37, 0};
  const std::uint32_t versions[3] = {1, 3, 1};
  std::uint64_t previousEnd = 48 + 3 * 32;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t entry = 48 + 32 * i;
    EXPECT_EQ(peek<std::uint32_t>(file, entry + 4), versions[i]);
    const auto offset = peek<std::uint64_t>(file, entry + 8);
    const auto size = peek<std::uint64_t>(file, entry + 16);
    EXPECT_EQ(offset % 16, 0u) << "section " << i;
    EXPECT_GE(offset, previousEnd) << "section " << i;
    EXPECT_EQ(size, sizes[i]);
    EXPECT_EQ(peek<std::uint64_t>(file, entry + 24), XXH3_64bits(file.data() + offset, size)) << "section " << i;
    for (std::uint64_t k = previousEnd; k < offset; ++k) EXPECT_EQ(file[k], std::byte{0}) << "padding byte " << k;
    previousEnd = offset + size;
  }
  EXPECT_EQ(file.size() % 16, 0u);
  EXPECT_EQ(std::memcmp(file.data() + peek<std::uint64_t>(file, 48 + 32 + 8), std::string(37, 'x').data(), 37), 0);
}

TEST(BakeFile, ReaderReturnsEachSectionsPayloadAndVersion) {
  BakeFileWriter writer;
  writer.addSection(makeBakeSectionTag("AAAA"), 1, toBytes("hello"));
  writer.addSection(makeBakeSectionTag("BBBB"), 3, toBytes("world!"));
  const std::vector<std::byte> file = writer.encode();
  const BakeFileReader reader(file);
  ASSERT_EQ(reader.entries().size(), 2u);
  const BakeSection b = reader.section(makeBakeSectionTag("BBBB"), 3);
  EXPECT_EQ(b.version, 3u);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(b.payload.data()), b.payload.size()), "world!");
  EXPECT_FALSE(reader.findSection(makeBakeSectionTag("CCCC"), 1).has_value());
}

TEST(BakeFile, EmptyFileWithNoSectionsIsValid) {
  const std::vector<std::byte> file = BakeFileWriter{}.encode();
  EXPECT_EQ(file.size(), 48u);
  EXPECT_TRUE(BakeFileReader(file).entries().empty());
}

TEST(BakeFile, SectionNewerThanTheCallerReadsIsAVersionError) {
  BakeFileWriter writer;
  writer.addSection(makeBakeSectionTag("AAAA"), 2, toBytes("v2"));
  const std::vector<std::byte> file = writer.encode();
  const BakeFileReader reader(file);
  EXPECT_EQ(thrownCode([&] { reader.section(makeBakeSectionTag("AAAA"), 1); }), ErrorCode::kBakeVersion);
  EXPECT_EQ(reader.section(makeBakeSectionTag("AAAA"), 2).version, 2u);
}

TEST(BakeFile, MissingRequiredSectionIsNamed) {
  const std::vector<std::byte> file = BakeFileWriter{}.encode();
  try {
    BakeFileReader(file).section(makeBakeSectionTag("STRE"), 1);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBakeMissingSection);
    EXPECT_NE(std::string(e.what()).find("'STRE'"), std::string::npos) << e.what();
  }
}

TEST(BakeFile, NewerFormatVersionIsAVersionError) {
  std::vector<std::byte> file = BakeFileWriter{}.encode();
  const std::uint32_t version = 2;
  std::memcpy(file.data() + 8, &version, 4);
  resealHeader(file);
  EXPECT_EQ(thrownCode([&] { BakeFileReader{file}; }), ErrorCode::kBakeVersion);
}

TEST(BakeFile, TrailingBytesAreCorruption) {
  std::vector<std::byte> file = BakeFileWriter{}.encode();
  file.push_back(std::byte{0});
  EXPECT_EQ(thrownCode([&] { BakeFileReader{file}; }), ErrorCode::kBakeCorrupt);
}

TEST(BakeFile, WrongMagicIsCorruptionEvenForShortInput) {
  EXPECT_EQ(thrownCode([&] { BakeFileReader{toBytes("solid cube\n")}; }), ErrorCode::kBakeCorrupt);
  EXPECT_EQ(thrownCode([&] { BakeFileReader{toBytes("CLOD")}; }), ErrorCode::kBakeTruncated);
  EXPECT_EQ(thrownCode([&] { BakeFileReader{std::span<const std::byte>{}}; }), ErrorCode::kBakeTruncated);
}

// Table entries that pass the header checksum (the test reseals it) but break the rules.
TEST(BakeFile, InconsistentTableEntriesAreCorruptionNamingTheSection) {
  BakeFileWriter writer;
  writer.addSection(makeBakeSectionTag("AAAA"), 1, toBytes(std::string(40, 'a')));
  writer.addSection(makeBakeSectionTag("BBBB"), 1, toBytes(std::string(40, 'b')));
  const std::vector<std::byte> good = writer.encode();
  const std::size_t second = 48 + 32;
  auto expectCorrupt = [&](const char* what, auto edit) {
    std::vector<std::byte> file = good;
    edit(file);
    resealHeader(file);
    try {
      BakeFileReader{file};
      ADD_FAILURE() << what << ": accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kBakeCorrupt) << what << ": " << e.what();
    }
  };
  auto put64 = [](std::vector<std::byte>& f, std::size_t at, std::uint64_t v) { std::memcpy(f.data() + at, &v, 8); };
  auto put32 = [](std::vector<std::byte>& f, std::size_t at, std::uint32_t v) { std::memcpy(f.data() + at, &v, 4); };
  expectCorrupt("misaligned offset", [&](auto& f) { put64(f, second + 8, peek<std::uint64_t>(good, second + 8) + 8); });
  expectCorrupt("overlapping sections", [&](auto& f) { put64(f, second + 8, peek<std::uint64_t>(good, 48 + 8)); });
  expectCorrupt("offset inside the table", [&](auto& f) { put64(f, second + 8, 96); });
  expectCorrupt("size past the end", [&](auto& f) { put64(f, second + 16, 1000); });
  expectCorrupt("size overflowing offset+size", [&](auto& f) { put64(f, second + 16, ~std::uint64_t{0} - 8); });
  expectCorrupt("duplicate tag", [&](auto& f) { put32(f, second, makeBakeSectionTag("AAAA")); });
  expectCorrupt("version 0", [&](auto& f) { put32(f, second + 4, 0); });
  expectCorrupt("payload checksum", [&](auto& f) { put64(f, second + 24, peek<std::uint64_t>(good, second + 24) ^ 1); });
  expectCorrupt("section count too large", [&](auto& f) { put32(f, 16, kBakeMaxSections + 1); });
  expectCorrupt("flags", [&](auto& f) { put32(f, 12, 1); });
  expectCorrupt("header size", [&](auto& f) { put32(f, 20, 64); });
  expectCorrupt("non-zero padding", [&](auto& f) { f[peek<std::uint64_t>(good, 48 + 8) + 40] = std::byte{1}; });
  expectCorrupt("declared size smaller than the file", [&](auto& f) { put64(f, 24, good.size() - 16); });
}

TEST(BakeFile, TagNamesEscapeUnprintableBytes) {
  EXPECT_EQ(bakeSectionTagName(makeBakeSectionTag("MESH")), "MESH");
  EXPECT_EQ(bakeSectionTagName(0x00414243u), "CBA\\x00");
}

}  // namespace
}  // namespace clod
