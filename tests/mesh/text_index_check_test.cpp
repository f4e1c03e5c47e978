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
}

}  // namespace
}  // namespace clod::detail
