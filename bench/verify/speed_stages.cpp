#include "speed_stages.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "colorlab/client/runs.hpp"
#include "colorlab/verify/compare/scene_from_runs.hpp"
#include "colorlab/verify/compare/stored_request.hpp"
#include "colorlab/verify/rendering.hpp"
#include "colour_from_runs.hpp"
#include "rendering_sample.hpp"  // verify/compare/src: the engine's own sampling, timed alone

namespace colorlab::bench {

using nlohmann::json;
namespace v = colorlab::verify;

double Stages::median(const std::string& k) const {
  auto it = s.find(k);
  if (it == s.end() || it->second.empty()) return 0;
  std::vector<double> x = it->second;
  std::sort(x.begin(), x.end());
  return x.size() % 2 ? x[x.size() / 2] : 0.5 * (x[x.size() / 2 - 1] + x[x.size() / 2]);
}

namespace {

// What the engine samples: each region and the four one-pixel shifts of the misregistration probe.
double sample(const v::Rendering& r, const std::vector<v::PixelRect>& regions) {
  double sink = 0;
  for (const auto& region : regions) {
    sink += v::detail::region_mean(r, region)[0];
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}})
      sink += v::detail::shifted_mean(r, region, dx, dy)[0];
  }
  return sink;
}

void finish(const v::Rendering& r, const v::MeasuredScene& scene, const std::vector<v::PixelRect>& regions,
            const v::CompareOptions& o, const std::filesystem::path& file, const client::ApiClient& api,
            const std::vector<std::string>& against, Stages& st) {
  auto t0 = Clock::now();
  if (!(sample(r, regions) > -1)) std::printf(" ");
  st.add("sample", since(t0));
  t0 = Clock::now();
  const v::Verification ver = v::compare(r, scene, o);
  st.add("compare", since(t0));
  t0 = Clock::now();
  const std::string out = ver.to_json().dump(2);
  st.add("json", since(t0));
  t0 = Clock::now();
  api.post("/v1/verifications", v::store_request(ver, file.filename().string(), against, o));
  st.add("store", since(t0));
}

}  // namespace

void light_in_process(const std::filesystem::path& file, const client::ApiClient& api, const std::string& run, Stages& st) {
  auto t0 = Clock::now();
  const v::Rendering r = v::read_rendering(file);
  st.add("read", since(t0));
  t0 = Clock::now();
  std::vector<json> runs{client::fetch_run(api, run)};
  st.add("fetch", since(t0));
  t0 = Clock::now();
  const v::MeasuredScene scene = v::scene_from_runs(runs, r.width, r.height, v::RunsSceneOptions{});
  st.add("scene", since(t0));
  std::vector<v::PixelRect> regions;
  for (const auto& f : scene.floor) regions.push_back(f.rendering_region);
  v::CompareOptions o;
  o.scale = 1.0;
  finish(r, scene, regions, o, file, api, {run}, st);
}

void colour_in_process(const std::filesystem::path& file, const client::ApiClient& api, const std::string& run, Stages& st) {
  auto t0 = Clock::now();
  const v::Rendering r = v::read_rendering(file);
  st.add("read", since(t0));
  t0 = Clock::now();
  std::vector<json> runs{client::fetch_run(api, run)};
  runs.push_back(client::fetch_run(api, v::chart_read_of(runs[0])));
  st.add("fetch", since(t0));
  t0 = Clock::now();
  const v::ChartInRendering located = v::locate_chart_in_rendering(r, runs[1]);
  st.add("locate", since(t0));
  t0 = Clock::now();
  const v::RefitCharacterization refit = v::refit_characterization(runs[0], runs[1], "D65");
  st.add("refit", since(t0));
  t0 = Clock::now();
  json account;
  const v::MeasuredScene scene = v::measured_scene_from_runs(runs, r, v::RunsSceneOptions{}, &account);
  st.add("scene", since(t0));
  char note[256];
  std::snprintf(note, sizeof note, "%s, LOO mean %.2f ΔE00 in %.3f s; chart found, confidence %.2f, RMS %.2f px, %zu patches",
                refit.characterization.name.c_str(), refit.loo_mean_de00, refit.seconds, located.confidence, located.accuracy_px,
                located.regions.size());
  st.note = note;
  finish(r, scene, located.regions, v::CompareOptions{}, file, api, {run}, st);
}

}  // namespace colorlab::bench
