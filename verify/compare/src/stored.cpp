#include "colorlab/verify/compare/stored.hpp"

namespace colorlab::verify {

nlohmann::json verification_params(const std::string& rendering, const std::vector<std::string>& against,
                                   const CompareOptions& options, const nlohmann::json& placement) {
  nlohmann::json params{
      {"rendering", rendering},
      {"against", against},
      {"scale", options.scale ? nlohmann::json(*options.scale) : nlohmann::json(nullptr)},
      {"k", options.k},
      // Whether the rendering's own noise was budgeted, and over how many regions it was pooled (null when off).
      {"rendering_noise", options.rendering_noise},
      {"noise_neighbours", options.rendering_noise ? nlohmann::json(options.noise_neighbours) : nlohmann::json(nullptr)},
      {"noise_pooling", options.rendering_noise ? nlohmann::json(kNoisePooling) : nlohmann::json(nullptr)},
  };
  if (!placement.is_null()) params["placement"] = placement;
  return params;
}

nlohmann::json params_read_back(nlohmann::json params) {
  if (params.is_object() && !params.contains("noise_pooling")) params["noise_pooling"] = nullptr;
  return params;
}

StoredVerification to_store(const Verification& v, const std::string& rendering, const std::vector<std::string>& against,
                            const CompareOptions& options, const nlohmann::json& placement) {
  StoredVerification s;
  s.params = verification_params(rendering, against, options, placement);
  const auto full = v.to_json();
  s.summary = full["summary"];
  s.summary["floor_difference"] = full["floor_difference"];
  for (std::size_t i = 0; i < v.comparisons.size(); ++i) {
    const auto& c = v.comparisons[i];
    records::Measurement m;
    m.step = c.kind + "/" + c.where;
    m.instrument_id = "verify";
    m.quantity = c.kind == "colour_7_3" ? "delta_e00" : "relative_difference";
    m.value = c.difference;
    m.unit = c.kind == "colour_7_3" ? "ΔE00" : "1";
    m.data = full["comparisons"][i];
    s.measurements.push_back(std::move(m));
  }
  return s;
}

int exit_status(const Verification& v) { return v.differs() ? kExitDiffers : kExitAgrees; }

}  // namespace colorlab::verify
