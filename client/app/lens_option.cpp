#include "lens_option.hpp"

#include <sstream>
#include <stdexcept>
#include <vector>

#include "colorlab/core/error.hpp"

namespace colorlab::cli {

std::optional<verify::CameraIntrinsics> parse_lens(const std::string& text) {
  if (text.empty()) return std::nullopt;
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, "--lens: \"" + item + "\" is not a number", "--lens fx,fy,cx,cy[,k1,k2] in pixels");
    }
  }
  if (v.size() != 4 && v.size() != 6)
    throw Error(ErrorClass::bad_parameter, "--lens needs 4 or 6 numbers, got " + std::to_string(v.size()),
                "--lens fx,fy,cx,cy[,k1,k2] (OpenCV's model, pixels of the photograph)");
  verify::CameraIntrinsics k{v[0], v[1], v[2], v[3], 0, 0};
  if (v.size() == 6) k.k1 = v[4], k.k2 = v[5];
  return k;
}

}  // namespace colorlab::cli
