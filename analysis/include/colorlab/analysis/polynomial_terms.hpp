#pragma once
// Polynomial term sets for RGB → colour mappings: the dissertation's eleven (§7.3), Hong/Cheung's 3×n family and
// Finlayson's root-polynomials.
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

namespace colorlab::analysis {

// r^e0 · g^e1 · b^e2; root-polynomial terms have fractional exponents (e.g. √(rg) = {½, ½, 0}).
struct Term {
  std::array<double, 3> exponent{};
  std::string label() const;  // "r", "rg", "r^2g^2", "1", "(rg)^1/2" ...
};

struct TermSet {
  std::string name;  // "poly:10", "hong:11", "rootpoly:2"
  std::vector<Term> terms;
  std::size_t size() const { return terms.size(); }
  std::string describe() const;  // comma-separated labels
};

// §7.3 sets 1..11 exactly as the dissertation lists them (set 10: r³, g³ where the OCR shows r³g³).
TermSet dissertation_set(int number);
// Hong, Luo & Rhodes (2001) / Cheung et al. (2004) sizes 3, 5, 7, 8, 10, 11, 14, 16, 17, 19, 20.
TermSet hong_cheung_set(int terms);
inline constexpr std::array<int, 11> kHongCheungSizes{3, 5, 7, 8, 10, 11, 14, 16, 17, 19, 20};
// Finlayson, Mackiewicz & Hurlbert (2015) root-polynomials of degree 1..4 (3, 6, 13, 22 terms).
TermSet root_polynomial_set(int degree);
// "poly:N", "hong:N", "rootpoly:D", "ccm" (= hong:3); throws Error(bad_parameter).
TermSet term_set_by_name(const std::string& name);
// Every set of the three families.
std::vector<TermSet> all_term_sets();

// n × m design matrix; inputs are clamped at 0 for fractional exponents (a root of a negative count is noise).
Eigen::MatrixXd expand_terms(const TermSet& set, const Eigen::MatrixXd& rgb);

}  // namespace colorlab::analysis
