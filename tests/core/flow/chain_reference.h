// Reference solutions for the 1D chain (docs/physics.md §3.2), computed from their formulas.
#pragma once

#include <cmath>
#include <numbers>

namespace seep::core::testing {

enum class TimeScheme { kExplicit, kBackwardEuler, kCrankNicolson, kExact };

// Exact discrete solution of the chain with nodes 0..n, P_0 = 1, P_n = 0, interior P = 0 at t = 0,
// after `steps` steps of dt; per-node storage v, identical pipes c (discrete_exact.py).
inline double ChainDiscreteExact(int n, int i, int steps, double dt, double kf, double c, double v,
                                 TimeScheme scheme) {
  const double pi = std::numbers::pi;
  double sum = 0.0;
  for (int m = 1; m < n; ++m) {
    const double s = std::sin(m * pi / (2.0 * n));
    const double lambda = 4.0 * kf * c / v * s * s;
    double b = 0.0;
    for (int j = 1; j < n; ++j) b += (1.0 - static_cast<double>(j) / n) * std::sin(m * pi * j / n);
    b *= 2.0 / n;
    double rho;
    switch (scheme) {
      case TimeScheme::kExplicit:
        rho = std::pow(1.0 - dt * lambda, steps);
        break;
      case TimeScheme::kBackwardEuler:
        rho = std::pow(1.0 / (1.0 + dt * lambda), steps);
        break;
      case TimeScheme::kCrankNicolson:
        rho = std::pow((1.0 - 0.5 * dt * lambda) / (1.0 + 0.5 * dt * lambda), steps);
        break;
      case TimeScheme::kExact:
      default:
        rho = std::exp(-lambda * dt * steps);
        break;
    }
    sum += b * std::sin(m * pi * i / n) * rho;
  }
  return (1.0 - static_cast<double>(i) / n) - sum;
}

// The same for the theta method (docs/physics.md §4.5): mode m is multiplied per step by
// (1 - (1 - theta) dt lambda_m) / (1 + theta dt lambda_m); theta = 1 is kBackwardEuler, 1/2 is
// kCrankNicolson.
inline double ChainDiscreteTheta(int n, int i, int steps, double dt, double kf, double c, double v,
                                 double theta) {
  const double pi = std::numbers::pi;
  double sum = 0.0;
  for (int m = 1; m < n; ++m) {
    const double s = std::sin(m * pi / (2.0 * n));
    const double lambda = 4.0 * kf * c / v * s * s;
    double b = 0.0;
    for (int j = 1; j < n; ++j) b += (1.0 - static_cast<double>(j) / n) * std::sin(m * pi * j / n);
    b *= 2.0 / n;
    const double rho =
        std::pow((1.0 - (1.0 - theta) * dt * lambda) / (1.0 + theta * dt * lambda), steps);
    sum += b * std::sin(m * pi * i / n) * rho;
  }
  return (1.0 - static_cast<double>(i) / n) - sum;
}

// Continuum (a): p(0) = 1, p(L) = 0, p(x, 0) = 0; xi = x/L, T = c t / L^2.
inline double SeriesDirichletDirichlet(double xi, double T) {
  const double pi = std::numbers::pi;
  double sum = 0.0;
  for (int k = 1; k <= 2000; ++k) {
    sum += std::sin(k * pi * xi) / k * std::exp(-k * k * pi * pi * T);
  }
  return 1.0 - xi - 2.0 / pi * sum;
}

// Continuum (b): p(0) = 1, no flow at x = L.
inline double SeriesDirichletNoFlow(double xi, double T) {
  const double pi = std::numbers::pi;
  double sum = 0.0;
  for (int k = 0; k <= 2000; ++k) {
    const double m = (2 * k + 1) * pi / 2.0;
    sum += std::sin(m * xi) * std::exp(-m * m * T) / m;
  }
  return 1.0 - 2.0 * sum;
}

}  // namespace seep::core::testing
