// `clod view`: the static HTTP server behind the web viewer. Starts the built CLI on port 0 with
// a stand-in viewer folder and output folder, talks raw HTTP/1.1 to it over a socket, and
// checks the answers against the files on disk (the oracle): bytes, Content-Type, status codes,
// refusal of every path that would leave the served folders, and a clean stop on SIGTERM.
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_runner.h"
#include "cli/view_harness.h"

namespace {

namespace fs = std::filesystem;
using clod::test::quoted;
using clod::test::runCli;
using namespace clod::test::view;

class ClodView : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("clod_view_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    writeFile(root_ / "viewer" / "index.html", "<!doctype html><title>stand-in viewer</title>\n");
    writeFile(root_ / "viewer" / "assets" / "app.js", "console.log('stand-in');\n");
    std::string glb("glTF\x02\0\0\0", 8);
    for (int i = 0; i < 70000; ++i) glb += char(i * 7 % 256);  // binary, with NULs, > one socket buffer
    writeFile(root_ / "out" / "scene.glb", glb);
    writeFile(root_ / "out" / "layers.json", R"({"format":"clod-layers","version":1})");
    writeFile(root_ / "out" / "trajectory.csv", "step,time\n0,0\n");
    writeFile(root_ / "out" / "my plot.svg", "<svg xmlns='http://www.w3.org/2000/svg'/>");
    writeFile(root_ / kSecretName, kSecret);
    fs::create_directory_symlink(root_, root_ / "out" / "escape");  // a link leaving the root
    server_ = startServer({(root_ / "out").string(), "--port", "0", "--viewer-dir", (root_ / "viewer").string(),
                           "--quit-after", "600"});
  }
  static void TearDownTestSuite() {
    stopServer(server_);
    fs::remove_all(root_);
  }

  static inline fs::path root_;
  static inline Server server_;
  static constexpr const char* kSecretName = "secret.txt";
  static constexpr const char* kSecret = "do-not-serve-7f3a9c";
};

TEST_F(ClodView, PrintsTheUrlWithTheChosenFreePort) {
  EXPECT_GT(server_.port, 0) << "first line: " << server_.firstLine;
}

TEST_F(ClodView, ServesTheViewerIndexAtTheRoot) {
  const HttpReply r = get(server_.port, "/");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.header("Content-Type"), "text/html; charset=utf-8");
  EXPECT_EQ(r.body, readFile(root_ / "viewer" / "index.html"));
  const HttpReply js = get(server_.port, "/assets/app.js?v=1");
  EXPECT_EQ(js.status, 200);
  EXPECT_EQ(js.header("Content-Type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(js.body, readFile(root_ / "viewer" / "assets" / "app.js"));
}

TEST_F(ClodView, ServesTheOutputFolderUnderDataByteForByte) {
  const HttpReply glb = get(server_.port, "/data/scene.glb");
  EXPECT_EQ(glb.status, 200);
  EXPECT_EQ(glb.header("Content-Type"), "model/gltf-binary");
  EXPECT_EQ(glb.header("Content-Length"), std::to_string(fs::file_size(root_ / "out" / "scene.glb")));
  EXPECT_TRUE(glb.body == readFile(root_ / "out" / "scene.glb"));
  const HttpReply json = get(server_.port, "/data/layers.json");
  EXPECT_EQ(json.status, 200);
  EXPECT_EQ(json.header("Content-Type"), "application/json");
  EXPECT_EQ(json.body, readFile(root_ / "out" / "layers.json"));
  EXPECT_EQ(get(server_.port, "/data/trajectory.csv").header("Content-Type"), "text/csv; charset=utf-8");
  const HttpReply svg = get(server_.port, "/data/my%20plot.svg");  // percent-decoded name
  EXPECT_EQ(svg.status, 200);
  EXPECT_EQ(svg.header("Content-Type"), "image/svg+xml");
}

TEST_F(ClodView, AnswersHeadWithTheHeadersOfGetAndNoBody) {
  const HttpReply r = get(server_.port, "/data/scene.glb", "HEAD");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.header("Content-Length"), std::to_string(fs::file_size(root_ / "out" / "scene.glb")));
  EXPECT_EQ(r.header("Content-Type"), "model/gltf-binary");
  EXPECT_TRUE(r.body.empty()) << r.body.size() << " body bytes";
}

TEST_F(ClodView, AnswersMissingFilesWith404) {
  EXPECT_EQ(get(server_.port, "/data/nothing.json").status, 404);
  EXPECT_EQ(get(server_.port, "/nothing.js").status, 404);
  EXPECT_EQ(get(server_.port, "/data/").status, 404);  // no directory listings
}

TEST_F(ClodView, RefusesEveryPathThatLeavesTheServedFolders) {
  for (const std::string target :
       {"/data/../secret.txt", "/../secret.txt", "/data/%2e%2e/secret.txt", "/data/..%2fsecret.txt",
        "/data/%2E%2E%2Fsecret.txt", "/data/..\\secret.txt", "/data//../secret.txt", "/data/escape/secret.txt",
        "/data/./../secret.txt", "secret.txt", "/data/%00/../secret.txt"}) {
    const HttpReply r = get(server_.port, target);
    EXPECT_GE(r.status, 400) << target;
    EXPECT_LT(r.status, 500) << target;
    EXPECT_EQ(r.body.find(kSecret), std::string::npos) << target;
  }
}

TEST_F(ClodView, AnswersOtherMethodsWith405AndMalformedRequestsWith400) {
  const HttpReply post = get(server_.port, "/data/scene.glb", "POST");
  EXPECT_EQ(post.status, 405);
  EXPECT_EQ(post.header("Allow"), "GET, HEAD");
  EXPECT_EQ(request(server_.port, "garbage\r\n\r\n").status, 400);
  EXPECT_EQ(get(server_.port, "/data/%zz").status, 400);
}

TEST_F(ClodView, StopsCleanlyOnSigint) {
  Server own = startServer({(root_ / "out").string(), "--port", "0", "--viewer-dir", (root_ / "viewer").string(),
                            "--quit-after", "120"});
  ASSERT_GT(own.port, 0) << own.firstLine;
  EXPECT_EQ(get(own.port, "/").status, 200);
  EXPECT_EQ(stopServer(own, SIGINT), 0);
}

TEST_F(ClodView, FailsWithExitCode1WhenTheOutputFolderOrSceneIsMissing) {
  const std::string viewer = " --viewer-dir " + quoted(root_ / "viewer") + " --port 0 --quit-after 5";
  const auto noFolder = runCli("view " + quoted(root_ / "no-such-folder") + viewer);
  EXPECT_EQ(noFolder.exitCode, 1);
  EXPECT_NE(noFolder.err.find("no-such-folder"), std::string::npos) << noFolder.err;
  const auto noScene = runCli("view " + quoted(root_ / "viewer") + viewer);  // a folder without scene.glb
  EXPECT_EQ(noScene.exitCode, 1);
  EXPECT_NE(noScene.err.find("scene.glb"), std::string::npos) << noScene.err;
}

TEST_F(ClodView, FailsWithExitCode1WhenTheViewerIsNotBuilt) {
  const auto r = runCli("view " + quoted(root_ / "out") + " --viewer-dir " + quoted(root_ / "out") +
                        " --port 0 --quit-after 5");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("viewer not built: run scripts/build-viewer.sh"), std::string::npos) << r.err;
  ::setenv("CLOD_VIEWER_DIR", (root_ / "no-viewer-here").c_str(), 1);
  const auto fromEnv = runCli("view " + quoted(root_ / "out") + " --port 0 --quit-after 5");
  ::unsetenv("CLOD_VIEWER_DIR");
  EXPECT_EQ(fromEnv.exitCode, 1);
  EXPECT_NE(fromEnv.err.find("no-viewer-here"), std::string::npos) << fromEnv.err;
}

TEST_F(ClodView, FailsWithExitCode2OnAnOutOfRangePort) {
  const auto r = runCli("view " + quoted(root_ / "out") + " --viewer-dir " + quoted(root_ / "viewer") +
                        " --port 70000 --quit-after 5");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("--port"), std::string::npos) << r.err;
}

}  // namespace
