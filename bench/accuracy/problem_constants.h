// The material every accuracy problem shares: lattice disks of 1 mm with a 10 um residual
// aperture in water (docs/physics.md §4.2 magnitudes), so that the problems differ only in
// geometry.
#pragma once

namespace seep::bench {

inline constexpr double kRadius = 1e-3;        // m
inline constexpr double kAperture = 1e-5;      // m
inline constexpr double kViscosity = 1e-3;     // Pa s
inline constexpr double kBulkModulus = 2.2e9;  // Pa, real water

}  // namespace seep::bench
