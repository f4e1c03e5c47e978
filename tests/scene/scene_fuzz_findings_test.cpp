// Inputs fuzz_scene_load (fuzz/, docs/testing.md) found to escape parseScene as something other
// than clod::Error(kSceneError); each stays here as a regression test.
#include <string>

#include <gtest/gtest.h>

#include "clod/error.h"
#include "clod/scene.h"

namespace clod {
namespace {

TEST(SceneFuzzFindings, ANumberBeyondADoubleIsASceneErrorNotAJsonException) {
  // nlohmann::json throws out_of_range (406), not parse_error, for a number it cannot hold.
  for (const std::string number : {"0.01E666666666666666", "-1e400", "1E+99999"}) {
    const std::string text = R"({"dt": )" + number + R"(, "bodies": []})";
    try {
      parseScene(text, ".", "t.json");
      ADD_FAILURE() << number << ": accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kSceneError) << e.what();
      EXPECT_NE(std::string(e.what()).find("t.json: not valid JSON"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace clod
