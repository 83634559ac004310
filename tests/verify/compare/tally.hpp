#pragma once
// Counting verdicts over repeated draws, by kind and by whether a comparison sits where a defect was planted.
#include <cstdio>
#include <functional>
#include <map>
#include <string>

#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify::testing {

struct Count {
  long n = 0, flagged = 0;
  double rate() const { return n ? static_cast<double>(flagged) / static_cast<double>(n) : 0.0; }
  void add(bool differs) {
    ++n;
    flagged += differs ? 1 : 0;
  }
};

// Per kind, split by `at_defect(comparison)`.
struct Tally {
  std::map<std::string, Count> at, elsewhere;
  Count all_elsewhere;
  void add(const Verification& v, const std::function<bool(const Comparison&)>& at_defect) {
    for (const auto& c : v.comparisons) {
      const bool d = c.verdict == Verdict::differs;
      if (at_defect(c)) {
        at[c.kind].add(d);
      } else {
        elsewhere[c.kind].add(d);
        all_elsewhere.add(d);
      }
    }
  }
  void print(const char* title) const {
    std::printf("%s\n", title);
    for (const auto& [k, c] : at) std::printf("  at the defect  %-12s flagged %6.2f %% of %ld\n", k.c_str(), 100 * c.rate(), c.n);
    for (const auto& [k, c] : elsewhere)
      std::printf("  elsewhere      %-12s flagged %6.2f %% of %ld\n", k.c_str(), 100 * c.rate(), c.n);
  }
};

}  // namespace colorlab::verify::testing
