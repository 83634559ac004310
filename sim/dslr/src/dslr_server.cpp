#include "colorlab/sim/dslr/dslr_server.hpp"

#include <cmath>
#include <deque>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::sim::dslr {

namespace asio = boost::asio;
using local = asio::local::stream_protocol;
using nlohmann::json;

namespace {

constexpr std::size_t kMaxRequestBytes = 64 * 1024;
constexpr std::size_t kShotsRemembered = 64;
constexpr double kCommandSeconds = 0.02;  // identify, configure, delete: a USB control round trip

}  // namespace

struct DslrServer::Impl {
  asio::any_io_executor executor;
  std::shared_ptr<DslrBody> body;
  std::filesystem::path path;
  std::shared_ptr<const SimClock> clock;
  std::shared_ptr<asio::thread_pool> renderer = std::make_shared<asio::thread_pool>(1);
  std::shared_ptr<local::acceptor> acceptor;  // replaced at each plug-in; the accept loop keeps its own
  std::shared_ptr<local::socket> client;
  std::unique_ptr<asio::steady_timer> replug;
  bool stopped = false;
  bool unplugged = false;
  // One-shot faults, counted down as they are used.
  int capture_timeouts = 0;
  int busy = 0;
  int malformed = 0;
  // Statistics and truth.
  std::uint64_t connections = 0, refused_connections = 0, requests = 0, captures_answered = 0, captures_swallowed = 0;
  std::deque<ShotResult> shots;

  Impl(asio::any_io_executor ex, std::shared_ptr<DslrBody> b, std::filesystem::path p, std::shared_ptr<const SimClock> c)
      : executor(std::move(ex)), body(std::move(b)), path(std::move(p)), clock(std::move(c)) {}

  void listen();
  void unplug();
  json faults() const {
    return {{"capture_timeout", capture_timeouts}, {"busy", busy}, {"malformed_answer", malformed}, {"disconnect", unplugged}};
  }
};

namespace {

asio::awaitable<void> pause(asio::any_io_executor ex, asio::steady_timer::duration d) {
  asio::steady_timer t(ex, d);
  boost::system::error_code ec;
  co_await t.async_wait(asio::redirect_error(asio::use_awaitable, ec));
}

asio::awaitable<ShotResult> take_shot(std::shared_ptr<DslrBody> body, ShotPlan plan) { co_return body->take(plan); }

json refusal(const json& id, const std::string& code, const std::string& message) {
  return {{"id", id}, {"ok", false}, {"error", code}, {"message", message}};
}

// One request -> its answer, or null when the camera (by fault) never answers it.
asio::awaitable<json> handle(std::shared_ptr<DslrServer::Impl> d, const json& req) {
  const json id = req.contains("id") ? req["id"] : json(nullptr);
  if (!id.is_number_unsigned()) co_return refusal(nullptr, "bad_request", "every request carries \"id\": a non-negative integer");
  const std::string cmd = req.contains("cmd") && req["cmd"].is_string() ? req["cmd"].get<std::string>() : std::string();
  auto ok = [&](json body) {
    body["id"] = id;
    body["ok"] = true;
    return body;
  };
  try {
    if (cmd == "identify") {
      co_await pause(d->executor, d->clock->to_real(kCommandSeconds));
      co_return ok(d->body->identify());
    }
    if (cmd == "configure") {
      co_await pause(d->executor, d->clock->to_real(kCommandSeconds));
      co_return ok(d->body->configure(req));
    }
    if (cmd == "delete") {
      co_await pause(d->executor, d->clock->to_real(kCommandSeconds));
      co_return ok(d->body->remove(req));
    }
    if (cmd == "capture") {
      if (d->busy > 0) {
        --d->busy;
        co_await pause(d->executor, d->clock->to_real(kCommandSeconds));
        co_return refusal(id, "busy", "the camera is busy writing to its card");
      }
      if (d->capture_timeouts > 0) {
        // The release never completes: no image, no answer. The camera stays usable afterwards.
        --d->capture_timeouts;
        ++d->captures_swallowed;
        co_return json(nullptr);
      }
      const ShotPlan plan = d->body->plan_shot();
      asio::steady_timer done(d->executor, d->clock->to_real(d->body->shot_seconds(plan)));
      // Rendering and writing the files run beside the simulated shot time, off the lab's thread.
      // (A named awaitable, not a capturing lambda: GCC 12 destroys such temporaries twice across co_await.)
      auto work = take_shot(d->body, plan);
      ShotResult shot = co_await asio::co_spawn(d->renderer->get_executor(), std::move(work), asio::use_awaitable);
      boost::system::error_code ec;
      co_await done.async_wait(asio::redirect_error(asio::use_awaitable, ec));
      json files = json::array();
      for (const auto& f : shot.files) {
        files.push_back({{"name", f.name}, {"path", f.path.string()}, {"type", f.type}, {"bytes", f.bytes}});
      }
      d->shots.push_back(std::move(shot));
      while (d->shots.size() > kShotsRemembered) d->shots.pop_front();
      ++d->captures_answered;
      co_return ok({{"shot", plan.shot}, {"files", files}});
    }
  } catch (const Refusal& r) {
    co_return refusal(id, r.code, r.message);
  } catch (const Error& e) {
    co_return refusal(id, "failed", e.what());
  }
  co_return refusal(id, "bad_request", "unknown command '" + cmd + "' (identify, configure, capture, delete)");
}

asio::awaitable<void> serve(std::shared_ptr<DslrServer::Impl> d, std::shared_ptr<local::socket> socket) {
  asio::streambuf buf(kMaxRequestBytes);
  for (;;) {
    boost::system::error_code ec;
    const std::size_t n = co_await asio::async_read_until(*socket, buf, '\n', asio::redirect_error(asio::use_awaitable, ec));
    if (ec) break;  // closed by the client, by an unplug, or a line over the size limit
    std::string line(asio::buffers_begin(buf.data()), asio::buffers_begin(buf.data()) + static_cast<long>(n));
    buf.consume(n);
    ++d->requests;
    const json req = json::parse(line, nullptr, false);
    json answer = refusal(nullptr, "bad_request", "a request is one JSON object per line");
    if (req.is_object()) answer = co_await handle(d, req);
    if (answer.is_null() || !socket->is_open()) continue;
    std::string out = answer.dump() + "\n";
    if (d->malformed > 0) {
      --d->malformed;
      out = "~" + out.substr(out.size() / 2);  // half a line behind a byte no JSON starts with
    }
    co_await asio::async_write(*socket, asio::buffer(out), asio::redirect_error(asio::use_awaitable, ec));
    if (ec) break;
  }
  if (d->client == socket) d->client.reset();
}

// Answers the first request of a connection the camera cannot serve with in_use, then closes it.
// Waiting for that request (rather than refusing at once) means the client always finds the
// refusal as the answer to what it sent, never a connection reset under its first write.
asio::awaitable<void> turn_away(std::shared_ptr<local::socket> socket) {
  asio::steady_timer give_up(socket->get_executor(), std::chrono::seconds(5));
  give_up.async_wait([socket](boost::system::error_code ec) {
    if (!ec) socket->close(ec);
  });
  asio::streambuf buf(kMaxRequestBytes);
  boost::system::error_code ec;
  const std::size_t n = co_await asio::async_read_until(*socket, buf, '\n', asio::redirect_error(asio::use_awaitable, ec));
  give_up.cancel();
  if (ec) co_return;
  const std::string line(asio::buffers_begin(buf.data()), asio::buffers_begin(buf.data()) + static_cast<long>(n));
  const json req = json::parse(line, nullptr, false);
  const json id = req.is_object() && req.contains("id") ? req["id"] : json(nullptr);
  const std::string out = refusal(id, "in_use", "another client holds the camera").dump() + "\n";
  co_await asio::async_write(*socket, asio::buffer(out), asio::redirect_error(asio::use_awaitable, ec));
  socket->close(ec);
}

asio::awaitable<void> accept_loop(std::shared_ptr<DslrServer::Impl> d, std::shared_ptr<local::acceptor> acceptor) {
  for (;;) {
    boost::system::error_code ec;
    auto socket = std::make_shared<local::socket>(co_await acceptor->async_accept(asio::redirect_error(asio::use_awaitable, ec)));
    if (ec) co_return;  // closed: stopped or unplugged
    if (d->client) {
      // One USB connection per camera: a second program is turned away, the first keeps it.
      ++d->refused_connections;
      asio::co_spawn(d->executor, turn_away(socket), asio::detached);
      continue;
    }
    ++d->connections;
    d->client = socket;
    asio::co_spawn(d->executor, serve(d, socket), asio::detached);
  }
}

}  // namespace

void DslrServer::Impl::listen() {
  std::error_code fec;
  std::filesystem::remove(path, fec);
  acceptor = std::make_shared<local::acceptor>(executor);
  boost::system::error_code ec;
  local::endpoint ep(path.string());
  acceptor->open(ep.protocol(), ec);
  if (!ec) acceptor->bind(ep, ec);
  if (!ec) acceptor->listen(4, ec);
  if (ec) throw Error(ErrorClass::io_error, "simulated DSLR socket " + path.string() + ": " + ec.message(), "check [dslr] socket");
  unplugged = false;
}

void DslrServer::Impl::unplug() {
  unplugged = true;
  boost::system::error_code ec;
  if (acceptor) acceptor->close(ec);
  if (client) client->close(ec);
  client.reset();
  std::error_code fec;
  std::filesystem::remove(path, fec);
}

DslrServer::DslrServer(asio::any_io_executor executor, std::shared_ptr<DslrBody> body, std::filesystem::path socket_path,
                       std::shared_ptr<const SimClock> clock)
    : impl_(std::make_shared<Impl>(std::move(executor), std::move(body), std::move(socket_path), std::move(clock))) {}

DslrServer::~DslrServer() { stop(); }

void DslrServer::start() {
  impl_->listen();
  asio::co_spawn(impl_->executor, accept_loop(impl_, impl_->acceptor), asio::detached);
}

void DslrServer::stop() {
  if (impl_->stopped) return;
  impl_->stopped = true;
  if (impl_->replug) impl_->replug->cancel();
  impl_->unplug();
  impl_->renderer->join();  // a frame being written finishes; nothing new starts
}

const std::filesystem::path& DslrServer::socket_path() const { return impl_->path; }
DslrBody& DslrServer::body() { return *impl_->body; }

json DslrServer::faults() const { return impl_->faults(); }

json DslrServer::set_faults(const json& f) {
  auto& d = *impl_;
  if (!f.is_object()) throw Error(ErrorClass::bad_parameter, "dslr faults must be an object");
  auto count = [&](const char* key, int& slot) {
    if (!f.contains(key)) return;
    const json& v = f[key];
    if (v.is_boolean()) slot = v.get<bool>() ? 1 : 0;
    else if (v.is_number_integer() && v.get<int>() >= 0) slot = v.get<int>();
    else throw Error(ErrorClass::bad_parameter, std::string("dslr fault ") + key + " must be true/false or a count");
  };
  for (const auto& [key, value] : f.items()) {
    if (key != "capture_timeout" && key != "busy" && key != "malformed_answer" && key != "disconnect" && key != "disconnect_s") {
      throw Error(ErrorClass::bad_parameter, "unknown dslr fault '" + key + "'",
                  "capture_timeout, busy, malformed_answer, disconnect, disconnect_s");
    }
  }
  count("capture_timeout", d.capture_timeouts);
  count("busy", d.busy);
  count("malformed_answer", d.malformed);
  auto plug_in = [impl = impl_] {
    if (impl->stopped || !impl->unplugged) return;
    impl->listen();
    asio::co_spawn(impl->executor, accept_loop(impl, impl->acceptor), asio::detached);
    log::info("sim", "simulated DSLR plugged in again");
  };
  if (f.contains("disconnect")) {
    if (!f["disconnect"].is_boolean()) throw Error(ErrorClass::bad_parameter, "dslr fault disconnect must be true or false");
    if (f["disconnect"].get<bool>()) {
      if (d.replug) d.replug->cancel();
      d.unplug();
    } else {
      plug_in();
    }
  }
  if (f.contains("disconnect_s")) {
    const double s = f["disconnect_s"].is_number() ? f["disconnect_s"].get<double>() : -1;
    if (!(s > 0)) throw Error(ErrorClass::bad_parameter, "dslr fault disconnect_s must be a positive number of seconds");
    d.unplug();
    d.replug = std::make_unique<asio::steady_timer>(d.executor, d.clock->to_real(s));
    d.replug->async_wait([plug_in](boost::system::error_code ec) {
      if (!ec) plug_in();
    });
  }
  return d.faults();
}

json DslrServer::truth() const {
  const auto& d = *impl_;
  json t{{"socket", d.path.string()},
         {"connected", static_cast<bool>(d.client)},
         {"plugged_in", !d.unplugged},
         {"connections", d.connections},
         {"refused_connections", d.refused_connections},
         {"requests", d.requests},
         {"captures_answered", d.captures_answered},
         {"captures_swallowed", d.captures_swallowed},
         {"capture_dir", d.body->config().capture_dir.string()},
         {"settings", d.body->settings()},
         {"faults", d.faults()}};
  if (!d.shots.empty()) t["last_file"] = d.shots.back().files.front().name;
  return t;
}

json DslrServer::shot_truth(const std::optional<std::string>& file) const {
  const auto& d = *impl_;
  const ShotResult* shot = nullptr;
  for (auto it = d.shots.rbegin(); it != d.shots.rend() && !shot; ++it) {
    if (!file || it->files.front().name == *file) shot = &*it;
  }
  if (!shot) {
    throw Error(ErrorClass::not_found, file ? "the simulated DSLR remembers no shot " + *file : "the simulated DSLR has taken no shot yet",
                "the last " + std::to_string(kShotsRemembered) + " shots are remembered");
  }
  const auto& model = d.body->model();
  const auto& cfg = model.config();
  const auto& ex = shot->plan.exposure;
  json patches = json::array();
  for (std::size_t p = 0; p < shot->truth.size(); ++p) {
    const auto r = model.patch_region(static_cast<int>(p));
    json sigma = json::array();
    for (double mean : shot->truth[p]) {
      const double signal = std::max(0.0, mean - 256.0);
      const double t = model.temporal_sigma_dn(signal, ex);
      // Temporal noise, pixel gain and offset non-uniformity, column offsets: every per-pixel spread the model adds.
      sigma.push_back(std::sqrt(t * t + std::pow(cfg.prnu_sigma * signal, 2) + std::pow(cfg.dsnu_sigma_dn, 2) +
                                std::pow(cfg.column_offset_sigma_dn, 2)));
    }
    patches.push_back({{"index", p}, {"region", {r.x, r.y, r.width, r.height}}, {"mean", shot->truth[p]}, {"pixel_sigma", sigma}});
  }
  json dust = json::array();
  for (const auto& s : model.dust()) dust.push_back(s.patch);
  json defects = json::array();
  for (const auto& px : model.defects()) defects.push_back({px.x, px.y});
  json files = json::array();
  for (const auto& f : shot->files) files.push_back(f.name);
  return {{"file", shot->files.front().name},
          {"files", files},
          {"shot", shot->plan.shot},
          {"settings", {{"iso", ex.iso}, {"shutter_s", ex.shutter_s}, {"aperture", ex.f_number}}},
          {"width", model.width()},
          {"height", model.height()},
          {"black_level", 256},
          {"white_level", 4095},
          {"patches", patches},
          {"dust_patches", dust},
          {"defects", defects}};
}

}  // namespace colorlab::sim::dslr
