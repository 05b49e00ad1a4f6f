// FluidLedger: the run's cumulative fluid books, m^2 per m of thickness at the reference
// density, from the start of the run (docs/physics.md §1.2). The flow effect adds every update's
// tally (flow/fluid_tally.h), the re-detection effect what each re-detection created or
// destroyed; checkpoints carry it, so a resumed run's books are the uninterrupted run's.
//
//   injected_m2     sum dt Q_src: the well's injection and the flux regions' rates (< 0: the
//                   regions extracted more than was injected)
//   left_m2[b]      what left the sample into boundary b (FluidBoundaryNames order; < 0: came in)
//   compressed_m2   sum V_s dP / K_f over the free and source domains, update by update, and
//                   what each re-detection's remap changed of it (as redetection_m2 books it)
//   pore_growth_m2  sum dV over them (fluid taken up by the pores opening)
//   redetection_m2  fluid created (> 0) or destroyed (< 0) by re-detections: the free and source
//                   domains' sum V_s P / K_f after each one minus before. A remap that conserves
//                   every cluster books rounding; a pocket born, a domain lost to a reservoir at
//                   breakthrough or merged into a fixed node books what it held or took.
//   handled_m2      the fluid the books moved: injected, every boundary exchange step by step,
//                   the magnitude of every booking, and what the pores' deformation moved (sum
//                   |dV| over the free and source domains, update by update) — what the
//                   balance error is relative to.
//
// The balance: injected - sum left + redetection = compressed + pore_growth.
// since_step: the books start there (0; a run resumed from a checkpoint written before the
// books existed starts them at its step).
#pragma once

#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace seep::core {

struct FluidLedger {
  double injected_m2 = 0.0;
  std::vector<double> left_m2;
  double compressed_m2 = 0.0;
  double pore_growth_m2 = 0.0;
  double redetection_m2 = 0.0;
  double handled_m2 = 0.0;
  std::uint64_t since_step = 0;

  double stored_m2() const { return compressed_m2 + pore_growth_m2; }
  double imbalance_m2() const {
    const double left = std::accumulate(left_m2.begin(), left_m2.end(), 0.0);
    return injected_m2 - left + redetection_m2 - stored_m2();
  }
  // |imbalance| / handled, 0 when nothing was handled.
  double relative_error() const {
    return handled_m2 > 0.0 ? std::abs(imbalance_m2()) / handled_m2 : 0.0;
  }
};

}  // namespace seep::core
