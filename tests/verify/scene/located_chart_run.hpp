#pragma once
// A characterize-camera run's export holding only its located chart (`chart/raw`, `chart_location`): what
// `colorlab scene` reads to pose the camera, without a daemon or the photograph's pixels in between.
#include <utility>

#include <nlohmann/json.hpp>

namespace colorlab::verify::testing {

inline nlohmann::json located_chart_run(nlohmann::json corners, double confidence, int width, int height,
                                        double reprojection_rms_px) {
  nlohmann::json row{
      {"step", "chart/raw"},
      {"quantity", "chart_location"},
      {"value", confidence},
      {"data", {
                   {"format", "raw"},
                   {"corners", std::move(corners)},
                   {"width", width},
                   {"height", height},
                   {"reprojection_rms_px", reprojection_rms_px},
               }},
  };
  return {
      {"run", {
                  {"id", "0193c0de-0000-7000-8000-0000000cc0de"},
                  {"campaign", "characterize-camera"},
                  {"params", nlohmann::json::object()},
                  {"status", "finished_ok"},
              }},
      {"measurements", nlohmann::json::array({row})},
  };
}

}  // namespace colorlab::verify::testing
