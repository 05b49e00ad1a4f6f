// Closed-form reference solutions of the verification problems (docs/physics.md §3.1–3.3), for the
// accuracy bench and the verification tests: 1D transient pressure diffusion after a pressure
// step, and steady radial (Thiem) flow. Pure functions of dimensionless arguments.
#pragma once

namespace seep::core {

// 1D diffusion p_t = c p_xx on 0 <= x <= L from p(x, 0) = 0 with p(0, t) = p1 (docs/physics.md
// §3.2), as p/p1 at xi = x/L and dimensionless time T = c t / L^2.
//
// (a) p(L, t) = 0:  1 - xi - (2/pi) sum_n sin(n pi xi) exp(-n^2 pi^2 T) / n.
// (b) no flow at x = L:  1 - 2 sum_m sin(M xi) exp(-M^2 T) / M,  M = (2m + 1) pi / 2.
//
// Both are evaluated to round-off for every T > 0: by the sine series when T >= 0.05 (its terms
// fall as exp(-n^2 pi^2 T), so a few dozen suffice), else by the method of images (sums of erfc,
// which converge in a few terms at small T). T <= 0 gives the initial step (1 at xi = 0, else 0).
double DiffusionDirichletDirichlet(double xi, double T);
double DiffusionDirichletNoFlow(double xi, double T);

// Steady radial flow between a well of radius r_w at p_w and an outer boundary r_e at p_e, unit
// thickness (docs/physics.md §3.3): p(r) = p_w + (p_e - p_w) ln(r / r_w) / ln(r_e / r_w).
double ThiemPressure(double r, double r_w, double r_e, double p_w, double p_e);

// The Thiem rate out of the well, m^2/s: Q = 2 pi k (p_w - p_e) / (mu ln(r_e / r_w)).
double ThiemFlowRate(double permeability, double viscosity, double r_w, double r_e, double p_w,
                     double p_e);

}  // namespace seep::core
