#pragma once
// Run documents as `GET /v1/runs/{id}/export?format=json` gives them, filled from a simulated Scene the way its
// instruments would measure it: the chart's spectra read with the Spectrolino's noise, the floor grid read
// with the LS-110's repeatability. What the export reads, without a daemon in between.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/sim/scene.hpp"

namespace colorlab::verify::testing {

inline nlohmann::json chart_read_run(const sim::Scene& scene, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  nlohmann::json m = nlohmann::json::array();
  for (const auto& p : scene.chart().patches) {
    const sim::Spectrum read = scene.noisy_reflectance(p.reflectance, rng);
    m.push_back({
        {"quantity", "reflectance_spectrum"},
        {"value", 50.0},
        {"unit", "L*"},
        {"instrument", "spectrolino"},
        {"data", {{"id", p.name}, {"first_nm", read.start_nm}, {"step_nm", read.step_nm}, {"values", read.values}}},
    });
  }
  return {{"run", {
                      {"id", "0193c0de-0000-7000-8000-00000000c4a7"},
                      {"campaign", "chart-read"},
                      {"params", {{"chart", "sg"}, {"pitch_mm", 19.0}}},
                      {"status", "finished_ok"},
                  }},
          {"measurements", m}};
}

// The left half of the floor grid (8 × 10, as cabinet-grid measures it) for each lamp alone at each level.
inline nlohmann::json cabinet_grid_run(const sim::Scene& scene, const std::vector<sim::Lamp>& lamps,
                                       const std::vector<double>& levels, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  nlohmann::json m = nlohmann::json::array();
  for (auto lamp : lamps) {
    for (double level : levels) {
      for (int r = 0; r < sim::floor_rows; ++r) {
        for (int c = 0; c < sim::floor_cols / 2; ++c) {
          const auto [x, y] = sim::Scene::floor_spot_position_mm(r, c);
          const double truth = scene.lamp_floor_luminance(lamp, level, x, y);
          const double read = truth + scene.luminance_noise_sigma(truth) * n01(rng);
          m.push_back({
              {"quantity", "luminance"},
              {"value", read},
              {"unit", "cd/m2"},
              {"instrument", "ls110"},
              {"data", {
                           {"row", r},
                           {"col", c},
                           {"lamp", std::string(sim::to_string(lamp))},
                           {"dimmer_percent", level},
                           {"readings", {read}},
                       }},
          });
        }
      }
    }
  }
  return {{"run", {
                      {"id", "0193c0de-0000-7000-8000-0000000091d0"},
                      {"campaign", "cabinet-grid"},
                      {"params", nlohmann::json::object()},
                      {"status", "finished_ok"},
                  }},
          {"measurements", m}};
}

}  // namespace colorlab::verify::testing
