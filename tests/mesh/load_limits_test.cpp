// MeshLoadOptions::maxVertices / maxTriangles / maxPolygonVertices: a file past a limit gets
// kUnsupportedMesh naming the limit, as early as the format allows (header counts before any
// allocation), and a file exactly at the limits loads.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "clod/error.h"
#include "clod/mesh_io.h"
#include "mesh/off_reader.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

std::span<const std::byte> asBytes(const std::string& text) {
  return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The message of the kUnsupportedMesh error `load` throws (fails the test for anything else).
template <class F>
std::string limitError(F&& load) {
  try {
    load();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kUnsupportedMesh) << errorCodeName(e.code()) << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find("raise it"), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no clod::Error thrown";
  return "";
}

MeshLoadOptions limits(std::uint64_t vertices, std::uint64_t triangles, std::uint64_t polygon) {
  MeshLoadOptions options;
  options.maxVertices = vertices;
  options.maxTriangles = triangles;
  options.maxPolygonVertices = polygon;
  return options;
}

// A grid of `n` x 1 unit squares as OBJ quads: 2n + 2 vertices, n quads, 2n triangles.
std::string quadStrip(int n) {
  std::string obj;
  for (int i = 0; i <= n; ++i) obj += "v " + std::to_string(i) + " 0 0\nv " + std::to_string(i) + " 1 0\n";
  for (int i = 0; i < n; ++i)
    obj += "f " + std::to_string(2 * i + 1) + " " + std::to_string(2 * i + 3) + " " + std::to_string(2 * i + 4) + " " +
           std::to_string(2 * i + 2) + "\n";
  return obj;
}

TEST(LoadLimits, OffHeaderClaimingTwoToTheThirtyOneVerticesFailsBeforeAllocating) {
  // 2^31 vertices of 24 bytes would be 48 GiB; the header alone must be enough to refuse.
  const std::string off = "OFF\n2147483648 1 0\n0 0 0\n";
  const std::string message = limitError([&] { loadMeshFromMemory(asBytes(off), "off"); });
  EXPECT_NE(message.find("line 2: 2147483648 vertices declared, more than MeshLoadOptions::maxVertices = 150000000"),
            std::string::npos) << message;
  // The same through the reader alone, with a small configured limit.
  const std::string small = "OFF\n11 1 0\n";
  const std::string readerMessage = limitError([&] { detail::readOff(small, "f.off", limits(10, 100, 100)); });
  EXPECT_NE(readerMessage.find("maxVertices = 10"), std::string::npos) << readerMessage;
}

TEST(LoadLimits, OffFacesAreCheckedAgainstPolygonAndTriangleLimits) {
  const std::string off = "OFF\n5 1 0\n0 0 0\n1 0 0\n2 1 0\n1 2 0\n0 1 0\n5 0 1 2 3 4\n";
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(off), "off", limits(100, 100, 4)); })
                .find("line 8: face 0: 5 corners in one face, more than MeshLoadOptions::maxPolygonVertices = 4"),
            std::string::npos);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(off), "off", limits(100, 2, 100)); }).find("maxTriangles = 2"),
            std::string::npos);
  EXPECT_EQ(loadMeshFromMemory(asBytes(off), "off", limits(5, 3, 5)).mesh.triangleCount(), 3u);
}

TEST(LoadLimits, ObjLinesAreCountedBeforeTheImporterRuns) {
  const std::string obj = quadStrip(10);  // 22 vertices, 10 quads, 20 triangles
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(obj), "obj", limits(21, 100, 100)); })
                .find("line 22: 22 vertices ('v' lines) so far, more than MeshLoadOptions::maxVertices = 21"),
            std::string::npos);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(obj), "obj", limits(100, 19, 100)); })
                .find("line 32: 20 triangles so far, more than MeshLoadOptions::maxTriangles = 19"),
            std::string::npos);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(obj), "obj", limits(100, 100, 3)); })
                .find("line 23: 4 corners in one face, more than MeshLoadOptions::maxPolygonVertices = 3"),
            std::string::npos);
  // Assimp's OBJ reader makes a vertex of every face corner: 40 here.
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(obj), "obj", limits(39, 100, 100)); })
                .find("line 32: 40 face corners so far"),
            std::string::npos);
  const LoadedMesh atTheLimits = loadMeshFromMemory(asBytes(obj), "obj", limits(40, 20, 4));
  EXPECT_EQ(atTheLimits.mesh.triangleCount(), 20u);
}

TEST(LoadLimits, PlyHeaderCountsAreCheckedBeforeTheImporterRuns) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 1099511627776\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(header + "0 0 0\n"), "ply"); })
                .find("line 3: 1099511627776 vertices declared"),
            std::string::npos);
  // Under the limits but more elements than the bytes could hold: malformed.
  std::string tooMany = header;
  tooMany.replace(tooMany.find("1099511627776"), 13, "1000000");
  try {
    loadMeshFromMemory(asBytes(tooMany + "0 0 0\n"), "ply");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kParseError) << e.what();
    EXPECT_NE(std::string(e.what()).find("1000000 vertex elements declared"), std::string::npos) << e.what();
  }
  const std::string box = readBytes(test::goodFile("box.ply"));
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(box), "ply", limits(7, 100, 100)); }).find("maxVertices = 7"),
            std::string::npos);
}

// The importer sizes each PLY list by the count its row gives: a face row declaring a count of 70
// digits made it ask for 26 GB (found by fuzz_mesh_load). Every list count is held against
// maxPolygonVertices before it runs, in ASCII and binary files alike.
std::string plyHeader(std::string_view format, std::string_view countType) {
  return "ply\nformat " + std::string(format) + " 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list " + std::string(countType) + " int vertex_indices\nend_header\n";
}

TEST(LoadLimits, PlyListCountsAreCheckedBeforeTheImporterRuns) {
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
  const std::string ascii = plyHeader("ascii", "uchar") + vertices;
  EXPECT_EQ(loadMeshFromMemory(asBytes(ascii + "3 0 1 2\n"), "ply").mesh.triangleCount(), 1u);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(ascii + std::string(70, '1') + " 0 1 2\n"), "ply"); })
                .find("entries in one list, more than MeshLoadOptions::maxPolygonVertices"),
            std::string::npos);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(ascii + "4 0 1 2 0\n"), "ply", limits(100, 100, 3)); })
                .find("4 entries in one list"),
            std::string::npos);
  // Binary, little- and big-endian: a uint count of 4,000,000,000 (and a negative int's bits).
  for (const std::string format : {"binary_little_endian", "binary_big_endian"}) {
    std::string binary = plyHeader(format, "uint");
    for (int v = 0; v < 9; ++v) binary.append(4, '\0');  // 3 vertices of 3 floats (zeros)
    const std::uint32_t count = 4000000000u;
    for (int b = 0; b < 4; ++b) {
      const int shift = format == "binary_little_endian" ? 8 * b : 8 * (3 - b);
      binary.push_back(static_cast<char>((count >> shift) & 0xffu));
    }
    binary.append(12, '\0');
    EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(binary), "ply"); }).find("4000000000 entries in one list"),
              std::string::npos)
        << format;
  }
}

TEST(LoadLimits, PlyHeadersOutsideTheFormatAreParseErrorsNamingTheLine) {
  auto parseError = [](const std::string& text) {
    try {
      loadMeshFromMemory(asBytes(text), "ply");
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kParseError) << e.what();
      return std::string(e.what());
    }
    ADD_FAILURE() << "no error";
    return std::string();
  };
  const std::string good = plyHeader("ascii", "uchar") + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::string keyword = good;
  keyword.replace(keyword.find("element vertex"), 7, "elemxnt");
  EXPECT_NE(parseError(keyword).find("line 3: PLY header: unknown keyword 'elemxnt'"), std::string::npos);
  std::string type = good;
  type.replace(type.find("float x"), 5, "floau");
  EXPECT_NE(parseError(type).find("line 4: PLY header: unknown type 'floau'"), std::string::npos);
  std::string listType = good;
  listType.replace(listType.find("list uchar"), 10, "list float");
  EXPECT_NE(parseError(listType).find("an integer count type"), std::string::npos);
}

TEST(LoadLimits, ImportedScenesAreCheckedWithNodeInstancesCounted) {
  // glTF is not pre-scanned: the check runs on the importer's scene, before clod copies it.
  nlohmann::json gltf = nlohmann::json::parse(readBytes(test::goodFile("box.gltf")));
  gltf["nodes"].push_back({{"mesh", 0}, {"translation", {20, 0, 0}}});
  gltf["scenes"][0]["nodes"] = {0, 1};
  const std::string twice = gltf.dump();
  EXPECT_EQ(loadMeshFromMemory(asBytes(twice), "gltf", limits(16, 24, 3)).mesh.triangleCount(), 24u);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(twice), "gltf", limits(15, 24, 3)); })
                .find("16 vertices or more in the imported scene, more than MeshLoadOptions::maxVertices = 15"),
            std::string::npos);
  EXPECT_NE(limitError([&] { loadMeshFromMemory(asBytes(twice), "gltf", limits(16, 23, 3)); }).find("maxTriangles = 23"),
            std::string::npos);
  // STL delivers 3 vertices per triangle.
  EXPECT_NE(limitError([&] { loadMesh(test::goodFile("box_binary.stl"), limits(35, 12, 3)); }).find("maxVertices = 35"),
            std::string::npos);
  // Collada polygons are checked on the imported faces.
  EXPECT_NE(limitError([&] { loadMesh(test::goodFile("box_z_up.dae"), limits(100, 100, 3)); })
                .find("4 corners in one face, more than MeshLoadOptions::maxPolygonVertices = 3"),
            std::string::npos);
}

TEST(LoadLimits, DefaultsAreDocumentedValues) {
  const MeshLoadOptions defaults;
  EXPECT_EQ(defaults.maxVertices, 150'000'000u);
  EXPECT_EQ(defaults.maxTriangles, 50'000'000u);
  EXPECT_EQ(defaults.maxPolygonVertices, 1'000'000u);
}

}  // namespace
}  // namespace clod
