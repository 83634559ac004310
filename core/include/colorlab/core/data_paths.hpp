#pragma once
// Where reference data lives. Standard CIE tables come from Debian's colord-data at run time;
// the team's shared data set (chart spectra, camera curves) is optional and only used when present.
#include <filesystem>
#include <optional>
#include <string_view>

namespace colorlab::paths {

// /usr/share/colord, or $COLORLAB_COLORD_DIR.
std::filesystem::path colord_dir();

// A file below colord_dir(), e.g. "illuminant/CIE-D65.sp"; throws Error(not_found) naming the package.
std::filesystem::path colord_file(std::string_view relative);

// $COLORLAB_SHARED_DATA, else ../shared/data relative to the source tree or the working directory.
std::optional<std::filesystem::path> shared_data_dir();

// A file in the shared data set, or nullopt when the set or the file is absent.
std::optional<std::filesystem::path> shared_data_file(std::string_view name);

// The directory holding the Python client's package (`import colorlab`, its report and study modules):
// $COLORLAB_PYTHONPATH, else installed beside the running binary (<prefix>/lib/python3/dist-packages),
// else the source tree this was built from; empty when none has it (Debian's module path may still).
std::filesystem::path python_client_dir();

}  // namespace colorlab::paths
