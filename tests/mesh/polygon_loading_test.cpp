// Polygonal faces through the loaders: clod triangulates them (polygon_triangulation.h), in
// O(n log n) for a face of n corners, with every triangle wound like the face and inside it.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "clod/mesh_io.h"

namespace clod {
namespace {

std::span<const std::byte> asBytes(const std::string& text) {
  return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

// z components of the triangles' (b - a) x (c - a): twice their areas, signed, for flat meshes
// in the z = 0 plane.
std::vector<double> twiceSignedAreasXY(const TriangleMesh& mesh) {
  std::vector<double> areas;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) areas.push_back(mesh.triangleCross(t).z());
  return areas;
}

// A comb polygon in z = 0, counter-clockwise seen from +z: a bar [0, teeth] x [0, 1] with teeth
// [k, k + 0.5] x [1, 4]; 4 teeth + 3 corners, area 2.5 per tooth.
std::vector<Vec3> combCorners(int teeth) {
  std::vector<Vec3> corners{Vec3(0, 0, 0), Vec3(teeth, 0, 0), Vec3(teeth, 1, 0)};
  for (int k = teeth; k-- > 0;) {
    corners.push_back(Vec3(k + 0.5, 1, 0));
    corners.push_back(Vec3(k + 0.5, 4, 0));
    corners.push_back(Vec3(k, 4, 0));
    corners.push_back(Vec3(k, 1, 0));
  }
  return corners;
}

std::string objWithOneFace(const std::vector<Vec3>& corners) {
  std::string obj;
  obj.reserve(corners.size() * 24);
  for (const Vec3& p : corners)
    obj += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  obj += "f";
  for (std::size_t i = 1; i <= corners.size(); ++i) obj += " " + std::to_string(i);
  return obj + "\n";
}

// One 100,003-corner face (Assimp's ear clipping took > 400 s on such a face; the time is a
// benchmark matter, this checks the result).
TEST(PolygonLoading, HundredThousandCornerObjFaceLoadsAsATriangulatedComb) {
  const int teeth = 25'000;
  const std::vector<Vec3> corners = combCorners(teeth);
  const auto path = std::filesystem::temp_directory_path() / ("clod_big_polygon_" + std::to_string(::getpid()) + ".obj");
  std::ofstream(path) << objWithOneFace(corners);
  const LoadedMesh loaded = loadMesh(path);
  std::filesystem::remove(path);

  EXPECT_EQ(loaded.importedVertexCount, corners.size());
  EXPECT_EQ(loaded.mesh.vertexCount(), corners.size());
  ASSERT_EQ(loaded.mesh.triangleCount(), corners.size() - 2);
  double twiceArea = 0.0;
  std::size_t againstTheFace = 0;
  for (double a : twiceSignedAreasXY(loaded.mesh)) {
    twiceArea += a;
    againstTheFace += a < 0.0;
  }
  // Coordinates are small multiples of 0.5 (exact in float and double), so every triangle's
  // area is exact too, and so is their sum below 2^53.
  EXPECT_EQ(twiceArea, 2.0 * 2.5 * teeth);
  EXPECT_EQ(againstTheFace, 0u);
  for (const std::string& w : loaded.warnings) EXPECT_EQ(w.find("fan-triangulated"), std::string::npos) << w;
}

// An L-shaped hexagon whose first corner is reflex: a fan from it would put a triangle outside
// (wound backwards, the total area still right), which is what the old OFF reader did.
TEST(PolygonLoading, ConcaveFacesAreCutInsideInEveryFormat) {
  const std::string obj = "v 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4 5 6\n";
  const std::string off = "OFF\n6 1 0\n1 1 0\n1 2 0\n0 2 0\n0 0 0\n2 0 0\n2 1 0\n6 0 1 2 3 4 5\n";
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "1 1 0\n1 2 0\n0 2 0\n0 0 0\n2 0 0\n2 1 0\n6 0 1 2 3 4 5\n";
  for (const auto& [bytes, hint] : {std::pair{obj, "obj"}, std::pair{off, "off"}, std::pair{ply, "ply"}}) {
    SCOPED_TRACE(hint);
    const LoadedMesh loaded = loadMeshFromMemory(asBytes(bytes), hint);
    ASSERT_EQ(loaded.mesh.triangleCount(), 4u);
    double twiceArea = 0.0;
    for (double a : twiceSignedAreasXY(loaded.mesh)) {
      EXPECT_GT(a, 0.0);
      twiceArea += a;
    }
    EXPECT_EQ(twiceArea, 6.0);
  }
}

TEST(PolygonLoading, SelfIntersectingFaceIsFannedWithAWarning) {
  const std::string obj = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nv 0.5 2 0\nf 1 2 3 4 5\n";
  const LoadedMesh loaded = loadMeshFromMemory(asBytes(obj), "obj");
  EXPECT_EQ(loaded.mesh.triangleCount(), 3u);
  bool warned = false;
  for (const std::string& w : loaded.warnings) warned |= w.find("1 polygon(s) not simple") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace clod
