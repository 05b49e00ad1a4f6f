#include "seep/core/geometry/random_packing.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/disk_overlap.h"

namespace seep::core {

double UniformUnit(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

namespace {

// Radius-expansion state: base radii, current positions, and the scratch of the relaxation.
class Expander {
 public:
  Expander(const RandomPackingOptions& options, std::vector<double> base_radius,
           std::vector<double> x, std::vector<double> y)
      : options_(&options), base_radius_(std::move(base_radius)) {
    packing_.x = std::move(x);
    packing_.y = std::move(y);
    packing_.radius.resize(base_radius_.size());
    double sum = 0.0;
    for (const double r : base_radius_) sum += r;
    mean_base_radius_ = sum / static_cast<double>(base_radius_.size());
  }

  const Packing& packing() const { return packing_; }
  double scale() const { return scale_; }
  double mean_radius() const { return scale_ * mean_base_radius_; }

  // Sets radii to scale * base and relaxes; returns true when the overlaps reached tolerance.
  bool GrowTo(double scale, std::int32_t max_iterations) {
    scale_ = scale;
    for (std::size_t k = 0; k < base_radius_.size(); ++k) {
      packing_.radius[k] = scale * base_radius_[k];
    }
    return Relax(max_iterations);
  }

  // Largest pair or wall overlap after the last relaxation (absolute).
  double max_overlap() const { return max_overlap_; }

  double Coordination(double contact_gap) {
    (void)detector_.Detect(packing_, contact_gap, &contacts_);
    return 2.0 * static_cast<double>(contacts_.size()) / static_cast<double>(packing_.size());
  }

  double PorosityWithLenses() {
    (void)detector_.Detect(packing_, 0.0, &contacts_);
    double solid = 0.0;
    for (const double r : packing_.radius) solid += std::numbers::pi * r * r;
    for (std::size_t c = 0; c < contacts_.size(); ++c) {
      const std::size_t i = static_cast<std::size_t>(contacts_.i[c]);
      const std::size_t j = static_cast<std::size_t>(contacts_.j[c]);
      const double ri = packing_.radius[i], rj = packing_.radius[j];
      solid -= LensArea(ri, rj, ri + rj + contacts_.gap[c]);
    }
    return 1.0 - solid / (options_->width * options_->height);
  }

 private:
  double WallOverlapAndClamp() {
    double worst = 0.0;
    for (std::size_t k = 0; k < packing_.size(); ++k) {
      const double r = packing_.radius[k];
      const double lo_x = r, hi_x = options_->width - r;
      const double lo_y = r, hi_y = options_->height - r;
      worst = std::max({worst, lo_x - packing_.x[k], packing_.x[k] - hi_x, lo_y - packing_.y[k],
                        packing_.y[k] - hi_y});
      packing_.x[k] = std::clamp(packing_.x[k], lo_x, std::max(lo_x, hi_x));
      packing_.y[k] = std::clamp(packing_.y[k], lo_y, std::max(lo_y, hi_y));
    }
    return worst;
  }

  bool Relax(std::int32_t max_iterations) {
    const double tolerance = options_->overlap_tolerance * mean_radius();
    const std::size_t n = packing_.size();
    dx_.resize(n);
    dy_.resize(n);
    WallOverlapAndClamp();
    for (std::int32_t iteration = 0; iteration <= max_iterations; ++iteration) {
      (void)detector_.Detect(packing_, 0.0, &contacts_);
      double worst = 0.0;
      for (std::size_t c = 0; c < contacts_.size(); ++c) worst = std::max(worst, -contacts_.gap[c]);
      max_overlap_ = worst;
      if (worst <= tolerance || iteration == max_iterations) break;
      std::fill(dx_.begin(), dx_.end(), 0.0);
      std::fill(dy_.begin(), dy_.end(), 0.0);
      for (std::size_t c = 0; c < contacts_.size(); ++c) {
        const std::size_t i = static_cast<std::size_t>(contacts_.i[c]);
        const std::size_t j = static_cast<std::size_t>(contacts_.j[c]);
        double ux = packing_.x[j] - packing_.x[i];
        double uy = packing_.y[j] - packing_.y[i];
        const double d = std::sqrt(ux * ux + uy * uy);
        if (d > 0.0) {
          ux /= d;
          uy /= d;
        } else {
          ux = 1.0;  // coincident centres: separate along x, deterministically
          uy = 0.0;
        }
        // Push slightly past contact (factor kPush) so that pairs settle with a tiny gap instead
        // of creeping towards zero overlap; shares by the other disk's area (heavier moves less).
        const double ai = packing_.radius[i] * packing_.radius[i];
        const double aj = packing_.radius[j] * packing_.radius[j];
        const double push = kRelaxation * (-contacts_.gap[c] + kPushPast * tolerance);
        const double share_i = push * aj / (ai + aj);
        const double share_j = push * ai / (ai + aj);
        dx_[i] -= share_i * ux;
        dy_[i] -= share_i * uy;
        dx_[j] += share_j * ux;
        dy_[j] += share_j * uy;
      }
      for (std::size_t k = 0; k < n; ++k) {
        packing_.x[k] += dx_[k];
        packing_.y[k] += dy_[k];
      }
      WallOverlapAndClamp();
    }
    return max_overlap_ <= tolerance;
  }

  // Under-relaxation of the Jacobi sweep: a disk with several overlaps receives the sum of its
  // pushes, which overshoots at full strength.
  static constexpr double kRelaxation = 0.5;
  static constexpr double kPushPast = 0.5;

  const RandomPackingOptions* options_;  // pointer, not reference: Expander is copied
  std::vector<double> base_radius_;
  double mean_base_radius_ = 0.0;
  double scale_ = 0.0;
  double max_overlap_ = 0.0;
  Packing packing_;
  ContactDetector detector_;
  ContactList contacts_;
  std::vector<double> dx_, dy_;
};

Status CheckOptions(const RandomPackingOptions& o) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (o.count < 1) {
    return InvalidArgument("random packing: count must be >= 1 (got " + std::to_string(o.count) +
                           ")");
  }
  if (!positive(o.radius_min) || !positive(o.radius_max) || o.radius_max < o.radius_min) {
    return InvalidArgument("random packing: need 0 < radius_min <= radius_max (got " +
                           std::to_string(o.radius_min) + ", " + std::to_string(o.radius_max) +
                           ")");
  }
  if (!positive(o.width) || !positive(o.height)) {
    return InvalidArgument("random packing: width and height must be > 0");
  }
  if (o.target == RandomPackingOptions::Target::kPorosity &&
      !(o.porosity > 0.0 && o.porosity < 1.0)) {
    return InvalidArgument("random packing: porosity must be in (0, 1) (got " +
                           std::to_string(o.porosity) + ")");
  }
  if (o.target == RandomPackingOptions::Target::kCoordination &&
      !(o.coordination > 0.0 && o.coordination < 6.0)) {
    return InvalidArgument("random packing: coordination must be in (0, 6) (got " +
                           std::to_string(o.coordination) + ")");
  }
  if (!positive(o.overlap_tolerance) || !(o.contact_gap_ratio >= 0.0) ||
      o.contact_gap_ratio <= o.overlap_tolerance) {
    return InvalidArgument(
        "random packing: need overlap_tolerance > 0 and contact_gap_ratio > overlap_tolerance");
  }
  if (o.max_relax_iterations < 1) {
    return InvalidArgument("random packing: max_relax_iterations must be >= 1");
  }
  return Status::Ok();
}

// Scale at which the disks cover `solid_fraction` of the box (overlaps ignored).
double ScaleForSolidFraction(const RandomPackingOptions& o, double sum_base_r2,
                             double solid_fraction) {
  return std::sqrt(solid_fraction * o.width * o.height / (std::numbers::pi * sum_base_r2));
}

}  // namespace

Result<RandomPacking> GenerateRandomPacking(const RandomPackingOptions& options) {
  SEEP_RETURN_IF_ERROR(CheckOptions(options));
  const std::size_t n = static_cast<std::size_t>(options.count);
  std::mt19937_64 rng(options.seed);
  std::vector<double> base(n), x(n), y(n);
  double sum_base_r2 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = UniformUnit(rng()) * options.width;
    y[k] = UniformUnit(rng()) * options.height;
    base[k] = options.radius_min + UniformUnit(rng()) * (options.radius_max - options.radius_min);
    sum_base_r2 += base[k] * base[k];
  }
  Expander expander(options, std::move(base), std::move(x), std::move(y));

  // Growth schedule in solid fraction: loose start, then steps of kStep.
  constexpr double kStartFraction = 0.3;
  constexpr double kStep = 0.02;
  constexpr std::int32_t kGrowthIterations = 200;  // intermediate steps need not converge fully
  const std::int32_t max_iterations = options.max_relax_iterations;

  bool converged = false;
  if (options.target == RandomPackingOptions::Target::kPorosity) {
    const double final_fraction = 1.0 - options.porosity;
    for (double f = std::min(kStartFraction, final_fraction); f < final_fraction; f += kStep) {
      expander.GrowTo(ScaleForSolidFraction(options, sum_base_r2, f), kGrowthIterations);
    }
    converged = expander.GrowTo(ScaleForSolidFraction(options, sum_base_r2, final_fraction),
                                max_iterations);
    if (!converged) {
      return FailedPrecondition("random packing: overlaps did not fall below " +
                                std::to_string(options.overlap_tolerance) +
                                " * mean radius at porosity " + std::to_string(options.porosity) +
                                " (too dense for a random packing?)");
    }
  } else {
    const double target = options.coordination;
    auto coordination = [&]() {
      return expander.Coordination(options.contact_gap_ratio * expander.mean_radius());
    };
    // Walk up in solid fraction until Z >= target, keeping the last state below it.
    double low = 0.0;
    double high = 0.0;
    Expander below = expander;
    for (double f = kStartFraction; f < 0.92; f += kStep / 2) {
      const double s = ScaleForSolidFraction(options, sum_base_r2, f);
      const bool ok = expander.GrowTo(s, max_iterations);
      if (!ok) break;  // jammed before reaching the target
      if (coordination() >= target) {
        high = s;
        break;
      }
      low = s;
      below = expander;
    }
    if (high == 0.0) {
      return FailedPrecondition("random packing: coordination " + std::to_string(target) +
                                " not reached before the packing jammed");
    }
    // Bisect the scale, always restarting from the last relaxed state below the target.
    Expander best_above = expander;
    for (int step = 0; step < 24 && high - low > 1e-9 * high; ++step) {
      const double mid = 0.5 * (low + high);
      Expander trial = below;
      if (!trial.GrowTo(mid, max_iterations)) {
        high = mid;  // jammed: treat as above the target, but keep the last converged state
      } else if (trial.Coordination(options.contact_gap_ratio * trial.mean_radius()) >= target) {
        high = mid;
        best_above = trial;
      } else {
        low = mid;
        below = trial;
      }
    }
    expander = best_above;
    converged = expander.max_overlap() <= options.overlap_tolerance * expander.mean_radius();
    if (!converged) {
      return FailedPrecondition("random packing: overlaps did not converge at coordination " +
                                std::to_string(target));
    }
  }

  RandomPacking result;
  result.packing = expander.packing();
  result.radius_scale = expander.scale();
  result.mean_radius = expander.mean_radius();
  result.max_overlap = expander.max_overlap();
  result.porosity = expander.PorosityWithLenses();
  result.coordination = expander.Coordination(options.contact_gap_ratio * result.mean_radius);
  return result;
}

}  // namespace seep::core
