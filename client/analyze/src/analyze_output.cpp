#include "analyze_output.hpp"

#include <cmath>
#include <iomanip>

namespace colorlab::cli::detail {

void print_tables(std::ostream& os, const std::vector<Table>& tables, bool json) {
  if (json) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& t : tables) {
      nlohmann::json rows = nlohmann::json::array();
      for (const auto& r : t.rows) {
        nlohmann::json o = nlohmann::json::object();
        for (std::size_t i = 0; i < r.size() && i < t.columns.size(); ++i) {
          if (r[i].is_text) {
            o[t.columns[i]] = r[i].text;
          } else {
            const double v = r[i].number;
            o[t.columns[i]] = std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
          }
        }
        rows.push_back(std::move(o));
      }
      out[t.name] = std::move(rows);
    }
    os << out.dump(2) << "\n";
    return;
  }
  bool first = true;
  for (const auto& t : tables) {
    if (!first) os << "\n";
    first = false;
    if (tables.size() > 1) os << "# " << t.name << "\n";
    for (std::size_t i = 0; i < t.columns.size(); ++i) os << (i ? "," : "") << t.columns[i];
    os << "\n";
    for (const auto& r : t.rows) {
      for (std::size_t i = 0; i < r.size(); ++i) {
        if (i) os << ",";
        if (r[i].is_text) {
          bool quote = r[i].text.find_first_of(",\"") != std::string::npos;
          os << (quote ? "\"" : "") << r[i].text << (quote ? "\"" : "");
        } else {
          const double v = r[i].number;
          os << std::setprecision(6) << (std::abs(v) < 1e-9 ? 0.0 : v);  // no "-2.8e-13" for an exact zero
        }
      }
      os << "\n";
    }
  }
}

}  // namespace colorlab::cli::detail
