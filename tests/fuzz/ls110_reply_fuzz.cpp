// The LS-110 reply parser (drivers/ls110): one line from the meter. Besides ending in a typed error,
// an accepted value must be a finite number — a luminance of NaN or infinity would be stored and
// averaged as a reading — and an error reply's code must have a meaning in the table.
#include <cmath>

#include "colorlab/wire/ls110_protocol.hpp"
#include "fuzz_support.hpp"

namespace {

using colorlab::fuzz::typed;

void one_input(const std::uint8_t* data, std::size_t size) {
  colorlab::wire::ls110::Reply reply;
  if (!typed("parse_reply", [&] { reply = colorlab::wire::ls110::parse_reply(colorlab::fuzz::as_text(data, size)); })) return;
  if (!reply.ok) {
    auto code = colorlab::wire::ls110::lookup_error(reply.error_code);
    if (code.meaning.empty()) {
      std::fprintf(stderr, "fuzz: LS-110 error code '%s' has no meaning\n", reply.error_code.c_str());
      std::abort();
    }
    return;
  }
  if (reply.value && !std::isfinite(*reply.value)) {
    std::fprintf(stderr, "fuzz: LS-110 reply accepted with a non-finite value %f\n", *reply.value);
    std::abort();
  }
}

}  // namespace

COLORLAB_FUZZ_TARGET("ls110_reply", one_input)
