// Replays one transcript file (tests/transcripts/*.jsonl, or one colorlab doctor just wrote) against
// the real drivers: a ReplayPeer plays the device's recorded bytes on a pty, colorlab doctor's own
// examination runs on it with the recorded plan, and the values the driver decodes must equal the
// transcript's expected values — the operator's (or the simulator's ground truth), never the
// decoding stored at recording time. Exit 0 when they agree, 1 with every reason when not.
#include <chrono>
#include <future>
#include <iostream>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/bringup/examine.hpp"
#include "colorlab/bringup/transcript_file.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/bringup/relay_check.hpp"
#include "replay_hid.hpp"
#include "replay_peer.hpp"

namespace bu = colorlab::bringup;
using nlohmann::json;

namespace {

// Deadlines four times doctor's own: a replay on a loaded CI machine must not time out where the
// recorded device answered; a silent step of the recording only costs its longer deadline.
constexpr double kDeadlineScale = 4.0;
// Far beyond any examination's deadlines (each bounded, see handshake.hpp/examine.cpp): a hang guard.
constexpr auto kHardLimit = std::chrono::seconds(300);

int report(const std::string& file, const bu::TranscriptFile& t, std::vector<std::string> problems, const json& decoded,
           std::size_t events) {
  for (const auto& [key, want] : t.expected.items()) {
    auto why = bu::compare_expected(key, want, decoded.value(key, json()));
    if (!why.empty()) problems.push_back(why);
  }
  if (problems.empty()) {
    std::cout << file << ": " << t.expected.size() << " expected values (" << t.expected_source << ") decoded by the driver from "
              << events << " recorded byte events\n";
    return 0;
  }
  std::cerr << file << ": the replay disagrees with the transcript:\n";
  for (const auto& p : problems) std::cerr << "  - " << p << "\n";
  std::cerr << "  decoded now: " << decoded.dump() << "\n";
  return 1;
}

// A relay board's transcript: its feature reports played to the relay driver as a HID device.
int replay_hid(const std::string& file, const bu::TranscriptFile& t) {
  const json h = t.header.value("hid", json::object());
  colorlab::drivers::HidDeviceInfo info;
  info.path = t.header.value("port", std::string());
  info.product = h.value("product", std::string());
  info.manufacturer = h.value("manufacturer", std::string());
  info.serial = h.value("serial", std::string());
  info.vendor_id = h.value("vendor_id", std::uint16_t{0});
  info.product_id = h.value("product_id", std::uint16_t{0});
  auto transport = std::make_unique<colorlab::test::ReplayHidTransport>(t.events, info);
  auto progress = transport->progress();
  auto r = bu::identify_relay(std::move(transport), info.path);
  std::vector<std::string> problems;
  if (!progress->mismatch.empty()) problems.push_back(progress->mismatch);
  if (progress->position != progress->size) {
    problems.push_back("the driver stopped after " + std::to_string(progress->position) + " of the transcript's " +
                       std::to_string(progress->size) + " byte events (verdict " + r.value("verdict", std::string()) + ": " +
                       r.value("message", std::string()) + ")");
  }
  json decoded = json::object();
  for (const char* key : {"board_id", "relays", "relays_on"}) {
    if (r.contains(key)) decoded[key] = r[key];
  }
  return report(file, t, problems, decoded, progress->size);
}

int replay(const std::string& file) {
  auto t = bu::read_transcript(file);
  std::vector<std::string> problems;
  if (t.expected.empty()) {
    std::cerr << file << ": no expected values — a transcript becomes a test once an operator (or the simulator's ground "
                         "truth) has confirmed what the instrument showed; fill its \"expected\" line\n";
    return 1;
  }
  const std::string transport = t.header.value("transport", std::string("serial"));
  if (transport == "hid") return replay_hid(file, t);
  if (transport != "serial") {
    std::cerr << file << ": transport '" << transport << "' cannot be replayed by this colorlab (it replays serial and hid)\n";
    return 1;
  }
  const json plan = t.header.value("plan", json::object());
  bu::ExamineOptions o;
  o.expect = plan.value("expect", std::string());
  o.measure = plan.value("measure", false);
  o.deadline_scale = kDeadlineScale;
  if (plan.contains("order") && plan["order"] != json(bu::probe_order(o.expect))) {
    problems.push_back("the recording probed in the order " + plan["order"].dump() + ", this colorlab probes " +
                       json(bu::probe_order(o.expect)).dump());
  }

  boost::asio::io_context io;
  auto peer = std::make_shared<colorlab::test::ReplayPeer>(io, t.events);
  peer->start();
  bu::Recording recording;
  auto fut = boost::asio::co_spawn(io, bu::examine_port(io.get_executor(), peer->path(), o, recording), boost::asio::use_future);
  const auto deadline = std::chrono::steady_clock::now() + kHardLimit;
  while (fut.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    io.run_one_for(std::chrono::milliseconds(50));
    if (std::chrono::steady_clock::now() > deadline) {
      std::cerr << file << ": the examination did not finish within " << kHardLimit.count() << " s (a hang)\n";
      return 1;
    }
  }
  auto x = fut.get();
  peer->stop();

  if (!peer->mismatch().empty()) problems.push_back(peer->mismatch());
  if (!peer->done()) {
    problems.push_back("the driver stopped after " + std::to_string(peer->position()) + " of the transcript's " +
                       std::to_string(peer->size()) + " byte events (verdict " + x.verdict + ": " + x.message + ")");
  }
  return report(file, t, problems, x.decoded, peer->size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: transcript_replay FILE.jsonl\n";
    return 2;
  }
  try {
    return replay(argv[1]);
  } catch (const colorlab::Error& e) {
    std::cerr << argv[1] << ": " << e.what() << "\n";
    if (!e.hint().empty()) std::cerr << "  hint: " << e.hint() << "\n";
    return 1;
  }
}
