#pragma once
// The bucket as [ship] configures it (the shipper, backups and restores all use it), and what backup.cpp and
// restore.cpp share: where a bench's backups live in the bucket, their index, and the durable-file steps
// (backup.hpp describes the layout).
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/fleet/config.hpp"
#include "colorlab/fleet/s3.hpp"

namespace colorlab::fleet {

// Its keys read from their files, its stall limit from [ship] stall_timeout_s.
S3Client bucket_for(const ShipConfig& c);
// "backups/<bench_id>/"
std::string backup_prefix(const ShipConfig& c);
// {"snapshots": [...], "restores": [...]}; both empty when the bench never backed up.
nlohmann::json read_index(S3Client& s3, const ShipConfig& c);
// Through a temporary file in `scratch` (the S3 client uploads files, each with its SHA-256).
void put_json(S3Client& s3, const std::filesystem::path& scratch, const std::string& key, const nlohmann::json& doc);
// Error{io_error} naming the file when the disk refuses.
void fsync_file(const std::filesystem::path& p, bool directory = false);

}  // namespace colorlab::fleet
