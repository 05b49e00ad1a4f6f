// The valid requests the fuzzer starts from: small scenes of each kind the service runs (steady,
// explicit and implicit transients, staged, random and listed packings, regions, radial, moving
// disks), a calibration and a sweep, each cheap enough to finish in well under a second, so that
// an accepted job that does not is the service's doing, not the fuzzer's.
#pragma once

#include <string>
#include <vector>

#include "seep/v1/calibration.pb.h"
#include "seep/v1/scene.pb.h"
#include "seep/v1/sweep.pb.h"

namespace seep::fuzz {

struct BaseScene {
  std::string name;
  v1::Scene scene;
};

// Every base scene, parsed once; each has stages when `staged` is in its name (a fork's parent).
const std::vector<BaseScene>& BaseScenes();
// A steady calibration of a small lattice against one target permeability.
const v1::Calibration& BaseCalibration();
// A zipped sweep of two points over a steady lattice.
const v1::Sweep& BaseSweep();

}  // namespace seep::fuzz
