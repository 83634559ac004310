#include "colorlab/analysis/color_difference.hpp"

#include <cmath>
#include <numbers>

namespace colorlab::analysis {

double delta_e76(const Lab& a, const Lab& b) { return std::hypot(a.L - b.L, a.a - b.a, a.b - b.b); }

double delta_e_uv(const Luv& a, const Luv& b) { return std::hypot(a.L - b.L, a.u - b.u, a.v - b.v); }

double delta_e2000(const Lab& p, const Lab& q, double kL, double kC, double kH) {
  constexpr double pi = std::numbers::pi;
  auto deg = [](double r) { return r * 180.0 / pi; };
  auto rad = [](double d) { return d * pi / 180.0; };
  const double C1 = std::hypot(p.a, p.b), C2 = std::hypot(q.a, q.b);
  const double Cbar = (C1 + C2) / 2;
  const double Cbar7 = std::pow(Cbar, 7);
  const double G = 0.5 * (1 - std::sqrt(Cbar7 / (Cbar7 + std::pow(25.0, 7))));
  const double a1 = (1 + G) * p.a, a2 = (1 + G) * q.a;
  const double C1p = std::hypot(a1, p.b), C2p = std::hypot(a2, q.b);
  auto hue = [&](double b, double a) {
    if (a == 0 && b == 0) return 0.0;
    double h = deg(std::atan2(b, a));
    return h < 0 ? h + 360 : h;
  };
  const double h1 = hue(p.b, a1), h2 = hue(q.b, a2);
  const double dL = q.L - p.L, dC = C2p - C1p;
  double dh = 0;
  if (C1p * C2p != 0) {
    dh = h2 - h1;
    if (dh > 180) dh -= 360;
    else if (dh < -180) dh += 360;
  }
  const double dH = 2 * std::sqrt(C1p * C2p) * std::sin(rad(dh / 2));
  const double Lbar = (p.L + q.L) / 2, Cbarp = (C1p + C2p) / 2;
  double hbar = h1 + h2;
  if (C1p * C2p != 0) {
    if (std::abs(h1 - h2) <= 180) hbar = (h1 + h2) / 2;
    else if (h1 + h2 < 360) hbar = (h1 + h2 + 360) / 2;
    else hbar = (h1 + h2 - 360) / 2;
  }
  const double T = 1 - 0.17 * std::cos(rad(hbar - 30)) + 0.24 * std::cos(rad(2 * hbar)) +
                   0.32 * std::cos(rad(3 * hbar + 6)) - 0.20 * std::cos(rad(4 * hbar - 63));
  const double dTheta = 30 * std::exp(-std::pow((hbar - 275) / 25, 2));
  const double Cbarp7 = std::pow(Cbarp, 7);
  const double Rc = 2 * std::sqrt(Cbarp7 / (Cbarp7 + std::pow(25.0, 7)));
  const double l50 = (Lbar - 50) * (Lbar - 50);
  const double SL = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double SC = 1 + 0.045 * Cbarp, SH = 1 + 0.015 * Cbarp * T;
  const double RT = -std::sin(rad(2 * dTheta)) * Rc;
  const double tL = dL / (kL * SL), tC = dC / (kC * SC), tH = dH / (kH * SH);
  return std::sqrt(tL * tL + tC * tC + tH * tH + RT * tC * tH);
}

}  // namespace colorlab::analysis
