#include "colorlab/analysis/chart_photo.hpp"

#include <cstring>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

PhotoView Photo::view() const {
  PhotoView v;
  v.data = bytes.data();
  v.width = width;
  v.height = height;
  v.channels = channels;
  v.type = type;
  return v;
}

Photo read_photo(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error(ErrorClass::not_found, "photo " + path.string() + " does not exist");
  cv::Mat m;
  try {
    m = cv::imread(path.string(), cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
  } catch (const cv::Exception& e) {
    throw Error(ErrorClass::bad_data, "photo " + path.string() + ": " + e.what());
  }
  if (m.empty())
    throw Error(ErrorClass::bad_data, "photo " + path.string() + " is not an image OpenCV can read",
                "use TIFF (8 or 16 bit), JPEG, PNG or PGM; convert a camera raw with dcraw -D -4 -T");
  if (m.depth() != CV_8U && m.depth() != CV_16U)
    throw Error(ErrorClass::bad_data, "photo " + path.string() + " has samples that are neither 8 nor 16 bit");
  if (m.channels() == 4) cv::cvtColor(m, m, cv::COLOR_BGRA2BGR);
  if (m.channels() == 3) cv::cvtColor(m, m, cv::COLOR_BGR2RGB);
  if (m.channels() != 1 && m.channels() != 3)
    throw Error(ErrorClass::bad_data, "photo " + path.string() + " has " + std::to_string(m.channels()) + " channels");
  Photo p;
  p.width = m.cols;
  p.height = m.rows;
  p.channels = m.channels();
  p.type = m.depth() == CV_8U ? SampleType::u8 : SampleType::u16;
  const std::size_t row = static_cast<std::size_t>(m.cols) * m.elemSize();
  p.bytes.resize(row * static_cast<std::size_t>(m.rows));
  for (int y = 0; y < m.rows; ++y) std::memcpy(p.bytes.data() + row * static_cast<std::size_t>(y), m.ptr(y), row);
  return p;
}

}  // namespace colorlab::analysis
