#pragma once
// One serial port examined for colorlab doctor: the handshakes (handshake.hpp), then the identified
// instrument's identity and calibration state through its own driver, and — only when the operator
// agreed — one reading. Everything is read-only until then; even with agreement no lamp is switched
// (a DMX widget's "reading" is its identity), and only the SpectroScan moves, to its white tile.
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/bringup/handshake.hpp"
#include "colorlab/bringup/recording.hpp"

namespace colorlab::bringup {

struct ExamineOptions {
  std::string expect;           // the kind the operator says is on this port; empty = find out
  bool measure = false;         // the operator agreed to one reading
  double deadline_scale = 1.0;  // multiplies every deadline (replays on a slow machine)
};

// The probing order a plan implies: the expected kind first, then the others in serial_kinds() order.
std::vector<std::string> probe_order(const std::string& expect);

// A value the operator is asked to confirm against the instrument itself (its display or label).
struct Confirmation {
  std::string key;       // as in Examination::decoded ("luminance", "serial")
  std::string question;  // "What luminance does the LS-110's display show?"
  std::string unit;      // "cd/m2"; empty for text
};

struct Examination {
  std::string port;
  std::string expected_kind;
  std::string kind;  // what answered ("" when nothing recognisable did)
  // identified | wrong_instrument | unknown_protocol | silent | cannot_open | failed
  std::string verdict;
  std::string message;  // one plain sentence
  std::string hint;
  std::vector<std::string> tried;
  nlohmann::json identity = nlohmann::json::object();
  nlohmann::json calibration = nlohmann::json::object();
  // What colorlab decoded, keyed as a transcript's expected values are: verdict, kind, serial,
  // firmware, luminance, spectrum, … (a replay compares these with the operator's values).
  nlohmann::json decoded = nlohmann::json::object();
  bool measured = false;
  std::vector<Confirmation> confirmations;
  double seconds = 0;
};

boost::asio::awaitable<Examination> examine_port(boost::asio::any_io_executor executor, std::string port,
                                                 ExamineOptions options, Recording& recording);

nlohmann::json to_json(const Examination& e);

}  // namespace colorlab::bringup
