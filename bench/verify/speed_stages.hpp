#pragma once
// The path of `colorlab verify` (client/app/verify_command.cpp) in process, stage by stage, for
// bench_verify_speed: the light half against a floor-luminance run, the colour half against a characterize-camera
// run (its chart-read fetched with it, as the CLI does).
#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "colorlab/client/api_client.hpp"

namespace colorlab::bench {

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Stages {
  std::map<std::string, std::vector<double>> s;
  std::string note;  // what the colour half found (characterization, chart in the rendering), from the last round
  void add(const std::string& k, double v) { s[k].push_back(v); }
  bool has(const std::string& k) const { return s.count(k) > 0; }
  double last(const std::string& k) const { return s.at(k).back(); }
  double median(const std::string& k) const;
};

// read, fetch, scene (the floor homography places each spot), sample (every region's mean and its four one-pixel
// shifts: the engine's region_mean), compare (the engine's compare(), scale 1), json, store.
void light_in_process(const std::filesystem::path& file, const client::ApiClient& api, const std::string& floor_run, Stages& st);

// read, fetch (the characterize-camera run and its chart-read), locate (the chart locator on the rendering's
// luminance), refit (the selected mapping fitted again under the lamp, with its leave-one-out), scene
// (measured_scene_from_runs as the CLI calls it: locate and refit again, plus the black box), sample, compare
// (fitted factor), json, store.
void colour_in_process(const std::filesystem::path& file, const client::ApiClient& api, const std::string& characterize_run,
                       Stages& st);

}  // namespace colorlab::bench
