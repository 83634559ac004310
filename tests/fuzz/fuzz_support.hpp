#pragma once
// What every fuzz target holds its parser to: bad input ends in a typed colorlab::Error, nothing
// else. Any other exception (std::out_of_range, a JSON library's type_error, ...) is a finding, so
// it aborts with its text; crashes, leaks and undefined behaviour are the sanitizers' to report.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>
#include <string_view>

#include "colorlab/core/error.hpp"

namespace colorlab::fuzz {

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs one parse; true when it accepted the input, false when it refused it with a colorlab::Error.
template <class F>
bool typed(const char* what, F&& parse) {
  try {
    parse();
    return true;
  } catch (const Error&) {
    return false;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: %s threw a non-colorlab exception: %s\n", what, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: %s threw a non-exception\n", what);
    std::abort();
  }
}

using Target = void (*)(const std::uint8_t* data, std::size_t size);

// Every target the regression test knows, by name (the normal build registers them instead of
// defining libFuzzer's entry point, so one GoogleTest binary replays every target's files).
inline std::map<std::string, Target>& targets() {
  static std::map<std::string, Target> all;
  return all;
}

}  // namespace colorlab::fuzz

// COLORLAB_FUZZ_TARGET("cgats", one_input): libFuzzer's entry point in the fuzz build, an entry in
// targets() in the normal build.
#if defined(COLORLAB_LIBFUZZER)
#define COLORLAB_FUZZ_TARGET(name, fn)                                                \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    fn(data, size);                                                                   \
    return 0;                                                                         \
  }
#else
#define COLORLAB_FUZZ_TARGET(name, fn) \
  [[maybe_unused]] static const bool colorlab_fuzz_registered = (::colorlab::fuzz::targets()[name] = fn, true);
#endif
