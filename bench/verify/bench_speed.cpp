// `colorlab verify` timed as a user waits for it (issue 23 "Speed", docs/PERFORMANCE.md "Verifying a rendering"):
// an XYZ and an RGB OpenEXR at the photograph's 3504 × 2336 (target ≤ 2 s each) and a 36-band spectral one at half
// that size, about 300 MB of float (target ≤ 8 s). colorlabd's embedded simulated lab (the DSLR at its full
// 3504 × 2336) runs what both halves need: one floor-luminance (the full 8 × 10 grid) for the light, a chart-read and
// a characterize-camera (raw, 2 frames) for the colour. Each rendering holds the lab's chart (speed_renderings.hpp).
// Per round and file, interleaved so all see the same load: the whole `colorlab verify … --json --store` process
// against the light run (`--scale 1`) and against the colour run, oiiotool's read of the same file, then each path
// in process stage by stage (speed_stages.hpp).
//
//   bench_verify_speed [--rounds N] [--dir DIR] [--no-oiiotool] [--keep-files]
// --keep-files: reuse the renderings already in DIR and leave them there (for perf record on one stage).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>

#include "colorlab/client/api_client.hpp"
#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "speed_renderings.hpp"
#include "speed_stages.hpp"

namespace {

using colorlab::bench::Clock;
using colorlab::bench::since;
using colorlab::bench::Stages;
using colorlab::verify::Encoding;
using nlohmann::json;

json run_to_end(const colorlab::client::ApiClient& api, const std::string& campaign, const json& params) {
  const auto t0 = Clock::now();
  const json e = api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
  const auto deadline = Clock::now() + std::chrono::minutes(20);
  for (;;) {
    const json s = api.get("/v1/executions/" + e["id"].get<std::string>());
    const std::string st = s.value("status", "");
    if (st.rfind("finished", 0) == 0 || st == "aborted" || st == "interrupted") {
      if (st != "finished_ok") {
        std::fprintf(stderr, "%s ended %s: %s\n", campaign.c_str(), st.c_str(), s.dump().substr(0, 4000).c_str());
        std::exit(1);
      }
      std::printf("%s run %s in %.1f s\n", campaign.c_str(), s["run_id"].get<std::string>().c_str(), since(t0));
      return s;
    }
    if (Clock::now() > deadline) {
      std::fprintf(stderr, "%s did not finish in 20 minutes\n", campaign.c_str());
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

void table(const char* title, const std::vector<std::string>& names, const std::vector<Stages>& stages,
           const std::vector<const char*>& columns, const std::vector<double>& targets, int rounds) {
  std::printf("\n%s, medians of %d rounds (s):\n%-22s", title, rounds, "case");
  for (const char* k : columns) std::printf(" %9s", k);
  std::printf("   target\n");
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::printf("%-22s", names[i].c_str());
    for (const char* k : columns) std::printf(" %9.3f", stages[i].median(k));
    const double p = stages[i].median("process");
    std::printf("   <= %.0f s: %s\n", targets[i], p <= targets[i] ? "met" : "NOT met");
  }
}

void print_round(int round, const std::string& name, const Stages& st, const std::vector<const char*>& columns) {
  std::printf("round %d %-30s", round, name.c_str());
  for (const char* k : columns)
    if (st.has(k)) std::printf(" | %s %.3f", k, st.last(k));
  std::printf("\n");
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

  // Seed 5: the DSLR's seeded chart pose characterize_camera_test and verify_colour_runs_test locate.
  colorlab::testing::TempDir state;
  {
    std::ofstream(state.path() / "lab.toml") << "[genicam]\nenabled = false\n";
    std::ofstream(state.path() / "colorlabd.toml")
        << "[simulator]\nenabled = true\ntime_scale = 500\nseed = 5\nconfig = \"lab.toml\"\n";
  }
  auto daemon = std::make_unique<colorlab::testing::DaemonProcess>(state.path() / "state", state.path() / "colorlabd.toml");
  colorlab::client::Endpoint ep;
  ep.unix_socket = daemon->unix_socket();
  const colorlab::client::ApiClient api(ep, std::chrono::seconds(120));
  const std::string floor_run =
      run_to_end(api, "floor-luminance", {{"lamps", {"D65"}}, {"dimmer_levels", {100}}, {"settle_s", 0}, {"frames", 4}})["run_id"];
  const std::string chart_read = run_to_end(api, "chart-read", json::object())["run_id"];
  // The fewest frames and formats that give the colour half all it reads: the raw's patch values, its selected
  // mapping and the black box (§7.4).
  const std::string characterize =
      run_to_end(api, "characterize-camera",
                 {{"reference_run", chart_read}, {"frames", 2}, {"formats", {"raw"}}, {"prior_exclude", {"Canon_20D"}}})["run_id"];

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
    const auto t0 = Clock::now();
    const auto r = colorlab::bench::chart_and_floor(c.e, c.w, c.h);
    colorlab::verify::write_openexr(r, c.file);
    std::printf("wrote %s: %.0f MB on disk, %.0f MB of float, %.1f s\n", c.file.c_str(),
                static_cast<double>(std::filesystem::file_size(c.file)) / 1e6, static_cast<double>(r.pixels.size()) * 4 / 1e6, since(t0));
  }

  const std::string colorlab = "'" + (bin / "colorlab").string() + "' --socket '" + daemon->unix_socket() + "' verify '";
  const std::vector<const char*> light_cols{"process", "oiiotool", "read", "fetch", "scene", "sample", "compare", "json", "store"};
  const std::vector<const char*> colour_cols{"process", "read", "fetch", "locate", "refit", "scene", "sample", "compare", "json", "store"};
  std::vector<Stages> light(cases.size()), colour(cases.size());
  for (int round = 1; round <= rounds; ++round)
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const auto& c = cases[i];
      light[i].add("process", run_process(colorlab + c.file.string() + "' --against " + floor_run + " --json --scale 1 --store >/dev/null"));
      if (oiio) {
        const auto t = Clock::now();
        if (std::system(("oiiotool -i:now=1 '" + c.file.string() + "' >/dev/null 2>&1").c_str()) != 0) {
          std::fprintf(stderr, "oiiotool failed (openimageio-tools installed?); --no-oiiotool to skip it\n");
          return 1;
        }
        light[i].add("oiiotool", since(t));
      }
      colour[i].add("process", run_process(colorlab + c.file.string() + "' --against " + characterize + " --json --store >/dev/null"));
      colorlab::bench::light_in_process(c.file, api, floor_run, light[i]);
      colorlab::bench::colour_in_process(c.file, api, characterize, colour[i]);
      print_round(round, std::string(c.name) + " light", light[i], light_cols);
      print_round(round, std::string(c.name) + " colour", colour[i], colour_cols);
    }

  std::vector<std::string> names;
  std::vector<double> targets;
  for (const auto& c : cases) {
    names.emplace_back(c.name);
    targets.push_back(c.target_s);
  }
  table("light half (--against the floor-luminance run, --scale 1)", names, light, light_cols, targets, rounds);
  table("colour half (--against the characterize-camera run; scene repeats locate and refit)", names, colour, colour_cols,
        targets, rounds);
  for (std::size_t i = 0; i < cases.size(); ++i)
    std::printf("%-22s colour: %s\n", cases[i].name, colour[i].note.c_str());
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
