// Calibrator and CalibrateResidualAperture (calibration.h): first guess from the affine estimate,
// then the safeguarded cube-root/secant search on the measured permeability.
#include "seep/core/calibration/calibration.h"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <utility>

#include "calibration_network.h"
#include "seep/core/calibration/aperture_search.h"
#include "seep/core/log.h"

namespace seep::core {

using calibration_internal::CalibrationNetwork;

namespace {

// The affine estimate is a cheap closed form: solve it for a0 far below any useful tolerance so
// that the first guess measures the estimate, not the search.
constexpr double kFirstGuessTolerance = 1e-13;
constexpr int kFirstGuessEvaluations = 200;

// Why a target did not converge, when the record shows it.
std::string NonConvergenceHint(const CalibrationSpec& spec, const CalibrationRecord& r) {
  const double cap = spec.scene.aperture.max_aperture_m;
  if (cap > 0.0 && r.residual_aperture_m >= cap && r.permeability_m2 < r.target_permeability_m2) {
    return fmt::format("; the target lies above the permeability at a0 = max_aperture_m = {} m",
                       cap);
  }
  if (r.permeability_m2 > r.target_permeability_m2 && r.stress.pipes_open > 0) {
    return "; the open gaps alone (a0 -> 0) may already exceed the target";
  }
  return "";
}

}  // namespace

class Calibrator::Impl {
 public:
  Impl(CalibrationSpec spec, CalibrationNetwork network)
      : spec_(std::move(spec)), network_(std::move(network)) {}

  // The a0 at which the affine estimate equals the target (the best reached if the cap or open
  // gaps keep it from getting there).
  Result<double> FirstGuess(double target) {
    // Start from the square-lattice closed form a0 = (24 R k)^(1/3) (docs/physics.md §1.3).
    const double start = std::cbrt(24.0 * network_.mean_radius() * target);
    ApertureSearchOptions options;
    options.tolerance = kFirstGuessTolerance;
    options.max_evaluations = kFirstGuessEvaluations;
    options.max_aperture = network_.max_aperture();
    SEEP_ASSIGN_OR_RETURN(
        const ApertureSearchResult guess,
        SearchResidualAperture(target, start, options, [this](double a0) -> Result<double> {
          return network_.AffinePermeability(a0);
        }));
    return guess.best.aperture;
  }

  Result<CalibrationRecord> CalibrateTarget(std::size_t index, const CalibrationControl& control) {
    if (index >= spec_.target_permeabilities_m2.size()) {
      return InvalidArgument(
          fmt::format("calibration: target index {} is out of range ({} targets)", index,
                      spec_.target_permeabilities_m2.size()));
    }
    const double target = spec_.target_permeabilities_m2[index];
    SEEP_ASSIGN_OR_RETURN(const double first_guess, FirstGuess(target));

    ApertureSearchOptions options;
    options.tolerance = spec_.tolerance;
    options.max_evaluations = spec_.max_iterations;
    options.max_aperture = network_.max_aperture();
    int iteration = 0;
    auto measure = [&](double a0) -> Result<double> {
      if (control.stop.stop_requested()) {
        return Cancelled(fmt::format("calibration stopped at target {} before iteration {}", index,
                                     iteration + 1));
      }
      SEEP_ASSIGN_OR_RETURN(const double k, network_.MeasurePermeability(a0));
      ++iteration;
      if (control.on_progress) {
        control.on_progress({index, spec_.target_permeabilities_m2.size(), iteration, a0, k,
                             std::abs(k - target) / target});
      }
      return k;
    };
    SEEP_ASSIGN_OR_RETURN(const ApertureSearchResult search,
                          SearchResidualAperture(target, first_guess, options, measure));

    CalibrationRecord r;
    r.target_index = index;
    r.target_permeability_m2 = target;
    r.residual_aperture_m = search.best.aperture;
    r.permeability_m2 = search.best.permeability;
    r.relative_error = search.best.relative_error;
    r.converged = search.converged;
    r.iterations = search.evaluations;
    r.corrections = search.evaluations - 1;
    r.first_guess_residual_aperture_m = search.first.aperture;
    r.first_guess_permeability_m2 = search.first.permeability;
    r.first_guess_relative_error = search.first.relative_error;
    r.packing = network_.packing_stats();
    r.fluid = spec_.scene.fluid;
    r.aperture = spec_.scene.aperture;
    r.aperture.residual_aperture_m = r.residual_aperture_m;
    r.stress = network_.stress();
    r.stress.pipes_capped = network_.CappedPipes(r.residual_aperture_m);
    r.stress.aperture_proportional_to_a0 = r.stress.pipes_open == 0 && r.stress.pipes_capped == 0;
    r.flow_axis = spec_.scene.boundary.axis;
    r.pressure_drop_pa =
        spec_.scene.boundary.inlet_pressure_pa - spec_.scene.boundary.outlet_pressure_pa;
    r.sample_length_m = network_.SampleLength(r.residual_aperture_m);
    r.sample_width_m = network_.sample_width();
    return r;
  }

  CalibrationSpec spec_;
  CalibrationNetwork network_;
};

Calibrator::Calibrator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Calibrator::~Calibrator() = default;
Calibrator::Calibrator(Calibrator&&) noexcept = default;
Calibrator& Calibrator::operator=(Calibrator&&) noexcept = default;

Result<Calibrator> Calibrator::Create(const CalibrationSpec& spec) {
  SEEP_RETURN_IF_ERROR(ValidateCalibration(spec));
  SEEP_ASSIGN_OR_RETURN(CalibrationNetwork network, CalibrationNetwork::Build(spec));
  return Calibrator(std::make_unique<Impl>(spec, std::move(network)));
}

Result<CalibrationRecord> Calibrator::CalibrateTarget(std::size_t target_index,
                                                      const CalibrationControl& control) {
  return impl_->CalibrateTarget(target_index, control);
}

Result<double> Calibrator::MeasurePermeability(double residual_aperture_m) {
  if (!std::isfinite(residual_aperture_m) || residual_aperture_m <= 0.0) {
    return InvalidArgument(
        fmt::format("calibration: residual_aperture_m must be a finite number > 0 (got {})",
                    residual_aperture_m));
  }
  return impl_->network_.MeasurePermeability(residual_aperture_m);
}

double Calibrator::AffinePermeability(double residual_aperture_m) const {
  return impl_->network_.AffinePermeability(residual_aperture_m);
}

const CalibrationPackingStats& Calibrator::packing_stats() const {
  return impl_->network_.packing_stats();
}

const LinearSystemStats& Calibrator::linear_system_stats() const {
  return impl_->network_.linear_system_stats();
}

Result<std::vector<CalibrationRecord>> CalibrateResidualAperture(
    const CalibrationSpec& spec, const CalibrationControl& control) {
  const auto log = control.logger ? control.logger : Logger();
  SEEP_ASSIGN_OR_RETURN(Calibrator calibrator, Calibrator::Create(spec));
  const CalibrationPackingStats& stats = calibrator.packing_stats();
  log->info("calibration: {} particles, {} contacts, {} domains, {} pipes; {} target(s)",
            stats.particle_count, stats.contact_count, stats.domain_count, stats.pipe_count,
            spec.target_permeabilities_m2.size());
  std::vector<CalibrationRecord> records;
  records.reserve(spec.target_permeabilities_m2.size());
  for (std::size_t t = 0; t < spec.target_permeabilities_m2.size(); ++t) {
    SEEP_ASSIGN_OR_RETURN(CalibrationRecord record, calibrator.CalibrateTarget(t, control));
    if (!record.converged) {
      return FailedPrecondition(fmt::format(
          "calibration.target_permeabilities_m2[{}]: did not converge to tolerance {} in {} "
          "iterations; best a0 = {} m gives k = {} m^2 (relative error {}){}",
          t, spec.tolerance, record.iterations, record.residual_aperture_m, record.permeability_m2,
          record.relative_error, NonConvergenceHint(spec, record)));
    }
    log->info(
        "calibration target {}: k = {} m^2 -> a0 = {} m in {} iteration(s), relative error {} "
        "(first guess a0 = {} m, error {})",
        t, record.target_permeability_m2, record.residual_aperture_m, record.iterations,
        record.relative_error, record.first_guess_residual_aperture_m,
        record.first_guess_relative_error);
    records.push_back(std::move(record));
  }
  return records;
}

}  // namespace seep::core
