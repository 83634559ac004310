#include "colorlab/campaigns/frame_keeper.hpp"

#include <algorithm>
#include <cctype>
#include <utility>

namespace colorlab::campaigns {

using nlohmann::json;

json blob_json(const KeptBlob& b) {
  return json{{"sha256", b.sha256}, {"name", b.name}, {"kind", b.kind}, {"media_type", b.media_type}, {"size", b.size}, {"meta", b.meta}};
}

KeptBlob KeepLedger::noted(KeptBlob b) {
  std::lock_guard lock(mutex_);
  kept_.push_back(b);
  return b;
}

KeptBlob KeepLedger::keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type,
                                const json& meta, std::span<const std::uint8_t> bytes) {
  return noted(keeper_->keep_bytes(name, kind, media_type, meta, bytes));
}

KeptBlob KeepLedger::keep_file(const std::string& name, const std::string& kind, const std::string& media_type,
                               const json& meta, const std::filesystem::path& file) {
  return noted(keeper_->keep_file(name, kind, media_type, meta, file));
}

KeptBlob KeepLedger::keep_preview(const std::string& name, const KeptBlob& of) { return noted(keeper_->keep_preview(name, of)); }

std::vector<KeptBlob> KeepLedger::take() {
  std::lock_guard lock(mutex_);
  return std::exchange(kept_, {});
}

std::string media_type_of(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".dng") return "image/x-adobe-dng";
  if (ext == ".cr2") return "image/x-canon-cr2";
  if (ext == ".nef") return "image/x-nikon-nef";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".tif" || ext == ".tiff") return "image/tiff";
  if (ext == ".png") return "image/png";
  return "application/octet-stream";
}

}  // namespace colorlab::campaigns
