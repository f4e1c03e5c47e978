#include "mesh/off_reader.h"

#include <gtest/gtest.h>

#include "clod/error.h"

namespace clod::detail {
namespace {

struct Thrown {
  ErrorCode code;
  std::string message;
};

Thrown thrownBy(std::string_view text) {
  try {
    readOff(text, "f.off");
  } catch (const Error& e) {
    return {e.code(), e.what()};
  }
  ADD_FAILURE() << "no clod::Error for: " << text;
  return {ErrorCode::kInvalidArgument, ""};
}

TEST(ReadOff, ReadsTheVariantsAndTriangulatesConvexPolygonsAsFans) {
  const OffContent plain = readOff("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", "f.off");
  ASSERT_EQ(plain.mesh.vertexCount(), 4u);
  ASSERT_EQ(plain.mesh.triangles.size(), 2u);
  EXPECT_EQ(plain.mesh.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(plain.mesh.triangles[1], (Triangle{0, 2, 3}));
  EXPECT_EQ(plain.mesh.vertices[2], Vec3(1, 1, 0));
  // Counts on the keyword line, CRLF, comments, colours after vertices and faces, no keyword.
  const OffContent coff = readOff("COFF 3 1 0 # counts\r\n0 0 0 255 0 0 255\r\n1 0 0 0 255 0 255\r\n0 1 0 0 0 255 255\r\n3 0 1 2 1 1 1\r\n", "f.off");
  EXPECT_EQ(coff.mesh.triangles.size(), 1u);
  const OffContent bare = readOff("3 2\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n", "f.off");
  EXPECT_EQ(bare.mesh.triangles.size(), 1u);
  EXPECT_EQ(bare.ignoredPrimitives, 1u);
}

TEST(ReadOff, NamesTheLineOfEveryKindOfProblem) {
  Thrown t = thrownBy("OFF\n# c\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4 0 1 2 3\n");
  EXPECT_EQ(t.code, ErrorCode::kIndexOutOfRange);
  EXPECT_EQ(t.message, "f.off: line 8: face 1: vertex index 3 >= vertex count 3");
  t = thrownBy("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -2 1\n");
  EXPECT_EQ(t.code, ErrorCode::kIndexOutOfRange);
  EXPECT_EQ(t.message, "f.off: line 6: face 0: vertex index -2 is negative");
  t = thrownBy("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n0 1 0\n");
  EXPECT_EQ(t.code, ErrorCode::kParseError);
  EXPECT_EQ(t.message, "f.off: line 6: face 0: '0' is not a vertex count >= 1");
  t = thrownBy("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
  EXPECT_EQ(t.message, "f.off: line 6: face 0: 3 vertices announced, 2 values given");
  t = thrownBy("OFF\n3 1 0\n0 0 0\n1 0 0\n");
  EXPECT_EQ(t.message, "f.off: the file ends before vertex 2 of 3");
  t = thrownBy("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(t.message, "f.off: the file ends before face 1 of 2");
  t = thrownBy("NOPE\n3 1 0\n");
  EXPECT_EQ(t.code, ErrorCode::kParseError);
  t = thrownBy("OFF\n99999999 1 0\n0 0 0\n");
  EXPECT_EQ(t.code, ErrorCode::kParseError);  // counts under the limits but larger than the file can hold
  t = thrownBy("OFF\n999999999 1 0\n0 0 0\n");
  EXPECT_EQ(t.code, ErrorCode::kUnsupportedMesh);  // past MeshLoadOptions::maxVertices
  t = thrownBy("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 x\n");
  EXPECT_EQ(t.message, "f.off: line 6: face 0: 'x' is not a vertex index");
}

TEST(ReadOff, KeepsNonFiniteCoordinatesForValidationToReport) {
  const OffContent content = readOff("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 inf 0\n3 0 1 2\n", "f.off");
  EXPECT_TRUE(std::isnan(content.mesh.vertices[1].y()));
  EXPECT_TRUE(std::isinf(content.mesh.vertices[2].y()));
}

}  // namespace
}  // namespace clod::detail
