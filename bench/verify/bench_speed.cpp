// `colorlab verify` timed as a user waits for it (issue 23 "Speed", docs/PERFORMANCE.md "Verifying a rendering"):
// an XYZ and an RGB OpenEXR at the photograph's 3504 × 2336 (target ≤ 2 s each) and a 36-band spectral one at half
// that size, about 300 MB of float (target ≤ 8 s), each verified against one floor-luminance run of colorlabd's
// embedded simulated lab (the full 8 × 10 grid) — the whole `colorlab verify … --json --scale 1 --store` process,
// then the same path in process, stage by stage: read, fetch the run, scene (the floor's homography places each
// spot), sample (every region's mean and its four shifted copies: the engine's own region_mean), compare (the
// engine's compare(): sampling, conversion to XYZ, budgets and verdicts), json, store. oiiotool's read of the same
// file runs in the same round (the reference where there is one), interleaved so both see the same load.
//
//   bench_verify_speed [--rounds N] [--dir DIR] [--no-oiiotool] [--keep-files]
// --keep-files: reuse the renderings already in DIR and leave them there (for perf record on one stage).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/client/runs.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "colorlab/verify/compare/scene_from_runs.hpp"
#include "colorlab/verify/compare/stored_request.hpp"
#include "colorlab/verify/rendering.hpp"
#include "rendering_sample.hpp"  // verify/compare/src: the engine's own sampling, timed alone

namespace {

using colorlab::verify::Encoding;
using colorlab::verify::Rendering;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

float noise(std::uint32_t i) {
  i ^= i >> 16;
  i *= 0x7feb352dU;
  i ^= i >> 15;
  i *= 0x846ca68bU;
  i ^= i >> 16;
  return static_cast<float>(i) / 4294967296.0f - 0.5f;
}

// A smooth floor-like field with a render's 1 % per-pixel noise, so the files compress like path-traced images.
// The values need not agree with the run: every comparison costs the same whatever its verdict.
Rendering image(Encoding e, int w, int h) {
  Rendering r;
  r.encoding = e;
  r.width = w;
  r.height = h;
  if (e == Encoding::spectral) {
    r.units = "W.m^-2.sr^-1.nm^-1";
    for (int b = 0; b < 36; ++b) r.wavelengths_nm.push_back(380.0 + 10.0 * b);
  } else if (e == Encoding::rgb) {
    r.chromaticities = colorlab::verify::rec709_chromaticities();
    r.chromaticities_from_file = true;
  }
  const int c = r.channels();
  r.pixels.resize(static_cast<std::size_t>(w) * h * c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = double(x) / w, v = double(y) / h;
      const double lum = 150 + 100 * std::sin(3 * u) * std::cos(2 * v);
      for (int k = 0; k < c; ++k) {
        const std::size_t i = (static_cast<std::size_t>(y) * w + x) * c + k;
        const double base = e == Encoding::spectral ? lum / (683 * 106.857) : lum;
        r.pixels[i] = static_cast<float>(base * (1.0 + 0.01 * noise(static_cast<std::uint32_t>(i))));
      }
    }
  return r;
}

json run_to_end(const colorlab::client::ApiClient& api, const std::string& campaign, const json& params) {
  const json e = api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
  const auto deadline = Clock::now() + std::chrono::minutes(10);
  for (;;) {
    const json s = api.get("/v1/executions/" + e["id"].get<std::string>());
    const std::string st = s.value("status", "");
    if (st.rfind("finished", 0) == 0 || st == "aborted" || st == "interrupted") {
      if (st != "finished_ok") {
        std::fprintf(stderr, "%s ended %s: %s\n", campaign.c_str(), st.c_str(), s.dump().c_str());
        std::exit(1);
      }
      return s;
    }
    if (Clock::now() > deadline) {
      std::fprintf(stderr, "%s did not finish in 10 minutes\n", campaign.c_str());
      std::exit(1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

double run_process(const std::string& cmd) {
  const auto t0 = Clock::now();
  const int rc = std::system(cmd.c_str());
  const double t = since(t0);
  // colorlab verify: 0 agrees, 4 differs — both are verdicts; anything else is a failure of the bench.
  if (!WIFEXITED(rc) || (WEXITSTATUS(rc) != 0 && WEXITSTATUS(rc) != 4)) {
    std::fprintf(stderr, "failed (%d): %s\n", rc, cmd.c_str());
    std::exit(1);
  }
  return t;
}

struct Stages {
  std::map<std::string, std::vector<double>> s;
  void add(const std::string& k, double v) { s[k].push_back(v); }
};

const char* const kStages[] = {"process", "oiiotool", "read", "fetch", "scene", "sample", "compare", "json", "store"};

void in_process(const std::filesystem::path& file, const colorlab::client::ApiClient& api, const std::string& run,
                Stages& st) {
  namespace v = colorlab::verify;
  auto t0 = Clock::now();
  const Rendering r = v::read_rendering(file);
  st.add("read", since(t0));
  t0 = Clock::now();
  std::vector<json> runs{colorlab::client::fetch_run(api, run)};
  st.add("fetch", since(t0));
  t0 = Clock::now();
  v::RunsSceneOptions so;
  const v::MeasuredScene scene = v::scene_from_runs(runs, r.width, r.height, so);
  st.add("scene", since(t0));
  // What the engine samples: each cell's region and the four one-pixel shifts of the misregistration probe.
  t0 = Clock::now();
  double sink = 0;
  for (const auto& f : scene.floor) {
    sink += v::detail::region_mean(r, f.rendering_region)[0];
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}})
      sink += v::detail::shifted_mean(r, f.rendering_region, dx, dy)[0];
  }
  st.add("sample", since(t0));
  if (!(sink > -1)) std::printf(" ");
  t0 = Clock::now();
  v::CompareOptions o;
  o.scale = 1.0;
  const v::Verification ver = v::compare(r, scene, o);
  st.add("compare", since(t0));
  t0 = Clock::now();
  const std::string out = ver.to_json().dump(2);
  st.add("json", since(t0));
  t0 = Clock::now();
  api.post("/v1/verifications", v::store_request(ver, file.filename().string(), {run}, o));
  st.add("store", since(t0));
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 3;
  bool oiio = true, keep = false;
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "colorlab_bench_verify_speed";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--rounds" && i + 1 < argc) rounds = std::max(1, std::atoi(argv[++i]));
    else if (a == "--dir" && i + 1 < argc) dir = argv[++i];
    else if (a == "--no-oiiotool") oiio = false;
    else if (a == "--keep-files") keep = true;
    else {
      std::fprintf(stderr, "usage: bench_verify_speed [--rounds N] [--dir DIR] [--no-oiiotool] [--keep-files]\n");
      return 2;
    }
  }
  std::filesystem::create_directories(dir);
  const std::filesystem::path bin = std::filesystem::canonical("/proc/self/exe").parent_path();

  // One floor-luminance run of the embedded simulated lab: the full 8 × 10 grid under D65 at 100 %.
  colorlab::testing::TempDir state;
  {
    std::ofstream(state.path() / "lab.toml") << "[genicam]\nenabled = false\n";
    std::ofstream(state.path() / "colorlabd.toml")
        << "[simulator]\nenabled = true\ntime_scale = 500\nseed = 3\nconfig = \"lab.toml\"\n";
  }
  auto t0 = Clock::now();
  auto daemon = std::make_unique<colorlab::testing::DaemonProcess>(state.path() / "state", state.path() / "colorlabd.toml");
  colorlab::client::Endpoint ep;
  ep.unix_socket = daemon->unix_socket();
  const colorlab::client::ApiClient api(ep, std::chrono::seconds(120));
  const json done = run_to_end(api, "floor-luminance",
                               {{"lamps", {"D65"}}, {"dimmer_levels", {100}}, {"settle_s", 0}, {"frames", 4}});
  const std::string run = done["run_id"].get<std::string>();
  std::printf("floor-luminance run %s (8 x 10 grid) in %.1f s\n", run.c_str(), since(t0));

  struct Case {
    const char* name;
    Encoding e;
    int w, h;
    double target_s;
    std::filesystem::path file;
  };
  std::vector<Case> cases{{"xyz 3504x2336", Encoding::xyz, 3504, 2336, 2.0, dir / "xyz_3504x2336.exr"},
                          {"rgb 3504x2336", Encoding::rgb, 3504, 2336, 2.0, dir / "rgb_3504x2336.exr"},
                          {"spectral 36x1752x1168", Encoding::spectral, 1752, 1168, 8.0, dir / "spectral_36x1752x1168.exr"}};
  for (auto& c : cases) {
    if (keep && std::filesystem::exists(c.file)) continue;
    t0 = Clock::now();
    const Rendering r = image(c.e, c.w, c.h);
    colorlab::verify::write_openexr(r, c.file);
    std::printf("wrote %s: %.0f MB on disk, %.0f MB of float, %.1f s\n", c.file.c_str(),
                std::filesystem::file_size(c.file) / 1e6, r.pixels.size() * 4 / 1e6, since(t0));
  }

  std::vector<Stages> stages(cases.size());
  for (int round = 0; round < rounds; ++round)
    for (std::size_t i = 0; i < cases.size(); ++i) {
      auto& c = cases[i];
      const double p = run_process("'" + (bin / "colorlab").string() + "' --socket '" + daemon->unix_socket() + "' verify '" +
                                   c.file.string() + "' --against " + run + " --json --scale 1 --store >/dev/null");
      stages[i].add("process", p);
      if (oiio) {
        const auto t = Clock::now();
        if (std::system(("oiiotool -i:now=1 '" + c.file.string() + "' >/dev/null 2>&1").c_str()) != 0) {
          std::fprintf(stderr, "oiiotool failed (openimageio-tools installed?); --no-oiiotool to skip it\n");
          return 1;
        }
        stages[i].add("oiiotool", since(t));
      }
      in_process(c.file, api, run, stages[i]);
      std::printf("round %d %-22s process %.3f s", round + 1, c.name, p);
      for (const char* k : kStages)
        if (std::string(k) != "process" && stages[i].s.count(k)) std::printf(" | %s %.3f", k, stages[i].s[k].back());
      std::printf("\n");
    }

  std::printf("\nmedians of %d rounds (s):\n%-22s", rounds, "case");
  for (const char* k : kStages) std::printf(" %9s", k);
  std::printf("   target\n");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::printf("%-22s", cases[i].name);
    for (const char* k : kStages) std::printf(" %9.3f", median(stages[i].s[k]));
    const double p = median(stages[i].s["process"]);
    std::printf("   <= %.0f s: %s\n", cases[i].target_s, p <= cases[i].target_s ? "met" : "NOT met");
  }
  if (!keep) {
    for (auto& c : cases) std::filesystem::remove(c.file);
    std::filesystem::remove(dir);
  }
  // The embedded simulator's capture folder outlives it; the machine's /tmp is shared.
  const json endpoint = json::parse(std::ifstream(daemon->state_dir() / "colorlabd.endpoint"));
  if (endpoint.contains("simulator_pid")) {
    const auto sim_dir = std::filesystem::temp_directory_path() /
                         ("colorlab-sim-" + std::to_string(endpoint["simulator_pid"].get<long>()) + "-dslr");
    daemon.reset();  // waits for the simulator to go
    std::filesystem::remove_all(sim_dir);
  }
  return 0;
}
