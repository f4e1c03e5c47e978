#include "clod/mesh_io.h"

#include <cstring>
#include <fstream>
#include <set>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "clod/error.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

using test::badFile;
using test::goodFile;

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::span<const std::byte> asBytes(const std::string& text) {
  return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

struct Thrown {
  ErrorCode code;
  std::string message;
};

template <class F>
Thrown thrownBy(F&& load) {
  try {
    load();
  } catch (const Error& e) {
    return {e.code(), e.what()};
  }
  ADD_FAILURE() << "no clod::Error thrown";
  return {ErrorCode::kInvalidArgument, ""};
}

// Every good file holds the box [0,1] x [0,2] x [0,3] (unequal sides catch swapped axes), stored
// as quads (OBJ, PLY, OFF), triangle soup (STL) or indexed triangles with a node transform
// (glTF/GLB: positions shifted by -5 in x, the node translates by +5).
void expectTheBox(const LoadedMesh& loaded, const std::string& name) {
  SCOPED_TRACE(name);
  const MeshReport& r = loaded.report;
  EXPECT_EQ(loaded.mesh.vertexCount(), 8u);
  EXPECT_EQ(loaded.mesh.triangleCount(), 12u);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.consistentlyOriented);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.degenerateTriangles, 0u);
  ASSERT_TRUE(r.signedVolume.has_value());
  // Corners are small integers, exact in float and double: the volume 1*2*3 is exact.
  EXPECT_EQ(*r.signedVolume, 6.0);
  EXPECT_EQ(r.bounds.min, Vec3(0, 0, 0));
  EXPECT_EQ(r.bounds.max, Vec3(1, 2, 3));
  std::set<std::tuple<double, double, double>> corners;
  for (const Vec3& v : loaded.mesh.vertices) corners.insert({v.x(), v.y(), v.z()});
  std::set<std::tuple<double, double, double>> expected;
  for (double x : {0.0, 1.0})
    for (double y : {0.0, 2.0})
      for (double z : {0.0, 3.0}) expected.insert({x, y, z});
  EXPECT_EQ(corners, expected);
  EXPECT_FALSE(loaded.flipped);
  EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
}

TEST(LoadMesh, EveryFormatLoadsTheSameBox) {
  for (const char* name : {"box.obj", "box_ascii.stl", "box_binary.stl", "box.ply", "box.off", "box.gltf", "box.glb",
                           "box_z_up.dae"})
    expectTheBox(loadMesh(goodFile(name)), name);
}

TEST(LoadMesh, EveryFormatLoadsTheSameBoxFromMemory) {
  for (const char* name : {"box.obj", "box_ascii.stl", "box_binary.stl", "box.ply", "box.off", "box.gltf", "box.glb",
                           "box_z_up.dae"}) {
    const std::string bytes = readBytes(goodFile(name));
    std::string hint = name;
    hint = hint.substr(hint.rfind('.') + 1);
    expectTheBox(loadMeshFromMemory(asBytes(bytes), hint), name);
  }
}

TEST(LoadMesh, StlTriangleSoupIsWeldedUnlessWeldingIsDisabled) {
  const LoadedMesh welded = loadMesh(goodFile("box_binary.stl"));
  EXPECT_EQ(welded.importedVertexCount, 36u);
  EXPECT_EQ(welded.weldedVertexCount, 28u);
  MeshLoadOptions noWeld;
  noWeld.weldToleranceRel = -1.0;
  const LoadedMesh soup = loadMesh(goodFile("box_binary.stl"), noWeld);
  EXPECT_EQ(soup.mesh.vertexCount(), 36u);
  EXPECT_EQ(soup.report.boundaryEdges, 36u);  // 12 separate triangles
  EXPECT_EQ(soup.report.components, 12u);
}

TEST(LoadMesh, WeldToleranceIsRelativeToTheDiagonal) {
  // Two triangles sharing an edge whose copies differ by 2^-20 (exact in float, which Assimp
  // stores), in a mesh of diagonal ~141: merged at the default 1e-7 * diagonal = 1.4e-5, kept
  // apart when only exact duplicates merge.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1.00000095367431640625 0 0\nv 0 1.00000095367431640625 0\nv 100 100 0\n"
      "f 1 2 3\nf 4 6 5\n";
  const LoadedMesh welded = loadMeshFromMemory(asBytes(obj), "obj");
  EXPECT_EQ(welded.mesh.vertexCount(), 4u);
  EXPECT_EQ(welded.report.boundaryEdges, 4u);
  EXPECT_EQ(welded.report.components, 1u);
  MeshLoadOptions exact;
  exact.weldToleranceRel = 0.0;
  const LoadedMesh apart = loadMeshFromMemory(asBytes(obj), "obj", exact);
  EXPECT_EQ(apart.mesh.vertexCount(), 6u);
  EXPECT_EQ(apart.report.boundaryEdges, 6u);
  EXPECT_EQ(apart.report.components, 2u);
}

TEST(LoadMesh, InsideOutBoxIsFlippedWithAWarning) {
  const LoadedMesh loaded = loadMesh(goodFile("box_inside_out.obj"));
  EXPECT_TRUE(loaded.flipped);
  ASSERT_TRUE(loaded.report.signedVolume.has_value());
  EXPECT_EQ(*loaded.report.signedVolume, 6.0);
  bool warned = false;
  for (const std::string& w : loaded.warnings) warned |= w.find("inside-out") != std::string::npos;
  EXPECT_TRUE(warned);

  MeshLoadOptions keep;
  keep.orientOutward = false;
  const LoadedMesh kept = loadMesh(goodFile("box_inside_out.obj"), keep);
  EXPECT_FALSE(kept.flipped);
  EXPECT_EQ(*kept.report.signedVolume, -6.0);
}

// glTF node transforms: a mirroring scale must not turn the box inside-out, and a mesh used by
// two nodes appears twice.
TEST(LoadMesh, GltfNodeTransformsAreAppliedAndMirroringKeepsOutward) {
  nlohmann::json gltf = nlohmann::json::parse(readBytes(goodFile("box.gltf")));
  gltf["nodes"][0]["scale"] = {-1, 1, 1};  // x -> -x + 5: the box lands on [9, 10] in x
  const std::string mirrored = gltf.dump();
  const LoadedMesh loaded = loadMeshFromMemory(asBytes(mirrored), "gltf");
  EXPECT_EQ(loaded.report.bounds.min, Vec3(9, 0, 0));
  EXPECT_EQ(loaded.report.bounds.max, Vec3(10, 2, 3));
  EXPECT_FALSE(loaded.flipped);
  ASSERT_TRUE(loaded.report.signedVolume.has_value());
  EXPECT_EQ(*loaded.report.signedVolume, 6.0);

  gltf["nodes"][0].erase("scale");
  gltf["nodes"].push_back({{"mesh", 0}, {"translation", {20, 0, 0}}});
  gltf["scenes"][0]["nodes"] = {0, 1};
  const std::string twice = gltf.dump();
  const LoadedMesh two = loadMeshFromMemory(asBytes(twice), "gltf");
  EXPECT_EQ(two.mesh.triangleCount(), 24u);
  EXPECT_EQ(two.report.components, 2u);
  EXPECT_EQ(two.report.bounds.max, Vec3(16, 2, 3));  // [-5,-4] + 20
  EXPECT_EQ(*two.report.signedVolume, 12.0);
}

// Collada: vertices as written in the file whatever its <up_axis> and <unit> (Assimp would
// rotate Z-up and X-up files to Y-up and scale by the unit); node transforms still apply.
TEST(LoadMesh, ColladaKeepsTheFilesOwnCoordinates) {
  const std::string zUp = readBytes(goodFile("box_z_up.dae"));
  auto variant = [&](const std::string& from, const std::string& to) {
    std::string text = zUp;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  const std::pair<std::string, std::string> variants[] = {
      {"Z_UP", "Z_UP"}, {"Z_UP", "Y_UP"}, {"Z_UP", "X_UP"}, {"meter=\"1\"", "meter=\"0.01\""}};
  for (const auto& [from, to] : variants) {
    const std::string text = variant(from, to);
    expectTheBox(loadMeshFromMemory(asBytes(text), "dae"), to);
    // Recognised by content too, as Assimp does.
    expectTheBox(loadMeshFromMemory(asBytes(text), "xml"), to + " (as .xml)");
  }
  // A glTF file is not Collada because "<collada" appears in its first bytes: its root node's
  // transform (the +5 in x of box.gltf) stays.
  nlohmann::json gltf = nlohmann::json::parse(readBytes(goodFile("box.gltf")));
  gltf["asset"]["generator"] = "<COLLADA";
  const std::string mentioning = gltf.dump();
  ASSERT_LT(mentioning.find("<COLLADA"), 200u);
  expectTheBox(loadMeshFromMemory(asBytes(mentioning), "gltf"), "glTF mentioning <COLLADA");
}

TEST(LoadMesh, PointsAndLinesAreIgnoredWithAWarning) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 2 3\nl 1 4\n";
  const LoadedMesh loaded = loadMeshFromMemory(asBytes(obj), "obj");
  EXPECT_EQ(loaded.mesh.triangleCount(), 1u);
  bool warned = false;
  for (const std::string& w : loaded.warnings) warned |= w.find("points/lines") != std::string::npos;
  EXPECT_TRUE(warned);
}

struct BadCase {
  const char* file;
  ErrorCode code;
  const char* culprit;  // must appear in the message
};

TEST(LoadMesh, EveryBadFileGivesItsErrorCodeAndNamesTheCulprit) {
  const BadCase cases[] = {
      {"empty.obj", ErrorCode::kEmptyFile, "0 bytes"},
      {"garbage.xyz", ErrorCode::kUnknownFormat, "unknown file format"},
      {"nan_vertex.obj", ErrorCode::kNonFiniteVertex, "nan"},
      {"inf_vertex.off", ErrorCode::kNonFiniteVertex, "inf"},
      {"index_out_of_range.obj", ErrorCode::kIndexOutOfRange, "line 5: vertex index 9001"},
      {"index_out_of_range.off", ErrorCode::kIndexOutOfRange, "line 7: face 1: vertex index 9001 >= vertex count 3"},
      {"negative_index.off", ErrorCode::kIndexOutOfRange, "vertex index -1 is negative"},
      {"index_out_of_range.ply", ErrorCode::kIndexOutOfRange, "face 1: vertex index 9001 >= vertex count 3"},
      {"index_out_of_range.gltf", ErrorCode::kIndexOutOfRange, "out-of-range"},
      {"no_triangles.obj", ErrorCode::kNoTriangles, "no triangles"},
      {"all_degenerate.obj", ErrorCode::kAllTrianglesDegenerate, "all 3 triangles have zero area"},
      {"truncated_binary.stl", ErrorCode::kParseError, "STL"},
      {"malformed.off", ErrorCode::kParseError, "line 4: vertex 1: expected three numbers"},
      // Assimp 5.2.5's PLY reader never returns on this (found by fuzz_mesh_load).
      {"ply_no_end_header.ply", ErrorCode::kParseError, "end_header"},
      // These two crashed Assimp's OFF reader (an assert abort and an out-of-bounds read, found by
      // fuzz_mesh_load); OFF now has its own reader (src/mesh/off_reader.h).
      {"face_without_indices.off", ErrorCode::kParseError, "line 6: vertex 3: expected three numbers"},
      {"face_with_zero_vertices.off", ErrorCode::kParseError, "line 6: face 0: '0' is not a vertex count >= 1"},
      // Assimp allocates and clears the 1 GiB this 788-byte file claims (found by fuzz_mesh_load).
      {"glb_chunk_too_long.glb", ErrorCode::kParseError, "declares 1073742416 bytes"},
      // OFF bytes under a .glb name: Assimp fell back to its OFF reader and crashed (fuzz).
      {"off_content_with_glb_name.glb", ErrorCode::kParseError, "vertex 1: expected three numbers"},
      // box_z_up.dae with one index of its <p> turned into a letter: Assimp 5.2.5's Collada reader
      // never returns (found by fuzz_mesh_load with a byte 0xc9 there).
      {"collada_letter_in_index_list.dae", ErrorCode::kParseError, "Collada <p> at byte 1710"},
      // box_z_up.dae whose <float_array> lost its count attribute ("ciunt"): Assimp 5.2.5 sized the
      // array 0 and its accessor read through a null pointer (found by fuzz_mesh_load).
      {"collada_array_without_count.dae", ErrorCode::kParseError, "Collada <float_array> at byte 981 has no count attribute"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.file);
    const Thrown thrown = thrownBy([&] { loadMesh(badFile(c.file)); });
    EXPECT_EQ(thrown.code, c.code) << errorCodeName(thrown.code) << ": " << thrown.message;
    EXPECT_NE(thrown.message.find(c.file), std::string::npos) << thrown.message;
    EXPECT_NE(thrown.message.find(c.culprit), std::string::npos) << thrown.message;
  }
}

TEST(LoadMesh, OffContentGoesToTheStrictReaderWhateverTheExtension) {
  const std::string off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n";
  for (const char* hint : {"off", "xyz", "glb"}) {  // glb: a crash found by fuzz_mesh_load
    SCOPED_TRACE(hint);
    const Thrown thrown = thrownBy([&] { loadMeshFromMemory(asBytes(off), hint); });
    EXPECT_EQ(thrown.code, ErrorCode::kIndexOutOfRange);
    EXPECT_NE(thrown.message.find("line 6: face 0: vertex index 9 >= vertex count 3"), std::string::npos) << thrown.message;
  }
}

TEST(LoadMesh, PlyContentIsCheckedWhateverTheExtension) {
  // Assimp sniffs PLY content in files with unknown extensions; the guard must follow it.
  const std::string ply = readBytes(badFile("ply_no_end_header.ply"));
  for (const char* hint : {"ply", "xyz", "obj"}) {
    SCOPED_TRACE(hint);
    const Thrown thrown = thrownBy([&] { loadMeshFromMemory(asBytes(ply), hint); });
    EXPECT_EQ(thrown.code, ErrorCode::kParseError);
    EXPECT_NE(thrown.message.find("end_header"), std::string::npos) << thrown.message;
  }
}

TEST(LoadMesh, ColladaArraysMustHoldTheValuesTheirCountSays) {
  // Oracle: box_z_up.dae's positions hold 24 numbers. Assimp 5.2.5 sizes an array by its count
  // and crashed on 0, -1 and "abc" (an empty array its accessor reads); every other mismatch is
  // a malformed file all the same.
  const std::string good = readBytes(goodFile("box_z_up.dae"));
  const std::string attribute = "count=\"24\">-5";
  ASSERT_NE(good.find(attribute), std::string::npos);
  EXPECT_NO_THROW(loadMeshFromMemory(asBytes(good), "dae"));
  for (const char* count : {"0", "-1", "abc", "", "20", "30", "99999999999"}) {
    SCOPED_TRACE(count);
    std::string dae = good;
    dae.replace(dae.find(attribute), attribute.size(), "count=\"" + std::string(count) + "\">-5");
    const Thrown thrown = thrownBy([&] { loadMeshFromMemory(asBytes(dae), "dae"); });
    EXPECT_EQ(thrown.code, ErrorCode::kParseError);
    EXPECT_NE(thrown.message.find("Collada <float_array>"), std::string::npos) << thrown.message;
  }
  std::string emptied = good;  // no values at all, count 0: its accessor still reads it
  const std::size_t from = emptied.find(attribute), to = emptied.find("</float_array>", from);
  emptied.replace(from, to - from, "count=\"0\">");
  const Thrown thrown = thrownBy([&] { loadMeshFromMemory(asBytes(emptied), "dae"); });
  EXPECT_EQ(thrown.code, ErrorCode::kParseError);
  EXPECT_NE(thrown.message.find("count=\"0\" but holds 0 values"), std::string::npos) << thrown.message;
}

TEST(LoadMesh, ColladaContentIsCheckedWhateverTheExtension) {
  // Assimp recognises Collada by content; a '.' among integer indices hangs it just the same.
  std::string dae = readBytes(badFile("collada_letter_in_index_list.dae"));
  dae[dae.find("0 4 x 2") + 4] = '.';
  for (const char* hint : {"dae", "xml", "obj"}) {
    SCOPED_TRACE(hint);
    const Thrown thrown = thrownBy([&] { loadMeshFromMemory(asBytes(dae), hint); });
    EXPECT_EQ(thrown.code, ErrorCode::kParseError);
    EXPECT_NE(thrown.message.find("Collada <p>"), std::string::npos) << thrown.message;
  }
}

TEST(LoadMesh, MissingFileAndDirectoryAreRejected) {
  Thrown missing = thrownBy([] { loadMesh(badFile("does_not_exist.obj")); });
  EXPECT_EQ(missing.code, ErrorCode::kFileNotFound);
  EXPECT_NE(missing.message.find("does_not_exist.obj"), std::string::npos);
  Thrown directory = thrownBy([] { loadMesh(std::string(CLOD_TEST_DATA_DIR) + "/bad"); });
  EXPECT_EQ(directory.code, ErrorCode::kFileUnreadable);
  EXPECT_NE(directory.message.find("directory"), std::string::npos);
}

TEST(LoadMeshFromMemory, RejectsEmptyBytesAndBadHints) {
  EXPECT_EQ(thrownBy([] { loadMeshFromMemory({}, "obj"); }).code, ErrorCode::kEmptyFile);
  const std::string obj = readBytes(goodFile("box.obj"));
  EXPECT_EQ(thrownBy([&] { loadMeshFromMemory(asBytes(obj), ""); }).code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(thrownBy([&] { loadMeshFromMemory(asBytes(obj), "../obj"); }).code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(thrownBy([&] { loadMeshFromMemory(asBytes(obj), "averyveryverylongextension"); }).code,
            ErrorCode::kInvalidArgument);
  MeshLoadOptions nanOptions;
  nanOptions.weldToleranceRel = std::nan("");
  EXPECT_EQ(thrownBy([&] { loadMeshFromMemory(asBytes(obj), "obj", nanOptions); }).code, ErrorCode::kInvalidArgument);
}

TEST(LoadMeshFromMemory, BinaryStlWithNanCoordinateIsRejected) {
  std::string stl = readBytes(goodFile("box_binary.stl"));
  ASSERT_EQ(stl.size(), 84u + 12u * 50u);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(stl.data() + 84 + 5 * 50 + 12 + 4, &nan, sizeof nan);  // triangle 5, first corner, y
  const Thrown thrown = thrownBy([&] { loadMeshFromMemory(asBytes(stl), "stl"); });
  EXPECT_EQ(thrown.code, ErrorCode::kNonFiniteVertex);
  EXPECT_NE(thrown.message.find("nan"), std::string::npos) << thrown.message;
}

TEST(LoadMesh, ConcurrentLoadsAllSucceed) {
  std::vector<std::thread> threads;
  std::vector<int> ok(4, 0);
  for (int i = 0; i < 4; ++i)
    threads.emplace_back([&, i] {
      for (int k = 0; k < 5; ++k) ok[i] += loadMesh(goodFile(i % 2 ? "box.glb" : "box.obj")).mesh.triangleCount() == 12;
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(ok, (std::vector<int>{5, 5, 5, 5}));
}

}  // namespace
}  // namespace clod
