#include "colorlab/analysis/polynomial_terms.hpp"

#include <cmath>
#include <sstream>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {
Term t(double r, double g, double b) { return Term{{r, g, b}}; }

// Monomials spelled like the dissertation: "r", "rg", "r2g2b2", "1".
std::vector<Term> parse_list(std::initializer_list<const char*> spec) {
  std::vector<Term> out;
  for (const char* s : spec) {
    Term term;
    std::string str(s);
    if (str != "1") {
      for (std::size_t i = 0; i < str.size(); ++i) {
        int ch = str[i] == 'r' ? 0 : str[i] == 'g' ? 1
                                                   : 2;
        int e = 1;
        if (i + 1 < str.size() && std::isdigit(static_cast<unsigned char>(str[i + 1]))) e = str[++i] - '0';
        term.exponent[static_cast<std::size_t>(ch)] += e;
      }
    }
    out.push_back(term);
  }
  return out;
}

std::string fmt_exp(double e) {
  if (std::abs(e - std::round(e)) < 1e-12) return std::to_string(static_cast<int>(std::round(e)));
  std::ostringstream os;
  os << e;
  return os.str();
}
}  // namespace

std::string Term::label() const {
  double total = exponent[0] + exponent[1] + exponent[2];
  if (total == 0) return "1";
  bool integral = true;
  for (double e : exponent) integral = integral && std::abs(e - std::round(e)) < 1e-12;
  const char* names = "rgb";
  std::string s;
  if (integral) {
    for (int c = 0; c < 3; ++c) {
      int e = static_cast<int>(std::round(exponent[static_cast<std::size_t>(c)]));
      if (e == 0) continue;
      s += names[c];
      if (e > 1) s += "^" + std::to_string(e);
    }
    return s;
  }
  // Root-polynomial: (r^a g^b b^c)^(1/d) with integer a, b, c; find the smallest such d.
  int d = 2;
  for (; d < 12; ++d) {
    bool ok = true;
    for (double e : exponent) ok = ok && std::abs(e * d - std::round(e * d)) < 1e-9;
    if (ok) break;
  }
  for (int c = 0; c < 3; ++c) {
    int e = static_cast<int>(std::round(exponent[static_cast<std::size_t>(c)] * d));
    if (e == 0) continue;
    s += names[c];
    if (e > 1) s += "^" + fmt_exp(e);
  }
  return "(" + s + ")^1/" + std::to_string(d);
}

std::string TermSet::describe() const {
  std::string s;
  for (std::size_t i = 0; i < terms.size(); ++i) s += (i ? ", " : "") + terms[i].label();
  return s;
}

TermSet dissertation_set(int n) {
  TermSet s;
  s.name = "poly:" + std::to_string(n);
  switch (n) {
    case 1: s.terms = parse_list({"r", "g", "b"}); break;
    case 2: s.terms = parse_list({"r", "g", "b", "rgb", "1"}); break;
    case 3: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb"}); break;
    case 4: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "rgb", "1"}); break;
    case 5: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2"}); break;
    case 6: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "rgb", "1"}); break;
    case 7: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "r3", "g3", "b3", "1"}); break;
    case 8:
      s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "r2g2", "r2b2", "g2b2", "r2g2b2", "r3",
                            "g3", "b3", "r3g3", "r3b3", "g3b3", "1"});
      break;
    case 9:
      s.terms = parse_list(
          {"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "r3", "g3", "b3", "r4", "g4", "b4", "1"});
      break;
    case 10:
      s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "rgb", "r2", "g2", "b2",
                            "r2g2", "r2b2", "g2b2", "r2g2b2", "r3", "g3", "b3", "r3g3", "r3b3", "g3b3",
                            "r3g3b3", "r4", "g4", "b4", "r4g4", "r4b4", "g4b4", "r4g4b4", "1"});
      break;
    case 11:
      s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "r3", "g3", "b3", "r4", "g4", "b4", "r5",
                            "g5", "b5", "1"});
      break;
    default:
      throw Error(ErrorClass::bad_parameter, "the dissertation lists polynomial sets 1-11, not " + std::to_string(n));
  }
  return s;
}

TermSet hong_cheung_set(int n) {
  const std::vector<Term> base = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "rgb"});
  TermSet s;
  s.name = "hong:" + std::to_string(n);
  switch (n) {
    case 3: s.terms = parse_list({"r", "g", "b"}); break;
    case 5: s.terms = parse_list({"r", "g", "b", "rgb", "1"}); break;
    case 7: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "rgb"}); break;
    case 8: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "rgb", "1"}); break;
    case 10: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "1"}); break;
    case 11: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "rgb", "1"}); break;
    case 14: s.terms = parse_list({"r", "g", "b", "rg", "rb", "gb", "r2", "g2", "b2", "rgb", "r3", "g3", "b3", "1"}); break;
    case 16:
    case 17:
      s.terms = base;
      for (auto& x : parse_list({"r2g", "g2b", "b2r", "r3", "g3", "b3"})) s.terms.push_back(x);
      if (n == 17) s.terms.push_back(t(0, 0, 0));
      break;
    case 19:
    case 20:
      s.terms = base;
      for (auto& x : parse_list({"r2g", "g2b", "b2r", "r2b", "g2r", "b2g", "r3", "g3", "b3"})) s.terms.push_back(x);
      if (n == 20) s.terms.push_back(t(0, 0, 0));
      break;
    default:
      throw Error(ErrorClass::bad_parameter,
                  "Hong/Cheung term sets have 3, 5, 7, 8, 10, 11, 14, 16, 17, 19 or 20 terms, not " + std::to_string(n));
  }
  return s;
}

TermSet root_polynomial_set(int degree) {
  if (degree < 1 || degree > 4)
    throw Error(ErrorClass::bad_parameter, "root-polynomial degree must be 1-4, not " + std::to_string(degree));
  TermSet s;
  s.name = "rootpoly:" + std::to_string(degree);
  s.terms = {t(1, 0, 0), t(0, 1, 0), t(0, 0, 1)};
  auto root = [](double a, double b, double c) {
    double d = a + b + c;
    return t(a / d, b / d, c / d);
  };
  if (degree >= 2) {
    s.terms.push_back(root(1, 1, 0));
    s.terms.push_back(root(0, 1, 1));
    s.terms.push_back(root(1, 0, 1));
  }
  if (degree >= 3) {
    for (auto e : {std::array<double, 3>{1, 2, 0}, {0, 1, 2}, {1, 0, 2}, {2, 1, 0}, {0, 2, 1}, {2, 0, 1}, {1, 1, 1}})
      s.terms.push_back(root(e[0], e[1], e[2]));
  }
  if (degree >= 4) {
    for (auto e : {
             std::array<double, 3>{3, 1, 0},
             {3, 0, 1},
             {1, 3, 0},
             {0, 3, 1},
             {1, 0, 3},
             {0, 1, 3},
             {2, 1, 1},
             {1, 2, 1},
             {1, 1, 2},
         })
      s.terms.push_back(root(e[0], e[1], e[2]));
  }
  return s;
}

TermSet term_set_by_name(const std::string& name) {
  if (name == "ccm") {
    TermSet s = hong_cheung_set(3);
    s.name = "ccm";
    return s;
  }
  auto colon = name.find(':');
  if (colon == std::string::npos)
    throw Error(ErrorClass::bad_parameter, "method '" + name + "' is not poly:N, hong:N, rootpoly:D or ccm");
  std::string family = name.substr(0, colon);
  int n = 0;
  try {
    std::size_t used = 0;
    n = std::stoi(name.substr(colon + 1), &used);
    if (used != name.size() - colon - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, "method '" + name + "': '" + name.substr(colon + 1) + "' is not a number");
  }
  if (family == "poly") return dissertation_set(n);
  if (family == "hong") return hong_cheung_set(n);
  if (family == "rootpoly") return root_polynomial_set(n);
  throw Error(ErrorClass::bad_parameter, "unknown term family '" + family + "' (poly, hong, rootpoly)");
}

std::vector<TermSet> all_term_sets() {
  std::vector<TermSet> v;
  for (int i = 1; i <= 11; ++i) v.push_back(dissertation_set(i));
  for (int n : kHongCheungSizes) v.push_back(hong_cheung_set(n));
  for (int d = 1; d <= 4; ++d) v.push_back(root_polynomial_set(d));
  return v;
}

Eigen::MatrixXd expand_terms(const TermSet& set, const Eigen::MatrixXd& rgb) {
  if (rgb.cols() != 3) throw Error(ErrorClass::bad_data, "RGB input must have 3 columns, has " + std::to_string(rgb.cols()));
  Eigen::MatrixXd X(rgb.rows(), static_cast<Eigen::Index>(set.size()));
  for (Eigen::Index i = 0; i < rgb.rows(); ++i) {
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(rgb(i, c)))
        throw Error(ErrorClass::bad_data, "RGB sample " + std::to_string(i + 1) + " is not finite");
    for (std::size_t j = 0; j < set.size(); ++j) {
      const auto& e = set.terms[j].exponent;
      double v = 1;
      for (int c = 0; c < 3; ++c) {
        double ec = e[static_cast<std::size_t>(c)];
        if (ec == 0) continue;
        double x = rgb(i, c);
        if (ec == std::round(ec)) {
          double p = 1;
          for (int k = 0; k < static_cast<int>(ec); ++k) p *= x;
          v *= p;
        } else {
          v *= std::pow(std::max(x, 0.0), ec);
        }
      }
      X(i, static_cast<Eigen::Index>(j)) = v;
    }
  }
  return X;
}

}  // namespace colorlab::analysis
