// Flow solver figures on locality-ordered 2D lattices (docs/performance.md §4: G4, G5, G11). Prints
// numbers; asserts nothing.
//
//   flow_bench [side=1000] [steps=40]
//
// 1. STREAM triad (a = b + s c, 24 B per element, best of 7) measured in this run: the bandwidth
//    anchor for the explicit sweep.
// 2. Explicit sweep on a side x side square lattice numbered row-major (~2 side^2 pipes): ns per
//    pipe-step and the fraction of triad bandwidth at the nominal 40 B per pipe.
// 3. Steady solve on the same lattice (Dirichlet left/right columns) next to Eigen + CHOLMOD on a
//    5-point Laplacian of the same size.
#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/steady_state_solver.h"

namespace {

using Clock = std::chrono::steady_clock;
using seep::core::DomainRole;
using seep::core::FlowNetwork;
using seep::core::FlowNetworkData;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

template <typename T>
void DoNotOptimize(T const& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

// Best-of-7 single-thread triad bandwidth, GB/s, STREAM byte counting (no write-allocate).
double TriadBandwidth() {
  const std::size_t n = std::size_t{1} << 25;  // 32 Mi doubles: 256 MiB per array
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  double best = 1e30;
  for (int rep = 0; rep < 7; ++rep) {
    const auto t0 = Clock::now();
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    DoNotOptimize(a[n / 2]);
    best = std::min(best, Seconds(t0, Clock::now()));
  }
  return 24.0 * static_cast<double>(n) / best / 1e9;
}

// side x side square-cell domains, row-major, pipes to the right and upper neighbours.
FlowNetworkData Lattice(int side) {
  FlowNetworkData d;
  const std::size_t nd = static_cast<std::size_t>(side) * side;
  d.apparent_volume.assign(nd, 4e-6);
  d.pore_volume.assign(nd, 0.858e-6);
  d.pressure.assign(nd, 0.0);
  d.role.assign(nd, DomainRole::kFree);
  d.source_rate.assign(nd, 0.0);
  const double c = 4.1667e-11;  // a^3/(24 mu R) for k = 1e-12, R = 1 mm
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const int id = j * side + i;
      auto add = [&](int other) {
        d.pipe_domain_a.push_back(id);
        d.pipe_domain_b.push_back(other);
        d.pipe_length.push_back(2e-3);
        d.pipe_aperture.push_back(2.88e-5);
        d.pipe_conductance.push_back(c);
      };
      if (i + 1 < side) add(id + 1);
      if (j + 1 < side) add(id + side);
    }
  }
  for (int j = 0; j < side; ++j) {
    d.role[static_cast<std::size_t>(j) * side] = DomainRole::kFixedPressure;
    d.pressure[static_cast<std::size_t>(j) * side] = 1e5;
    d.role[static_cast<std::size_t>(j) * side + side - 1] = DomainRole::kFixedPressure;
  }
  return d;
}

struct SweepFigure {
  double ns_per_pipe_step;
  double bytes_per_pipe;  // the model: 16 B per pipe + 40 B per domain (48 with dV)
};

SweepFigure ExplicitSweep(int side, int steps, bool diagnostics, bool with_dv) {
  auto net = FlowNetwork::Create(Lattice(side));
  if (!net.ok()) std::abort();
  seep::core::ExplicitSolverOptions opt;
  opt.diagnostics = diagnostics;
  auto solver = seep::core::ExplicitSolver::Create(opt);
  const double dt = 0.5 * solver->CriticalStep(*net)->dt_crit;
  std::vector<double> dv(with_dv ? net->num_domains() : 0, 0.0);
  if (!solver->Step(*net, dt, dv).ok()) std::abort();  // warm-up: first touch, caches
  double best = 1e30;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = Clock::now();
    for (int s = 0; s < steps; ++s) {
      if (!solver->Step(*net, dt, dv).ok()) std::abort();
    }
    best = std::min(best, Seconds(t0, Clock::now()));
  }
  const double np = static_cast<double>(net->num_pipes());
  const double nd = static_cast<double>(net->num_domains());
  return {best / steps / np * 1e9, 16.0 + (with_dv ? 48.0 : 40.0) * nd / np};
}

// Eigen + CHOLMOD on the 5-point Dirichlet Laplacian of an n x n grid (RHS = 1), the anchor of
// docs/performance.md §1.6: analyse + factorise + solve, seconds.
double CholmodLaplacian(int n, double* residual) {
  using Sp = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  const int size = n * n;
  std::vector<Eigen::Triplet<double, int>> t;
  t.reserve(static_cast<std::size_t>(size) * 3);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int id = j * n + i;
      t.emplace_back(id, id, 4.0);
      if (i + 1 < n) t.emplace_back(id + 1, id, -1.0);
      if (j + 1 < n) t.emplace_back(id + n, id, -1.0);
    }
  }
  const auto t0 = Clock::now();
  Sp a(size, size);
  a.setFromTriplets(t.begin(), t.end());
  Eigen::CholmodSupernodalLLT<Sp, Eigen::Lower> llt;
  llt.analyzePattern(a);
  llt.factorize(a);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(size);
  const Eigen::VectorXd x = llt.solve(b);
  const double secs = Seconds(t0, Clock::now());
  const Sp full = a.selfadjointView<Eigen::Lower>();
  *residual = (full * x - b).norm() / b.norm();
  return secs;
}

}  // namespace

int main(int argc, char** argv) {
  const int side = argc > 1 ? std::atoi(argv[1]) : 1000;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 40;

  const double triad = TriadBandwidth();
  std::printf("STREAM triad (1 thread, best of 7): %.1f GB/s\n", triad);

  std::printf("\nExplicit sweep, %d x %d square lattice, row-major:\n", side, side);
  for (const int s : {side, 100}) {
    const int n = s == side ? steps : 2000;
    const SweepFigure f = ExplicitSweep(s, n, false, false);
    const double pipes = 2.0 * s * (s - 1);
    std::printf(
        "  %8.0f pipes: %.2f ns/pipe-step; at 40 B/pipe %.1f GB/s = %.0f%% of triad "
        "(model %.1f B/pipe -> %.0f%%)\n",
        pipes, f.ns_per_pipe_step, 40.0 / f.ns_per_pipe_step,
        100.0 * 40.0 / f.ns_per_pipe_step / triad, f.bytes_per_pipe,
        100.0 * f.bytes_per_pipe / f.ns_per_pipe_step / triad);
  }
  const SweepFigure dv = ExplicitSweep(side, steps, false, true);
  std::printf("  with dV input:        %.2f ns/pipe-step (model %.1f B/pipe -> %.0f%% of triad)\n",
              dv.ns_per_pipe_step, dv.bytes_per_pipe,
              100.0 * dv.bytes_per_pipe / dv.ns_per_pipe_step / triad);
  const SweepFigure diag = ExplicitSweep(side, steps, true, false);
  std::printf("  with diagnostics on:  %.2f ns/pipe-step\n", diag.ns_per_pipe_step);

  std::printf("\nSteady solve, %d domains (%d unknowns):\n", side * side, side * (side - 2));
  for (const auto kind : {seep::core::LinearSolverKind::kCholmodSupernodal,
                          seep::core::LinearSolverKind::kEigenSimplicialLdlt}) {
    if (kind == seep::core::LinearSolverKind::kEigenSimplicialLdlt && side > 400) {
      std::printf("  eigen_simplicial_ldlt: skipped above 400^2 (minutes at 1e6; see notes)\n");
      continue;
    }
    auto net = FlowNetwork::Create(Lattice(side));
    seep::core::SteadyStateOptions opt;
    opt.linear_solver = kind;
    auto solver = seep::core::SteadyStateSolver::Create(opt);
    const auto t0 = Clock::now();
    const auto r1 = solver->Solve(*net);
    const auto t1 = Clock::now();
    const auto r2 = solver->Solve(*net);  // factorization reused
    const auto t2 = Clock::now();
    if (!r1.ok() || !r2.ok()) {
      std::printf("  solve failed: %s\n", r1.status().ToString().c_str());
      return 1;
    }
    std::printf(
        "  %s: first solve (assemble + analyse + factorise + solve) %.3f s; repeat solve "
        "%.3f s; mass balance %.1e\n",
        std::string(seep::core::LinearSolverKindName(kind)).c_str(), Seconds(t0, t1),
        Seconds(t1, t2), r1->mass_balance_error);
    if (kind == seep::core::LinearSolverKind::kCholmodSupernodal) {
      double residual = 0.0;
      const double anchor = CholmodLaplacian(side, &residual);
      std::printf(
          "  anchor Eigen+CHOLMOD 5-point Laplacian %d^2 (analyse + factorise + solve): "
          "%.3f s (residual %.1e) -> ratio %.2fx\n",
          side, anchor, residual, Seconds(t0, t1) / anchor);
    }
  }
  return 0;
}
