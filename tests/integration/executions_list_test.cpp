// GET /v1/executions through a real colorlabd on its embedded simulated lab: what ran is listed newest
// first, filtered by status (one or several) and campaign, paged across a cursor that keeps the filters,
// with a read key; a bad status or limit is a 400 problem naming the parameter; and the CLI lists it too.
#include <algorithm>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "resume_support.hpp"

using colorlab::client::ApiClient;
using colorlab::client::Endpoint;
using colorlab::testing::DaemonProcess;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

std::vector<std::string> ids_of(const json& items) {
  std::vector<std::string> out;
  for (const auto& e : items) out.push_back(e["id"].get<std::string>());
  return out;
}

}  // namespace

TEST(executions_list, FiltersPagesAndRefusesABadStatus) {
  TempDir dir;
  DaemonProcess daemon(dir / "state", colorlab::testing::write_daemon_config(dir.path(), 100, 7));
  auto api = colorlab::testing::api_for(daemon);

  // Two short spot readings to their end, then a long one aborted as soon as it has started.
  std::vector<std::string> started;
  for (int i = 0; i < 2; ++i) {
    auto e = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", 2}}}});
    started.push_back(e["id"].get<std::string>());
    ASSERT_EQ(colorlab::testing::wait_terminal(api, e["id"].get<std::string>())["status"], "finished_ok");
  }
  auto long_one = api.post("/v1/executions", {{"campaign", "luminance-spot"}, {"params", {{"readings", 1000}}}});
  started.push_back(long_one["id"].get<std::string>());
  const std::string long_id = long_one["id"].get<std::string>();
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::string status;
  while ((status = api.get("/v1/executions/" + long_id)["status"].get<std::string>()) == "waiting") {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the long execution never left 'waiting'";
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(status, "running");
  api.post("/v1/executions/" + long_id + "/abort", json::object());
  ASSERT_EQ(colorlab::testing::wait_terminal(api, long_one["id"].get<std::string>())["status"], "aborted");
  std::reverse(started.begin(), started.end());  // newest first

  // A read key over loopback TCP is enough.
  auto key = api.post("/v1/keys", {{"name", "reader"}, {"scope", "read"}});
  auto reader = ApiClient(Endpoint::from_url(daemon.url())).with_api_key(key["secret"].get<std::string>());

  auto all = reader.get("/v1/executions");
  EXPECT_EQ(ids_of(all["items"]), started);
  EXPECT_TRUE(all["next_cursor"].is_null());
  EXPECT_TRUE(all["links"]["next"].is_null());
  // Each item is the execution's own document.
  for (const auto& item : all["items"]) {
    auto one = reader.get("/v1/executions/" + item["id"].get<std::string>());
    EXPECT_EQ(item, one);
  }

  auto finished = reader.get("/v1/executions?status=finished_ok");
  EXPECT_EQ(ids_of(finished["items"]), (std::vector<std::string>{started[1], started[2]}));
  auto aborted = reader.get("/v1/executions?status=aborted&campaign=luminance-spot");
  EXPECT_EQ(ids_of(aborted["items"]), std::vector<std::string>{started[0]});
  auto either = reader.get("/v1/executions?status=aborted,finished_ok");
  EXPECT_EQ(ids_of(either["items"]), started);
  EXPECT_TRUE(reader.get("/v1/executions?campaign=frame-average")["items"].empty());
  EXPECT_TRUE(reader.get("/v1/executions?status=running")["items"].empty());

  // Pages of one, following links.next, which keeps the filter.
  std::vector<std::string> paged;
  std::string target = "/v1/executions?limit=1&status=aborted,finished_ok";
  for (int pages = 0; pages < 10; ++pages) {
    auto page = reader.get(target);
    ASSERT_LE(page["items"].size(), 1u);
    for (const auto& id : ids_of(page["items"])) paged.push_back(id);
    if (page["links"]["next"].is_null()) break;
    target = page["links"]["next"].get<std::string>();
    EXPECT_NE(target.find("status=aborted%2Cfinished_ok"), std::string::npos) << target;
  }
  EXPECT_EQ(paged, started);

  for (const char* bad : {"/v1/executions?status=done", "/v1/executions?status=running,", "/v1/executions?limit=0",
                          "/v1/executions?cursor=xyz"}) {
    auto r = reader.request("GET", bad);
    EXPECT_EQ(r.status, 400) << bad << ": " << r.body;
    EXPECT_EQ(r.content_type, "application/problem+json") << bad;
    auto body = json::parse(r.body, nullptr, false);
    std::string named = std::string(bad).substr(std::string(bad).find('?') + 1);
    named = named.substr(0, named.find('='));
    EXPECT_NE(body.value("detail", std::string()).find(named), std::string::npos) << bad << ": " << r.body;
  }

  // The CLI: the same list, filtered.
  auto cli = colorlab::testing::run_command({colorlab::testing::bin_path("colorlab"), "--socket", daemon.unix_socket(),
                                             "--json", "executions", "--status", "aborted"});
  ASSERT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_EQ(ids_of(json::parse(cli.out)["items"]), std::vector<std::string>{started[0]});
  auto text = colorlab::testing::run_command({colorlab::testing::bin_path("colorlab"), "--socket", daemon.unix_socket(),
                                              "executions", "--campaign", "luminance-spot"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (const auto& id : started) EXPECT_NE(text.out.find(id), std::string::npos) << text.out;
  auto bad = colorlab::testing::run_command({colorlab::testing::bin_path("colorlab"), "--socket", daemon.unix_socket(),
                                             "executions", "--status", "done"});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE((bad.out + bad.err).find("status"), std::string::npos) << bad.out << bad.err;
}
