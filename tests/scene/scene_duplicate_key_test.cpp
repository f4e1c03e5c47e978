// A key given twice in one object is an error naming its path: nlohmann::json would keep the
// last value without a word.
#include <string>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/scene.h"

namespace clod {
namespace {

std::string sceneError(const std::string& json) {
  try {
    parseScene(json, ".", "t.json");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kSceneError) << e.what();
    return e.what();
  }
  return "no error";
}

TEST(SceneDuplicateKeys, AtTopLevelNamesTheKey) {
  EXPECT_EQ(sceneError(R"({"dt": 0.01, "bodies": [], "dt": 0.1})"), "t.json: dt: duplicate key");
}

TEST(SceneDuplicateKeys, InsideBodiesNamesTheKeyPath) {
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1]}, {"box": [1,1,1], "name": "a", "name": "b"}]})"),
            "t.json: bodies[1].name: duplicate key");
  EXPECT_EQ(sceneError(R"({"bodies": [[0, [1]], {"box": [1,1,1], "bake": {"depth": 2, "depth": 3}}]})"),
            "t.json: bodies[1].bake.depth: duplicate key");
}

TEST(SceneDuplicateKeys, EqualKeysInDifferentObjectsAreFine) {
  EXPECT_EQ(sceneError(R"({"bodies": [{"box": [1,1,1], "name": "a"}, {"box": [1,1,1], "name": "b"}]})"), "no error");
}

}  // namespace
}  // namespace clod
