#pragma once
// One table type that prints as CSV or JSON, so every analyze subcommand formats alike.
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::cli::detail {

struct Table {
  std::string name;
  std::vector<std::string> columns;
  std::vector<std::vector<std::variant<std::string, double>>> rows;
};

void print_tables(std::ostream& os, const std::vector<Table>& tables, bool json);

}  // namespace colorlab::cli::detail
