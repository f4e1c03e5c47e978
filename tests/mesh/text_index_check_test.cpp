#include "mesh/text_index_check.h"

#include <gtest/gtest.h>

namespace clod::detail {
namespace {

TEST(FindBadObjIndex, ResolvesNegativeIndicesRelativeToTheLatestVertex) {
  EXPECT_FALSE(findBadObjIndex("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nf 1/1/1 2//2 3\n"));
  EXPECT_EQ(findBadObjIndex("v 0 0 0\nv 1 0 0\nf -3 -2 -1\nv 0 1 0\n"),
            "line 3: vertex index -3 does not refer to a vertex (2 defined so far)");
  EXPECT_EQ(findBadObjIndex("v 0 0 0\nf 0 1 1\n"), "line 2: vertex index 0 does not refer to a vertex (1 defined so far)");
  EXPECT_EQ(findBadObjIndex("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4/1\n"), "line 4: vertex index 4 > vertex count 3");
}

TEST(FindPlyHeaderProblem, RequiresAnEndHeaderLine) {
  EXPECT_FALSE(findPlyHeaderProblem("ply\nformat ascii 1.0\nend_header\n"));
  EXPECT_FALSE(findPlyHeaderProblem("PLY\r\nformat ascii 1.0\r\nend_header \r\n"));
  EXPECT_TRUE(findPlyHeaderProblem("ply\nformat ascii 1.0\nend_headerX\n"));
  EXPECT_TRUE(findPlyHeaderProblem("  ply\nformat ascii 1.0\n"));
  EXPECT_FALSE(findPlyHeaderProblem("solid not a ply\n"));
  // Leading NUL bytes, which Assimp drops before it looks for "ply" (a fuzz finding: this hung
  // its PLY reader for over a minute).
  using namespace std::string_view_literals;
  EXPECT_TRUE(findPlyHeaderProblem("\0\nply\nformat ascii 1.0\nelement vertex 8\n"sv));
  EXPECT_FALSE(findPlyHeaderProblem("\0\nply\nformat ascii 1.0\nend_header\n"sv));
}

TEST(FindGlbHeaderProblem, ChecksDeclaredLengthsAgainstTheBytes) {
  auto header = [](std::uint32_t total, std::uint32_t chunk) {
    std::string bytes = "glTF";
    for (std::uint32_t v : {2u, total, chunk, 0x4E4F534Au})
      for (int k = 0; k < 4; ++k) bytes.push_back(char((v >> (8 * k)) & 0xff));
    return bytes;
  };
  std::string ok = header(24, 4) + "{}  ";
  EXPECT_FALSE(findGlbHeaderProblem(ok));
  std::string longTotal = header(1000, 4) + "{}  ";
  EXPECT_EQ(findGlbHeaderProblem(longTotal), "GLB header declares 1000 bytes, the file has 24");
  std::string longChunk = header(24, 400) + "{}  ";
  EXPECT_EQ(findGlbHeaderProblem(longChunk), "GLB chunk 0 declares 400 bytes, only 4 remain");
  EXPECT_FALSE(findGlbHeaderProblem("solid x"));
}

}  // namespace
}  // namespace clod::detail
