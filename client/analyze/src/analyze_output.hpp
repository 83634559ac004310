#pragma once
// One table type that prints as CSV or JSON, so every analyze subcommand formats alike.
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::cli::detail {

// A table cell: text or a number.
struct Cell {
  Cell(std::string t) : text(std::move(t)), is_text(true) {}  // NOLINT: implicit by design, rows read like literals
  Cell(const char* t) : text(t), is_text(true) {}             // NOLINT
  Cell(double v) : number(v) {}                               // NOLINT
  std::string text;
  double number = 0;
  bool is_text = false;
};

struct Table {
  std::string name;
  std::vector<std::string> columns;
  std::vector<std::vector<Cell>> rows;
};

void print_tables(std::ostream& os, const std::vector<Table>& tables, bool json);

}  // namespace colorlab::cli::detail
