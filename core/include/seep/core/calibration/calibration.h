// Residual-aperture calibration (docs/physics.md §1.3, issue #6): the a0 that makes a steady
// permeameter on a packing measure a target permeability.
//
// Per target:
//   1. first guess: the a0 at which the affine (uniform-gradient) estimate of this packing's
//      pipes equals the target,
//        k_affine(a0) = 1/(12 H W) sum_p a_p(a0)^3 (d_p . e)^2 / L_p,
//      summed over every flow pipe with its aperture from the law and the stress state; d_p joins
//      the two domain centroids (for a reservoir pipe, the interior centroid and its image
//      through the contact point), W and H are the Darcy length and width of scene_network.h
//      (so that the estimate and the measurement share one geometry). For a uniform aperture on
//      an isotropic network this is the paper-style (C1), a^3/(24 A) sum |d|^2/L. It is exact on
//      lattices (one solve suffices) and otherwise an estimate from above (Dirichlet principle;
//      V6 finds the network 10-30% below it).
//   2. a steady solve measures k; a0 is rescaled by (k_target / k)^(1/3). This is exact in one
//      step when every aperture is proportional to a0 (all pipes in compression or closed).
//   3. when open gaps (a = a0 + m g) or the cap a_max break the scaling, further steps are secant
//      steps in (log a0, log k), kept inside the bracket of the target once one is known
//      (bisection otherwise) and limited to a factor 1000 per step, until
//      |k - k_target| / k_target < tolerance or max_iterations solves.
// The network is built once; only apertures change between solves, so the steady solver reuses
// its symbolic analysis and refactorizes numerically. Deterministic: same spec, same records.
#pragma once

#include <spdlog/logger.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <stop_token>
#include <vector>

#include "seep/core/calibration/calibration_record.h"
#include "seep/core/calibration/calibration_spec.h"
#include "seep/core/flow/linear_solver_kind.h"
#include "seep/core/status.h"

namespace seep::core {

struct CalibrationProgress {
  std::size_t target_index = 0;
  std::size_t target_count = 0;
  int iteration = 0;  // 1 = the first guess's solve
  double residual_aperture_m = 0.0;
  double permeability_m2 = 0.0;
  double relative_error = 0.0;  // |k - k_target| / k_target at this iteration
};

struct CalibrationControl {
  // Called from the calibrating thread after every permeameter solve; must not block for long.
  std::function<void(const CalibrationProgress&)> on_progress;
  // A stop request ends the calibration before its next solve with a kCancelled status.
  std::stop_token stop;
  // Where the calibration logs; null = core::Logger().
  std::shared_ptr<spdlog::logger> logger;
};

// Holds the built network between targets. Create validates and builds; CalibrateTarget may be
// called for any target index, in any order, with the same result.
class Calibrator {
 public:
  static Result<Calibrator> Create(const CalibrationSpec& spec);
  ~Calibrator();
  Calibrator(Calibrator&&) noexcept;
  Calibrator& operator=(Calibrator&&) noexcept;

  // Calibrates spec.target_permeabilities_m2[target_index]. Running out of iterations is not an
  // error here: the record holds the best a0 reached with converged = false.
  Result<CalibrationRecord> CalibrateTarget(std::size_t target_index,
                                            const CalibrationControl& control = {});

  // One steady permeameter solve at residual aperture a0 (m): the measured k (m^2).
  Result<double> MeasurePermeability(double residual_aperture_m);
  // The affine estimate of the first guess at a0, m^2.
  double AffinePermeability(double residual_aperture_m) const;

  const CalibrationPackingStats& packing_stats() const;
  // Work of the steady solver so far: one symbolic analysis for the calibrator's lifetime, one
  // numeric factorization and one solve per permeameter solve.
  const LinearSystemStats& linear_system_stats() const;

 private:
  class Impl;
  explicit Calibrator(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Calibrates every target in order. A target that does not converge within max_iterations ends
// the sweep with FAILED_PRECONDITION naming the target, the best a0 and its error.
Result<std::vector<CalibrationRecord>> CalibrateResidualAperture(
    const CalibrationSpec& spec, const CalibrationControl& control = {});

}  // namespace seep::core
