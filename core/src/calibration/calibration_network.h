// CalibrationNetwork: the permeameter of a calibration, built once and re-solved for every trial
// residual aperture a0 (calibration.h).
//
// It keeps, per flow pipe of the scene network, what the aperture law needs (the contact's normal
// force from the stress spec and its gap) and what the affine estimate and the Darcy length need
// (the pipe's centroid-to-centroid offset along the axis; for a reservoir pipe, the offset to the
// interior centroid's image through the contact point and that image's position). The Darcy
// length of scene_network.h is a conductance-weighted mean of the images, so it is recomputed at
// every a0: with open gaps the weights change with a0, and the k measured here is then the k
// RunScene would report for the calibrated scene.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "seep/core/calibration/calibration_record.h"
#include "seep/core/calibration/calibration_spec.h"
#include "seep/core/flow/aperture_law.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/status.h"

namespace seep::core::calibration_internal {

class CalibrationNetwork {
 public:
  // The spec must be valid (ValidateCalibration).
  static Result<CalibrationNetwork> Build(const CalibrationSpec& spec);

  // Steady solve with every aperture from the law at residual aperture a0: the Darcy k, m^2.
  Result<double> MeasurePermeability(double a0);
  // k_affine(a0) of calibration.h, m^2.
  double AffinePermeability(double a0) const;
  // The Darcy length at a0 (conductance-weighted reservoir images).
  double SampleLength(double a0) const;
  double sample_width() const { return net_.width_m; }
  double max_aperture() const { return law_.max_aperture; }
  double mean_radius() const { return net_.mean_radius_m; }
  std::size_t CappedPipes(double a0) const;

  const CalibrationPackingStats& packing_stats() const { return packing_stats_; }
  const LinearSystemStats& linear_system_stats() const { return solver_.stats(); }
  // Everything but pipes_capped (which depends on a0).
  const CalibrationStressRecord& stress() const { return stress_; }

 private:
  explicit CalibrationNetwork(SteadyStateSolver solver) : solver_(std::move(solver)) {}
  Status MapPipes(const CalibrationSpec& spec);
  void FillApertures(double a0, std::span<double> aperture) const;
  double LengthFromWeights(std::span<const double> weight) const;
  void ComputeStatistics(const CalibrationSpec& spec);

  SceneNetwork net_;
  SteadyStateSolver solver_;
  ApertureLaw law_;
  double viscosity_ = 0.0;
  double pressure_drop_ = 0.0;
  // Per flow pipe.
  std::vector<double> force_;
  std::vector<double> gap_;
  std::vector<double> offset_;  // d_p . e, m
  // Reservoir pipes: flow pipe index, side (1 = inlet), image position along the axis.
  std::vector<std::size_t> end_pipe_;
  std::vector<std::uint8_t> end_inlet_;
  std::vector<double> end_image_;
  mutable std::vector<double> scratch_;
  CalibrationPackingStats packing_stats_;
  CalibrationStressRecord stress_;
};

}  // namespace seep::core::calibration_internal
