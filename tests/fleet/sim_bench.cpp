#include "sim_bench.hpp"

#include <fstream>

namespace colorlab::fleet_test {

namespace fs = std::filesystem;
using protocol::ExecutionStatus;

SimBench::SimBench(fs::path state_dir, std::string bench_id, std::uint64_t seed)
    : state_dir_(std::move(state_dir)), bench_id_(std::move(bench_id)), rng_(seed),
      store_((fs::create_directories(state_dir_), std::make_unique<store::Store>(state_dir_ / "colorlab.db"))),
      blobs_(state_dir_ / "blobs") {}

std::string SimBench::run_campaign(ExecutionStatus status, int patches, int blob_every, bool end) {
  store::NewRun nr;
  nr.campaign = "chart-read";
  nr.params = {{"patches", patches}, {"note", "tab\there, newline\nthere, back\\slash, é"}};
  nr.simulated = true;
  nr.instruments = nlohmann::json::array({{{"id", "meter"}, {"kind", "spectrolino"}}});
  auto created = store_->create_execution(nr);
  auto e = created.execution;
  store_->start_execution(e);
  std::uniform_real_distribution<double> value(0.0, 100.0);
  std::uniform_int_distribution<int> size(1024, 48 * 1024);
  for (int i = 1; i <= patches; ++i) {
    store::StepRecord step;
    step.step = "patch-" + std::to_string(i);
    step.progress = static_cast<double>(i) / patches;
    store::MeasurementRow m;
    m.step = step.step;
    m.instrument_id = "meter";
    m.simulated = true;
    m.quantity = "Y";
    // A measurement without a value now and then: NULL must ship as NULL and hash as one.
    if (i % 17 != 0) m.value = value(rng_);
    m.unit = "cd/m2";
    m.data = {{"xyz", {value(rng_), value(rng_), value(rng_)}}};
    step.measurements.push_back(m);
    if (blob_every > 0 && i % blob_every == 0) {
      std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size(rng_)));
      for (auto& b : bytes) b = static_cast<std::uint8_t>(rng_());
      const std::string sha = blobs_.put(bytes);
      step.blobs.push_back({sha, step.step + "/frame", "raw", "application/x-colorlab-array", bytes.size(), {}});
    }
    store_->commit_step(e, step);
  }
  if (end) {
    store_->finish_execution(e, status, "done", {{"patches", patches}},
                             status == ExecutionStatus::finished_ok ? nlohmann::json(nullptr)
                                                                    : nlohmann::json{{"title", "simulated end"}},
                             "simulated");
  } else {
    open_[e.run_id] = e;
  }
  return e.run_id;
}

void SimBench::finish(const std::string& run_id, ExecutionStatus status) {
  auto e = open_.at(run_id);
  store_->finish_execution(e, status, "done", {{"late", true}}, nullptr, "simulated");
  open_.erase(run_id);
}

fs::path SimBench::write_config(const ShipTarget& t, int batch_runs) {
  std::ofstream(state_dir_ / "s3-access-key") << t.access_key << "\n";
  std::ofstream(state_dir_ / "s3-secret-key") << t.secret_key << "\n";
  const fs::path file = state_dir_ / "colorlabd.toml";
  std::ofstream out(file);
  out << "state_dir = \"" << state_dir_.string() << "\"\n\n[ship]\n"
      << "bench_id = \"" << bench_id_ << "\"\n"
      << "bench_name = \"Simulated " << bench_id_ << "\"\n"
      << "postgres = \"" << t.postgres << "\"\n"
      << "s3_endpoint = \"" << t.s3_endpoint << "\"\n"
      << "bucket = \"" << t.bucket << "\"\n"
      << "region = \"us-east-1\"\n"
      << "access_key_file = \"s3-access-key\"\n"
      << "secret_key_file = \"s3-secret-key\"\n"
      << "batch_runs = " << batch_runs << "\n";
  return file;
}

}  // namespace colorlab::fleet_test
