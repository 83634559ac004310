#pragma once
// A bench for the fleet tests: colorlabd's own Store and BlobStore in a state directory, driven the way the
// daemon's campaign runner drives them (create, start, one committed step per patch with its measurement and
// frames, finish with a status), plus the TOML colorlab-ship reads.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>

#include "colorlab/protocol/states.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::fleet_test {

struct ShipTarget {
  std::string postgres;
  std::string s3_endpoint;
  std::string bucket;
  std::string access_key;
  std::string secret_key;
};

class SimBench {
 public:
  SimBench(std::filesystem::path state_dir, std::string bench_id, std::uint64_t seed);

  // A campaign of `patches` steps (one measurement each, every `blob_every`-th step keeps a frame) that ends
  // with `status`; `end` = false leaves it running. Returns the run id.
  std::string run_campaign(protocol::ExecutionStatus status, int patches, int blob_every = 10, bool end = true);
  // Ends a run left running by run_campaign(..., end = false).
  void finish(const std::string& run_id, protocol::ExecutionStatus status);
  // Writes <state_dir>/colorlabd.toml with [ship] aimed at `target`; returns its path.
  std::filesystem::path write_config(const ShipTarget& target, int batch_runs = 50);

  const std::filesystem::path& state_dir() const { return state_dir_; }
  std::filesystem::path database() const { return state_dir_ / "colorlab.db"; }
  const std::string& bench_id() const { return bench_id_; }
  store::Store& store() { return *store_; }

 private:
  std::filesystem::path state_dir_;
  std::string bench_id_;
  std::mt19937_64 rng_;
  std::unique_ptr<store::Store> store_;
  store::BlobStore blobs_;
  std::map<std::string, store::ExecutionRecord> open_;
};

}  // namespace colorlab::fleet_test
