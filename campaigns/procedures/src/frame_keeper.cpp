#include "colorlab/campaigns/frame_keeper.hpp"

#include <algorithm>
#include <cctype>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

json KeptBlob::to_json() const {
  return json{{"sha256", sha256}, {"name", name}, {"kind", kind}, {"media_type", media_type}, {"size", size}, {"meta", meta}};
}

KeptBlob KeptBlob::from_json(const json& j) {
  KeptBlob b;
  try {
    b.sha256 = j.at("sha256").get<std::string>();
    b.name = j.at("name").get<std::string>();
    b.kind = j.at("kind").get<std::string>();
    b.media_type = j.at("media_type").get<std::string>();
    b.size = j.at("size").get<std::uint64_t>();
    if (j.contains("meta") && j["meta"].is_object()) b.meta = j["meta"];
  } catch (const json::exception& e) {
    throw Error(ErrorClass::internal, std::string("a blob reference in a call's result is malformed: ") + e.what());
  }
  return b;
}

std::vector<KeptBlob> kept_blobs(const json& call_result) {
  std::vector<KeptBlob> out;
  if (!call_result.is_object() || !call_result.contains("blobs") || !call_result["blobs"].is_array()) return out;
  for (const auto& b : call_result["blobs"]) out.push_back(KeptBlob::from_json(b));
  return out;
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
