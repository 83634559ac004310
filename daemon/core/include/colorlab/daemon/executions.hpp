#pragma once
// Starts campaigns as observable executions (SiLA): a POST creates the run and its execution in
// one transaction and returns at once; the campaign runs as a coroutine on the daemon's
// executor, recording each measurement durably and updating progress as it goes.
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/campaign.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class Executions {
 public:
  Executions(boost::asio::io_context& io, store::Store& store, const campaigns::CampaignRegistry& campaigns,
             const campaigns::InstrumentSet& instruments);

  // Validates, records and launches. Throws Error{bad_parameter|not_found} before anything starts.
  store::ExecutionRecord start(const std::string& campaign, const nlohmann::json& params,
                               const std::optional<std::string>& idempotency_key);
  std::size_t running() const { return running_; }

 private:
  boost::asio::io_context& io_;
  store::Store& store_;
  const campaigns::CampaignRegistry& campaigns_;
  const campaigns::InstrumentSet& instruments_;
  std::size_t running_ = 0;
};

}  // namespace colorlab::daemon
