// `colorlab doctor` as an operator runs it, against ptys made here that answer nothing, garbage, or
// another instrument's protocol, and against colorlab-sim: a clear verdict each (exit code and the
// --json report), never a hang (each run bounded by the process limit below, far beyond doctor's
// own deadlines), nothing measured or lit unasked (the simulator's ground truth counts), and the
// operator's confirmed value — not colorlab's decoding — what the recorded transcript's replay asserts.
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/sim/pty.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::bin_path;
using testing::run_command;
using namespace std::string_literals;

// A hang guard, not a speed bound: doctor's own deadlines end a silent port in under 3 s.
constexpr auto kLimit = std::chrono::seconds(120);

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? "'\\''"s : std::string(1, c);
  return out + "'";
}

struct Doctor {
  int exit_code = -1;
  json report;
  std::string err;
  std::string out;
};

// Runs `colorlab --json doctor ARGS` with `stdin_text` on its standard input (never a terminal).
Doctor doctor(const std::vector<std::string>& args, const std::string& stdin_text = "", bool json_output = true) {
  std::string cmd = "printf %s " + shell_quote(stdin_text) + " | " + shell_quote(bin_path("colorlab")) + (json_output ? " --json" : "") +
                    " doctor --no-host --no-gige";
  for (const auto& a : args) cmd += " " + shell_quote(a);
  auto r = run_command({"/bin/sh", "-c", cmd}, kLimit);
  Doctor d{r.exit_code, json(), r.err, r.out};
  if (json_output) {
    try {
      d.report = json::parse(r.out);
    } catch (const json::exception&) {
      ADD_FAILURE() << "doctor did not print JSON (exit " << r.exit_code << "):\n"
                    << r.out << "\n"
                    << r.err;
    }
  }
  return d;
}

// Answers every read on a pty's master with `reply` (empty: reads and answers nothing), on its own
// thread until destroyed.
class PtyResponder {
 public:
  explicit PtyResponder(std::string reply) : reply_(std::move(reply)) {
    thread_ = std::thread([this] {
      char buf[512];
      while (!stop_) {
        pollfd p{pty_.master_fd(), POLLIN, 0};
        if (::poll(&p, 1, 50) <= 0) continue;
        if (::read(pty_.master_fd(), buf, sizeof buf) <= 0) continue;
        if (!reply_.empty()) (void)!::write(pty_.master_fd(), reply_.data(), reply_.size());
      }
    });
  }
  ~PtyResponder() {
    stop_ = true;
    thread_.join();
  }
  const std::string& path() const { return pty_.slave_path(); }

 private:
  sim::Pty pty_;
  std::string reply_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::vector<json> read_lines(const fs::path& p) {
  std::vector<json> out;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) out.push_back(json::parse(line));
  return out;
}

TEST(DoctorPorts, APortThatAnswersNothingIsSilentAndItsProbesAreRecorded) {
  testing::TempDir dir;
  PtyResponder nobody("");
  auto d = doctor({"--port", nobody.path(), "--record", (dir / "rec").string()});
  EXPECT_EQ(d.exit_code, 3) << d.err;
  ASSERT_EQ(d.report["ports"].size(), 1u) << d.report.dump(2);
  const auto& p = d.report["ports"][0];
  EXPECT_EQ(p["verdict"], "silent");
  EXPECT_NE(p["message"].get<std::string>().find("nothing answered"), std::string::npos) << p["message"];
  EXPECT_EQ(p["kind"], nullptr);
  EXPECT_FALSE(p.value("hint", "").empty());
  EXPECT_EQ(d.report["ok"], false);
  // The transcript holds each handshake colorlab sent (4: widget, LS-110, Spectrolino at 2 speeds) and no reply.
  auto lines = read_lines(p["transcript"].get<std::string>());
  int host = 0, device = 0;
  for (const auto& l : lines) {
    host += l.contains("host") ? 1 : 0;
    device += l.contains("device") ? 1 : 0;
  }
  EXPECT_EQ(host, 4);
  EXPECT_EQ(device, 0);
  EXPECT_EQ(lines.back()["expected"], json::object());
}

TEST(DoctorPorts, GarbageIsNoKnownProtocolAndSaysWhatCame) {
  testing::TempDir dir;
  PtyResponder noise("\x13\x37garbage\xff\r\n"s);
  auto d = doctor({"--port", noise.path(), "--record", (dir / "rec").string()});
  EXPECT_EQ(d.exit_code, 3) << d.err;
  ASSERT_EQ(d.report["ports"].size(), 1u);
  const auto& p = d.report["ports"][0];
  EXPECT_EQ(p["verdict"], "unknown_protocol");
  EXPECT_NE(p["message"].get<std::string>().find("no protocol colorlab knows"), std::string::npos) << p["message"];
  EXPECT_NE(p["message"].get<std::string>().find("13 37"), std::string::npos) << p["message"];
}

TEST(DoctorPorts, AnUnknownKindIsAUsageError) {
  auto d = doctor({"--port", "/dev/null=modem"}, "", false);
  EXPECT_EQ(d.exit_code, 1);  // a typed error, not a finding (3)
  EXPECT_NE(d.err.find("unknown instrument kind 'modem'"), std::string::npos) << d.err;
}

TEST(DoctorPorts, APathThatCannotBeOpenedSaysWhy) {
  auto d = doctor({"--port", "/nonexistent/ttyUSB9=ls110", "--no-record"});
  EXPECT_EQ(d.exit_code, 3);
  ASSERT_EQ(d.report["ports"].size(), 1u);
  EXPECT_EQ(d.report["ports"][0]["verdict"], "cannot_open");
  EXPECT_NE(d.report["ports"][0]["message"].get<std::string>().find("cannot open"), std::string::npos);
}

// colorlab-sim with its serial instruments (no GigE camera: that needs the loopback lock), its
// announcement read for the ports and its control channel for the ground truth.
class DoctorSimLab : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[relay]\nenabled = true\n";
    sim = std::make_unique<testing::Process>(
        std::vector<std::string>{bin_path("colorlab-sim"), "--config", (dir / "lab.toml").string(), "--seed", "7", "--time-scale",
                                 "1000", "--control", (dir / "sim.sock").string()},
        dir / "sim.log");
    auto line = sim->read_line(std::chrono::seconds(30));
    ASSERT_TRUE(line) << "colorlab-sim did not announce itself";
    auto a = json::parse(*line);
    for (const auto& i : a["instruments"]) {
      if (i.contains("port")) ports[i["kind"].get<std::string>()] = i["port"].get<std::string>();
    }
    ASSERT_TRUE(ports.count("ls110") && ports.count("spectrolino") && ports.count("dmx") && ports.count("hidrelay")) << a.dump();
  }
  json truth() {
    auto r = run_command({"/usr/bin/python3", "-c",
                          "import socket,sys;s=socket.socket(socket.AF_UNIX);s.connect(sys.argv[1]);"
                          "s.sendall(b'{\"cmd\":\"truth\"}\\n');b=b''\n"
                          "while not b.endswith(b'\\n'): b+=s.recv(65536)\n"
                          "print(b.decode())",
                          (dir / "sim.sock").string()},
                         std::chrono::seconds(30));
    return json::parse(r.out);
  }
  testing::TempDir dir;
  std::unique_ptr<testing::Process> sim;
  std::map<std::string, std::string> ports;
};

TEST_F(DoctorSimLab, EveryInstrumentAnswersItsOwnHandshakeAndNothingIsMeasuredUnasked) {
  auto before = truth();
  auto d = doctor({"--port", ports["ls110"] + "=ls110", "--port", ports["spectrolino"] + "=spectrolino", "--port",
                   ports["dmx"] + "=dmx", "--relay", ports["hidrelay"], "--record", (dir / "rec").string()});
  EXPECT_EQ(d.exit_code, 0) << d.report.dump(2);
  ASSERT_EQ(d.report["ports"].size(), 3u);
  std::map<std::string, json> by_kind;
  for (const auto& p : d.report["ports"]) {
    EXPECT_EQ(p["verdict"], "identified") << p.dump(2);
    EXPECT_EQ(p["kind"], p["expected_kind"]);
    EXPECT_FALSE(p["measured"].get<bool>());
    EXPECT_FALSE(p["calibration"].empty()) << p.dump(2);
    by_kind[p["kind"].get<std::string>()] = p;
  }
  auto after = truth();
  // Ground truth: the widget's serial as its label prints it, the table's serial; the control channel's counts.
  EXPECT_EQ(by_kind["dmx"]["identity"]["serial"], after["dmx"]["serial"]);
  EXPECT_EQ(by_kind["spectrolino"]["identity"]["table_serial"], after["spectrolino"]["table_serial"]);
  EXPECT_EQ(after["ls110"]["readings_served"], before["ls110"]["readings_served"]);
  EXPECT_EQ(after["spectrolino"]["measurements"], before["spectrolino"]["measurements"]);
  EXPECT_EQ(after["spectrolino"]["head_mm"], before["spectrolino"]["head_mm"]);
  EXPECT_EQ(after["dmx"]["packets"], before["dmx"]["packets"]);
  ASSERT_EQ(d.report["relays"].size(), 1u);
  EXPECT_EQ(d.report["relays"][0]["verdict"], "identified") << d.report["relays"].dump(2);
  EXPECT_EQ(d.report["relays"][0]["board_id"], after["relay"]["board_id"]);
  EXPECT_EQ(after["relay"]["mask"], before["relay"]["mask"]);  // read, not switched
  EXPECT_NE(d.report["readings"].get<std::string>().find("--measure"), std::string::npos);
}

// Rewrites a transcript's expected line (the last) with `expected`, as a person committing it would.
void set_expected(const fs::path& file, const json& expected, const std::string& source) {
  auto lines = read_lines(file);
  ASSERT_FALSE(lines.empty());
  ASSERT_TRUE(lines.back().contains("expected")) << lines.back().dump();
  lines.back() = {{"expected", expected}, {"source", source}};
  std::ofstream out(file, std::ios::trunc);
  for (const auto& l : lines) out << l.dump() << "\n";
}

// The relay board's HID feature reports land in the transcript like a serial port's bytes: the board
// id the simulator holds is in the device's answer, and with the simulator's ground truth filled in
// as its expected value the replay (a HID device played from the file) decodes it, and a wrong
// expected value fails it.
TEST_F(DoctorSimLab, TheRelayBoardsFeatureReportsAreRecordedAndReplay) {
  auto d = doctor({"--relay", ports["hidrelay"], "--record", (dir / "relay").string()});
  EXPECT_EQ(d.exit_code, 0) << d.report.dump(2) << d.err;
  ASSERT_EQ(d.report["relays"].size(), 1u);
  const auto& r = d.report["relays"][0];
  ASSERT_TRUE(r.contains("transcript")) << r.dump(2);
  const fs::path file = r["transcript"].get<std::string>();
  auto lines = read_lines(file);
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines[0]["transport"], "hid");
  const auto truth_id = truth()["relay"]["board_id"].get<std::string>();
  std::string id_hex;
  for (unsigned char c : truth_id) {
    static const char* digits = "0123456789abcdef";
    id_hex += digits[c >> 4];
    id_hex += digits[c & 15];
  }
  bool host = false, id_answered = false;
  for (const auto& l : lines) {
    host = host || l.contains("host");
    if (l.contains("device") && l["device"].get<std::string>().find(id_hex) != std::string::npos) id_answered = true;
  }
  EXPECT_TRUE(host) << "no GET_REPORT request recorded";
  EXPECT_TRUE(id_answered) << "the board id " << truth_id << " (" << id_hex << ") is in no recorded device answer";

  const auto replay = bin_path("../tests/transcript_replay");
  auto unconfirmed = run_command({replay, file.string()}, std::chrono::seconds(60));
  EXPECT_EQ(unconfirmed.exit_code, 1) << "an unconfirmed transcript is no test yet";
  set_expected(file, {{"board_id", {{"value", truth_id}}}}, "simulator ground truth (control channel truth.relay.board_id)");
  auto ok = run_command({replay, file.string()}, std::chrono::seconds(60));
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  set_expected(file, {{"board_id", {{"value", "XXXXX"}}}}, "a wrong value");
  auto wrong = run_command({replay, file.string()}, std::chrono::seconds(60));
  EXPECT_EQ(wrong.exit_code, 1) << wrong.out << wrong.err;
  EXPECT_NE(wrong.err.find("board_id"), std::string::npos) << wrong.err;
}

TEST_F(DoctorSimLab, APortThatAnswersInAnotherInstrumentsProtocolIsNamedForWhatItIs) {
  auto d = doctor({"--port", ports["ls110"] + "=spectrolino", "--port", ports["dmx"] + "=ls110", "--no-record"});
  EXPECT_EQ(d.exit_code, 3);
  ASSERT_EQ(d.report["ports"].size(), 2u);
  const auto& meter = d.report["ports"][0];
  EXPECT_EQ(meter["verdict"], "wrong_instrument") << meter.dump(2);
  EXPECT_EQ(meter["kind"], "ls110");
  EXPECT_NE(meter["message"].get<std::string>().find("answers in the Konica Minolta LS-110's protocol"), std::string::npos)
      << meter["message"];
  EXPECT_NE(meter["message"].get<std::string>().find("not in the Spectrolino"), std::string::npos) << meter["message"];
  const auto& widget = d.report["ports"][1];
  EXPECT_EQ(widget["verdict"], "wrong_instrument") << widget.dump(2);
  EXPECT_EQ(widget["kind"], "dmx");
  EXPECT_FALSE(widget["measured"].get<bool>());
  // The text report says it in words too.
  auto t = doctor({"--port", ports["ls110"] + "=spectrolino", "--no-record"}, "", false);
  EXPECT_EQ(t.exit_code, 3);
  EXPECT_NE(t.out.find("WRONG INSTRUMENT"), std::string::npos) << t.out;
}

// On a terminal doctor asks before any reading; `script` gives it one. "n" takes none, "y" one.
TEST_F(DoctorSimLab, OnATerminalTheOperatorIsAskedFirstAndNoMeansNoReading) {
  ASSERT_TRUE(testing::on_path("script")) << "util-linux's script is part of every Debian system";
  auto session = [&](const std::string& answers) {
    const std::string cmd = shell_quote(bin_path("colorlab")) + " doctor --no-host --no-gige --no-record --port " +
                            shell_quote(ports["ls110"] + "=ls110");
    return run_command({"/bin/sh", "-c", "printf " + shell_quote(answers) + " | script -qec " + shell_quote(cmd) + " /dev/null"},
                       kLimit);
  };
  auto before = truth();
  auto no = session("n\n");
  EXPECT_NE(no.out.find("Take one reading"), std::string::npos) << no.out;
  EXPECT_NE(no.out.find("none taken"), std::string::npos) << no.out;
  EXPECT_EQ(truth()["ls110"]["readings_served"], before["ls110"]["readings_served"]);
  auto yes = session("y\n\n");
  EXPECT_NE(yes.out.find("operator confirmed: luminance="), std::string::npos) << yes.out;
  EXPECT_EQ(truth()["ls110"]["readings_served"].get<int>(), before["ls110"]["readings_served"].get<int>() + 1);
}

// With --measure the operator confirms the display on stdin: Enter for "shows the same". The
// transcript then replays to the driver; a different value typed is what its replay asserts.
TEST_F(DoctorSimLab, AConfirmedReadingBecomesATranscriptWhoseReplayAssertsTheOperatorsValue) {
  auto d = doctor({"--measure", "--port", ports["ls110"] + "=ls110", "--record", (dir / "agree").string()}, "\n");
  EXPECT_EQ(d.exit_code, 0) << d.report.dump(2) << d.err;
  ASSERT_EQ(d.report["ports"].size(), 1u);
  const auto& p = d.report["ports"][0];
  ASSERT_TRUE(p["measured"].get<bool>()) << p.dump(2);
  auto t = truth();
  EXPECT_NEAR(p["decoded"]["luminance"].get<double>(), t["ls110"]["luminance"].get<double>(),
              5 * t["ls110"]["noise_sigma"].get<double>() + 0.01);
  EXPECT_EQ(p["operator_confirmed"]["luminance"]["value"], p["decoded"]["luminance"]);
  EXPECT_EQ(t["ls110"]["readings_served"], 1);
  const auto replay = bin_path("../tests/transcript_replay");
  auto ok = run_command({replay, p["transcript"].get<std::string>()}, std::chrono::seconds(300));
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;

  auto no = doctor({"--measure", "--port", ports["ls110"] + "=ls110", "--record", (dir / "disagree").string()}, "9999\n");
  EXPECT_EQ(no.exit_code, 3) << no.report.dump(2);
  const auto& q = no.report["ports"][0];
  EXPECT_EQ(q["operator_disagrees"], true);
  EXPECT_EQ(q["operator_confirmed"]["luminance"]["value"], 9999.0);
  auto fails = run_command({replay, q["transcript"].get<std::string>()}, std::chrono::seconds(300));
  EXPECT_EQ(fails.exit_code, 1);
  EXPECT_NE(fails.err.find("luminance: expected 9999"), std::string::npos) << fails.err;
}

}  // namespace
}  // namespace colorlab::test
