// The web console's static files: "/" is index.html, nothing outside the console directory is
// reachable, the API prefix is never shadowed, caching revalidates.
#include <fstream>
#include <gtest/gtest.h>

#include "colorlab/api/console_files.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::daemon::serve_console;
using colorlab::http::HttpRequest;
using colorlab::testing::TempDir;

namespace {

HttpRequest get(const std::string& path) {
  HttpRequest r;
  r.method = "GET";
  r.path = path;
  r.target = path;
  return r;
}

void write(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

class ConsoleFiles : public ::testing::Test {
 protected:
  TempDir tmp;
  std::filesystem::path dir = tmp.path() / "console";
  void SetUp() override {
    write(dir / "index.html", "<!doctype html><title>colorlab</title>");
    write(dir / "js" / "app.js", "console.log(1)");
    write(dir / ".hidden", "x");
    write(tmp.path() / "secret.txt", "the state directory's neighbour");
  }
};

TEST_F(ConsoleFiles, RootIsTheIndexAsHtml) {
  auto r = serve_console(get("/"), dir);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->content_type, "text/html; charset=utf-8");
  ASSERT_TRUE(r->file);
  EXPECT_EQ(r->file->length, std::string("<!doctype html><title>colorlab</title>").size());
  EXPECT_EQ(r->headers.at("Cache-Control"), "no-cache");
}

TEST_F(ConsoleFiles, ScriptsHaveTheirTypeAndAnEtagThatRevalidates) {
  auto r = serve_console(get("/js/app.js"), dir);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->content_type, "text/javascript; charset=utf-8");
  auto again = get("/js/app.js");
  again.headers["if-none-match"] = r->headers.at("ETag");
  auto cached = serve_console(again, dir);
  ASSERT_TRUE(cached);
  EXPECT_EQ(cached->status, 304);
  EXPECT_FALSE(cached->file);
}

TEST_F(ConsoleFiles, NothingOutsideTheDirectoryNorHiddenIsServed) {
  for (const char* path : {"/../secret.txt", "/js/../../secret.txt", "/.hidden", "/missing.html", "/js"}) {
    auto r = serve_console(get(path), dir);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path;
    EXPECT_FALSE(r->file) << path;
  }
}

TEST_F(ConsoleFiles, TheApiPrefixIsNeverShadowed) {
  write(dir / "v1" / "runs", "a console file must not answer for the API");
  EXPECT_FALSE(serve_console(get("/v1"), dir));
  EXPECT_FALSE(serve_console(get("/v1/runs"), dir));
}

TEST_F(ConsoleFiles, WritesAreRefused) {
  auto req = get("/index.html");
  req.method = "POST";
  auto r = serve_console(req, dir);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 405);
  EXPECT_EQ(r->headers.at("Allow"), "GET, HEAD");
}

}  // namespace
