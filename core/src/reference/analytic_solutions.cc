// Closed-form reference solutions (see analytic_solutions.h).
#include "seep/core/reference/analytic_solutions.h"

#include <cmath>
#include <numbers>

namespace seep::core {
namespace {

// Below this T the sine series needs many terms and the image sums few; at it both converge
// to round-off within 40 terms (the series' 40th term is exp(-40^2 pi^2 0.05) ~ 1e-343, the
// images' 40th erfc argument is ~ 80 / (2 sqrt(0.05)) ~ 180).
constexpr double kSeriesFromT = 0.05;
constexpr int kTerms = 40;

// exp(-x^2 pi^2 T) of the next term is below 1e-18 of the leading one: later terms are lost in
// round-off.
bool Negligible(double x, double T) {
  return x * x * std::numbers::pi * std::numbers::pi * T > 42.0;
}

}  // namespace

double DiffusionDirichletDirichlet(double xi, double T) {
  if (T <= 0.0) return xi <= 0.0 ? 1.0 : 0.0;
  if (T < kSeriesFromT) {
    // Images: the step at 0 mirrored with odd sign about x = L, repeated with period 2L.
    const double s = 2.0 * std::sqrt(T);
    double p = 0.0;
    for (int n = 0; n < kTerms; ++n) {
      p += std::erfc((2.0 * n + xi) / s) - std::erfc((2.0 * n + 2.0 - xi) / s);
    }
    return p;
  }
  double sum = 0.0;
  for (int n = 1; !Negligible(n, T); ++n) {
    sum += std::sin(n * std::numbers::pi * xi) / n *
           std::exp(-n * n * std::numbers::pi * std::numbers::pi * T);
  }
  return 1.0 - xi - 2.0 / std::numbers::pi * sum;
}

double DiffusionDirichletNoFlow(double xi, double T) {
  if (T <= 0.0) return xi <= 0.0 ? 1.0 : 0.0;
  if (T < kSeriesFromT) {
    // Images: even about x = L (no flow), odd about x = 0 (Dirichlet): alternating pairs.
    const double s = 2.0 * std::sqrt(T);
    double p = 0.0;
    double sign = 1.0;
    for (int n = 0; n < kTerms; ++n) {
      p += sign * (std::erfc((2.0 * n + xi) / s) + std::erfc((2.0 * n + 2.0 - xi) / s));
      sign = -sign;
    }
    return p;
  }
  double sum = 0.0;
  for (int m = 0; !Negligible(m + 0.5, T); ++m) {
    const double big_m = (2.0 * m + 1.0) * std::numbers::pi / 2.0;
    sum += std::sin(big_m * xi) * std::exp(-big_m * big_m * T) / big_m;
  }
  return 1.0 - 2.0 * sum;
}

double ThiemPressure(double r, double r_w, double r_e, double p_w, double p_e) {
  return p_w + (p_e - p_w) * std::log(r / r_w) / std::log(r_e / r_w);
}

double ThiemFlowRate(double permeability, double viscosity, double r_w, double r_e, double p_w,
                     double p_e) {
  return 2.0 * std::numbers::pi * permeability * (p_w - p_e) / (viscosity * std::log(r_e / r_w));
}

}  // namespace seep::core
