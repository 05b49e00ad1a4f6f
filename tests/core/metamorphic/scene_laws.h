// The laws every valid scene must obey, each checked on one scene and reported as a verdict (an
// empty string when the law holds, else what broke, with the numbers): the metamorphic test runs
// them over a fixed set of generated scenes, the bench (bench/robustness/scene_laws_bench.cc) over
// as many as it is given time for.
//
//   Isometry     a translated, quarter-turned or mirrored scene ends `steps` steps later at the
//                image of the original's state: particle positions and velocities, wall lines,
//                domain pressures (matched by centroid) and wall stresses, within
//                kIsometryTolerance of their scales (below). Where the two runs meet a
//                discontinuity of the model on different sides (a contact's onset, where its
//                dashpot engages at once; a bond's strength; a re-detection), a rounding decided
//                it: they are compared at the step before, up to which they must be images.
//   Resume       a run stopped at a step, snapshotted and restored into a new simulation ends
//                with the uninterrupted run's snapshot bits and metrics.
//   Threads      one and two threads give the same snapshot bits and metrics.
//   Books        the fluid books close: |injected - left + redetection - stored| <= 1e-10 of the
//                fluid handled, and when nothing was handled, compressed = -pore growth.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "scene_maps.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core::metamorphic {

// Relative tolerance of the isometry law, against each quantity's scale: positions and the step's
// displacement (v dt) against the mean radius; pressures and wall stresses against the fluid's
// bulk modulus K_f or the largest value, whichever is larger (a pressure is K_f times the fluid's
// volumetric strain, so this holds the fluid content of each domain to the tolerance). The maps
// are exact on the inputs (scene_maps.h), so what differs is rounding in sums taken in another
// order (a quarter-turned packing's domains are numbered in another order) and in arithmetic on
// coordinates of another size, grown over the steps.
inline constexpr double kIsometryTolerance = 1e-9;
// The books' closure, relative to the fluid handled (FluidLedger::relative_error).
inline constexpr double kBooksTolerance = 1e-10;

// A law's deviations are measured against what one rounding does to the same scene: the spread is
// the largest deviation (measured as the isometry law does) between the scene and the same scene
// with every coordinate and radius moved by one ulp (two patterns; a map changes the rounding of
// every position update and of every tie, which such a nudge stands for) or with K_f one ulp
// higher. A scene whose start sits on a threshold of the model
// (disks exactly touching, a wall placed against the outermost disk, a velocity that is zero up to
// rounding under local damping's sign(v)) turns one rounding into finite differences within
// steps; there the isometry law can only ask for kSpreadFactor x that spread, and a bug that
// moves results by far more (the fluid's push on a wall off by rho_f g y_wall) still fails.
//
// A translation's image computes in a coarser frame: every position is rounded at |x + t| (up to
// 8 times |x|'s ulp at the generator's sizes) at every step, where a nudge rounds once. `frame` is
// that offset (the nudges are then one ulp of |c| + frame), and CheckIsometry holds a translation
// that exceeds the scene's own spread to the frame's spread times the steps compared: every step's
// rounding added up, an upper bound of a linear response (a coupled implicit disc went from 27 to
// 600 times the one-time nudge's spread between its 5th and 50th step, in step with the count).
// A law broken in proportion to the translation (rho_f g y_wall) moves results by 1e-2, not 1e-7.
inline constexpr double kSpreadFactor = 100.0;

struct Outcome;  // where a run stands after its steps (scene_laws.cc)

// A scene under the laws: the scene as generated (what the maps take), materialised once (what
// every law runs), and the materialised scene's own runs, each step count run once: the spread,
// the three maps, the resume and the books all compare against the same run.
class LawScene {
 public:
  explicit LawScene(const SceneSpec& generated);
  ~LawScene();
  const SceneSpec& generated() const { return generated_; }
  const SceneSpec& materialised() const { return materialised_; }
  const Outcome& Run(std::uint64_t steps) const;

 private:
  SceneSpec generated_;
  SceneSpec materialised_;
  mutable std::map<std::uint64_t, std::unique_ptr<Outcome>> runs_;
};

double RoundingSpread(const LawScene& scene, std::uint64_t steps, double frame = 0.0);

// What a seed's laws use, the same in the suite and the bench: a translation that is a multiple
// of the snapping grid (scene_maps.h) of the order of the sample (up to 0.25 m), and a step
// somewhere inside the run to stop and resume at.
SceneMap SeedTranslation(std::uint64_t seed);
std::uint64_t SeedResumeStep(std::uint64_t seed, std::uint64_t steps);

// Within max(kIsometryTolerance, kSpreadFactor x spread).
std::string CheckIsometry(const LawScene& scene, std::uint64_t steps, const SceneMap& map,
                          double spread);
std::string CheckResume(const LawScene& scene, std::uint64_t steps, std::uint64_t stop_at);
std::string CheckThreads(const LawScene& scene, std::uint64_t steps);
std::string CheckBooks(const LawScene& scene, std::uint64_t steps);

}  // namespace seep::core::metamorphic
