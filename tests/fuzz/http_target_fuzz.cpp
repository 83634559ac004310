// The request target of every API call (daemon/http message.cpp): path and query string split and
// percent-decoded by HttpRequest::parse_target. It reports a malformed target by returning false.
#include "colorlab/http/message.hpp"
#include "fuzz_support.hpp"

namespace {

void one_input(const std::uint8_t* data, std::size_t size) {
  colorlab::http::HttpRequest req;
  req.target = std::string(colorlab::fuzz::as_text(data, size));
  colorlab::fuzz::typed("parse_target", [&] {
    if (req.parse_target() && (req.target.empty() || req.target[0] != '/')) {
      std::fprintf(stderr, "fuzz: parse_target accepted a target that is not origin-form\n");
      std::abort();
    }
  });
}

}  // namespace

COLORLAB_FUZZ_TARGET("http_target", one_input)
