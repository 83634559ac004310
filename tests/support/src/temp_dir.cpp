#include "colorlab/testing/temp_dir.hpp"

#include <stdlib.h>

#include <stdexcept>
#include <string>

namespace colorlab::testing {

TempDir::TempDir() {
  std::string tmpl = (std::filesystem::temp_directory_path() / "colorlab-test-XXXXXX").string();
  if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
  path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

}  // namespace colorlab::testing
