// Issue 25: what did not come up is listed as absent with its reason, and a campaign that needs only an
// absent instrument is refused naming it — the registry's rules, on a fake meter whose state and port the
// test sets.
#include <fstream>

#include <boost/asio/io_context.hpp>
#include <gtest/gtest.h>

#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace {

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::campaigns::AbsentInstrument;
using colorlab::campaigns::InstrumentSet;
namespace drivers = colorlab::drivers;

class FakeMeter final : public drivers::LuminanceMeter {
 public:
  FakeMeter(std::string id, std::string port) : id_(std::move(id)), port_(std::move(port)) {}
  const std::string& id() const override { return id_; }
  drivers::Identity identity() const override { return {"ls110", "Konica Minolta LS-110", "", "", port_, false}; }
  drivers::InstrumentState state() const override { return state_; }
  std::vector<drivers::Capability> capabilities() const override { return {drivers::Capability::luminance}; }
  std::string last_problem() const override { return problem_; }
  boost::asio::awaitable<void> connect() override { co_return; }
  void disconnect() override { state_ = drivers::InstrumentState::disconnected; }
  boost::asio::awaitable<drivers::LuminanceReading> measure_luminance() override { co_return drivers::LuminanceReading{}; }

  drivers::InstrumentState state_ = drivers::InstrumentState::disconnected;
  std::string problem_;

 private:
  std::string id_, port_;
};

nlohmann::json item(const InstrumentSet& set, const std::string& id) {
  for (const auto& i : set.describe_all()) {
    if (i["id"] == id) return i;
  }
  return nullptr;
}

}  // namespace

TEST(InstrumentSet, ADriverIsAbsentWhileItsPortIsNotThereOrItsConnectionFailed) {
  colorlab::testing::TempDir dir;
  auto port = dir / "ttyUSB-meter";
  auto meter = std::make_shared<FakeMeter>("meter", port.string());
  InstrumentSet set;
  set.add(meter);

  auto j = item(set, "meter");
  EXPECT_EQ(j["state"], "absent");
  EXPECT_NE(j["reason"].get<std::string>().find(port.string() + " is not there"), std::string::npos) << j.dump();
  EXPECT_TRUE(InstrumentSet::port_missing(*meter));

  std::ofstream(port) << "";  // plugged in, not yet connected: merely disconnected
  j = item(set, "meter");
  EXPECT_EQ(j["state"], "disconnected");
  EXPECT_FALSE(j.contains("reason"));
  EXPECT_FALSE(InstrumentSet::port_missing(*meter));

  meter->problem_ = "LS-110 did not answer 3 times";  // its connection failed on a port that is there
  j = item(set, "meter");
  EXPECT_EQ(j["state"], "absent");
  EXPECT_EQ(j["reason"], "LS-110 did not answer 3 times");
  EXPECT_FALSE(InstrumentSet::port_missing(*meter)) << "retried at the campaign's call, not refused at its start";

  meter->state_ = drivers::InstrumentState::fault;  // up and failing is a fault with its problem, not absence
  EXPECT_EQ(item(set, "meter")["state"], "fault");
  meter->state_ = drivers::InstrumentState::ready;
  EXPECT_EQ(item(set, "meter")["state"], "ready");
}

TEST(InstrumentSet, EntriesWithoutADriverAreListedOnceAfterTheDrivers) {
  InstrumentSet set;
  set.add(std::make_shared<FakeMeter>("meter", "/dev/null"));
  set.add_absent(AbsentInstrument{"genicam", "genicam", "127.0.0.1", true, "GVCP port taken"});
  set.add_absent(AbsentInstrument{"genicam", "genicam", "127.0.0.1", true, "a later reason"});
  set.add_absent(AbsentInstrument{"meter", "ls110", "/dev/null", false, "the driver speaks for itself"});
  auto all = set.describe_all();
  ASSERT_EQ(all.size(), 2u) << all.dump();
  EXPECT_EQ(all[0]["id"], "meter");
  EXPECT_EQ(all[1]["id"], "genicam");
  EXPECT_EQ(all[1]["state"], "absent");
  EXPECT_EQ(all[1]["reason"], "GVCP port taken");
  EXPECT_TRUE(all[1]["simulated"]);
  EXPECT_TRUE(all[1]["capabilities"].empty());
}

TEST(InstrumentSet, ACampaignNeedingOnlyAnAbsentInstrumentIsRefusedNamingItAndItsReason) {
  colorlab::testing::TempDir dir;
  boost::asio::io_context io;
  InstrumentSet set;
  auto meter = std::make_shared<FakeMeter>("meter", (dir / "not-plugged-in").string());
  set.add(meter);
  set.add_absent(AbsentInstrument{"genicam", "genicam", "127.0.0.1", true, "GVCP port taken"});
  colorlab::campaigns::Lab lab(io.get_executor(), set, {});

  auto refusal = [&](const std::string& role) -> std::string {
    try {
      lab.check_needs({role});
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::not_found);
      EXPECT_FALSE(e.hint().empty());
      return e.what();
    }
    return "accepted";
  };
  auto camera = refusal("camera");
  EXPECT_NE(camera.find("'genicam' is configured but absent: GVCP port taken"), std::string::npos) << camera;
  auto meter_refusal = refusal("luminance_meter");
  EXPECT_NE(meter_refusal.find("'meter' is configured but absent"), std::string::npos) << meter_refusal;
  EXPECT_NE(refusal("table").find("none is configured"), std::string::npos);

  std::ofstream(dir / "not-plugged-in") << "";  // plugged in: it may connect at the campaign's call
  EXPECT_EQ(refusal("luminance_meter"), "accepted");
}
