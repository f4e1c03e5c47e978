// glTF JSON nested deeper than MeshLoadOptions::maxJsonDepth is refused before Assimp's
// recursive parser sees it (200,000 levels overflowed its stack: exit 139).
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/mesh_io.h"
#include "mesh/text_index_check.h"
#include "mesh_test_support.h"

namespace clod {
namespace {

using test::badFile;
using test::goodFile;

std::string nested(std::size_t depth) {
  return R"({"asset": {"version": "2.0"}, "extras": )" + std::string(depth, '[') + std::string(depth, ']') + "}";
}

// A GLB (glTF 2.0 "Binary glTF Layout") holding `json` as its only chunk.
std::string glbOf(std::string json) {
  while (json.size() % 4 != 0) json += ' ';
  std::string glb = "glTF";
  auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) glb += char((v >> (8 * i)) & 0xff);
  };
  u32(2);
  u32(std::uint32_t(12 + 8 + json.size()));
  u32(std::uint32_t(json.size()));
  u32(0x4E4F534A);  // "JSON"
  return glb + json;
}

std::span<const std::byte> bytesOf(const std::string& text) {
  return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

// The message of the kParseError loading `call` throws; fails the test on any other outcome.
template <class F>
std::string parseError(F&& call) {
  try {
    call();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kParseError) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "loaded";
  return "";
}

TEST(JsonDepth, ScanCountsBracketsOutsideStringsOnly) {
  EXPECT_FALSE(detail::findJsonDepthProblem(R"({"a": [[1]]})", 3));
  EXPECT_TRUE(detail::findJsonDepthProblem(R"({"a": [[1]]})", 2));
  EXPECT_FALSE(detail::findJsonDepthProblem(R"({"a": "[[[[{{{{", "b": "\"[[["})", 1));
  const auto problem = detail::findJsonDepthProblem(nested(200000), 512);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("deeper than 512 levels"), std::string::npos) << *problem;
}

TEST(JsonDepth, DeepGltfFromMemoryIsAParseErrorNotACrash) {
  const std::string json = nested(200000);  // 400 kB
  EXPECT_NE(parseError([&] { loadMeshFromMemory(bytesOf(json), "gltf"); }).find("maxJsonDepth"), std::string::npos);
  const std::string glb = glbOf(json);
  EXPECT_NE(parseError([&] { loadMeshFromMemory(bytesOf(glb), "glb"); }).find("maxJsonDepth"), std::string::npos);
}

TEST(JsonDepth, DeepGltfFileIsAParseErrorWhateverItsExtension) {
  const std::string message = parseError([] { loadMesh(badFile("json_nested_too_deep.gltf")); });
  EXPECT_NE(message.find("json_nested_too_deep.gltf"), std::string::npos) << message;
  EXPECT_NE(message.find("deeper than 512"), std::string::npos) << message;
  // Assimp recognises glTF by content too, so the name does not matter.
  const auto path = std::filesystem::temp_directory_path() / ("clod_json_depth_" + std::to_string(::getpid()) + ".dat");
  std::ofstream(path) << std::string(100, ' ') << nested(200000);
  EXPECT_NE(parseError([&] { loadMesh(path); }).find("maxJsonDepth"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(JsonDepth, TheLimitIsAnOption) {
  EXPECT_GT(loadMesh(goodFile("box.gltf")).mesh.triangleCount(), 0u);
  MeshLoadOptions strict;
  strict.maxJsonDepth = 2;
  EXPECT_NE(parseError([&] { loadMesh(goodFile("box.gltf"), strict); }).find("deeper than 2"), std::string::npos);
  EXPECT_NE(parseError([&] { loadMesh(goodFile("box.glb"), strict); }).find("deeper than 2"), std::string::npos);
  // A larger limit lets the 600-deep file through to the importer, which finds no mesh in it.
  MeshLoadOptions lenient;
  lenient.maxJsonDepth = 1000;
  try {
    loadMesh(badFile("json_nested_too_deep.gltf"), lenient);
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find("maxJsonDepth"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace clod
