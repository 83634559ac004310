#pragma once
// A Spectrolino (on a SpectroScan T or stand-alone) simulator on a pty, sharing one io_context with
// the driver under test; the Scene's chart and tile are the ground truth.
#include <memory>

#include <boost/asio/io_context.hpp>
#include <gtest/gtest.h>

#include "colorlab/drivers/spectrolino.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/sim/spectrolino_sim.hpp"
#include "run_support.hpp"

namespace colorlab::test {

class SpectrolinoSimTest : public ::testing::Test {
 protected:
  // Fast enough for unit-test budgets; the benchmark runs the same code at time scale 1.
  static constexpr double kTimeScale = 400.0;

  void start(bool table, double time_scale = kTimeScale) {
    clock_ = std::make_shared<sim::SimClock>(time_scale);
    sim::SceneConfig sc;
    sc.seed = 7;
    sc.force_synthetic_chart = true;          // deterministic without the shared data set
    sc.lamps_on_at_start = {sim::Lamp::d65};  // already warm: emission truth does not drift during a test
    scene_ = std::make_unique<sim::Scene>(sc, clock_);
    sim::SpectrolinoConfig cfg;
    cfg.table = table;
    sim_ = std::make_shared<sim::SpectrolinoSim>(io_.get_executor(), *scene_, cfg, 11, time_scale);
    sim_->start();
  }

  drivers::SpectrolinoOptions options() const {
    drivers::SpectrolinoOptions o;
    o.id = "spectro";
    o.port = sim_->port_path();
    o.simulated = true;
    // Device times are divided by the time scale, so these bound real waits of a few ms.
    o.timeouts.command = std::chrono::milliseconds(600);
    o.timeouts.measure = std::chrono::milliseconds(800);
    o.timeouts.move = std::chrono::milliseconds(800);
    o.timeouts.init = std::chrono::milliseconds(1000);
    o.timeouts.probe = std::chrono::milliseconds(100);
    o.reconnect.initial_backoff = std::chrono::milliseconds(10);
    o.reconnect.max_attempts = 3;
    return o;
  }

  // Chart layout of the Scene's ColorChecker SG as the simulator places it on the table:
  // strips are columns A..N (patches A1..A10 first), as the chart's patch numbering runs.
  drivers::ChartLayout chart_layout() const {
    const auto& cfg = sim_->model().config();
    const auto& p = scene_->chart().patches;
    drivers::ChartLayout l;
    l.origin_x_mm = cfg.chart_origin_x_mm + p[0].x_mm + p[0].size_mm / 2;
    l.origin_y_mm = cfg.chart_origin_y_mm + p[0].y_mm + p[0].size_mm / 2;
    l.step_x_mm = p[1].x_mm - p[0].x_mm;
    l.step_y_mm = p[1].y_mm - p[0].y_mm;
    l.pass_x_mm = p[10].x_mm - p[0].x_mm;
    l.pass_y_mm = p[10].y_mm - p[0].y_mm;
    l.patches_per_strip = sim::chart_rows;
    l.strips = sim::chart_columns;
    return l;
  }

  void TearDown() override {
    if (sim_) sim_->stop();
    settle(io_, std::chrono::milliseconds(5));
  }

  boost::asio::io_context io_;
  std::shared_ptr<sim::SimClock> clock_;
  std::unique_ptr<sim::Scene> scene_;
  std::shared_ptr<sim::SpectrolinoSim> sim_;
};

}  // namespace colorlab::test
