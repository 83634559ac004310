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
          if (const auto* s = std::get_if<std::string>(&r[i])) o[t.columns[i]] = *s;
          else {
            double v = std::get<double>(r[i]);
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
        if (const auto* s = std::get_if<std::string>(&r[i])) {
          bool quote = s->find_first_of(",\"") != std::string::npos;
          os << (quote ? "\"" : "") << *s << (quote ? "\"" : "");
        } else {
          os << std::setprecision(6) << std::get<double>(r[i]);
        }
      }
      os << "\n";
    }
  }
}

}  // namespace colorlab::cli::detail
