#include "mesh/text_index_check.h"

#include <gtest/gtest.h>

namespace clod::detail {
namespace {

TEST(FindBadOffFace, AcceptsValidFilesInTheirVariants) {
  EXPECT_FALSE(findBadOffFace("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  EXPECT_FALSE(findBadOffFace("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));  // counts on the header line
  EXPECT_FALSE(findBadOffFace("# comment\r\nCOFF\r\n3 1 0\r\n0 0 0 1 1 1 1\r\n1 0 0 1 1 1 1\r\n0 1 0 1 1 1 1\r\n3 0 1 2\r\n"));
  EXPECT_FALSE(findBadOffFace("not an off file\n3 0 1 9999\n"));  // not OFF: Assimp decides
}

TEST(FindBadOffFace, NamesTheLineOfAnOutOfRangeOrNegativeIndex) {
  auto bad = findBadOffFace("OFF\n# c\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4 0 1 2 3\n");
  ASSERT_TRUE(bad);
  EXPECT_TRUE(bad->indexOutOfRange);
  EXPECT_EQ(bad->message, "line 8: face 1: vertex index 3 >= vertex count 3");
  bad = findBadOffFace("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -2 1\n");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->message, "line 6: face 0: vertex index -2 is negative");
}

TEST(FindBadOffFace, RejectsAFaceWithoutVertices) {
  // Assimp 5.2.5 reads past its arrays on this one (found by fuzz_mesh_load).
  auto bad = findBadOffFace("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n0 1 0\n");
  ASSERT_TRUE(bad);
  EXPECT_FALSE(bad->indexOutOfRange);
  EXPECT_EQ(bad->message, "line 6: face 0 lists 0 vertices");
}

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
}

}  // namespace
}  // namespace clod::detail
