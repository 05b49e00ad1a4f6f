// `seep plot --what particles`: a job's state at one checkpoint as an SVG picture, the fracture at
// a glance. Layers, bottom to top:
//   - each domain's loop polygon filled with its pressure on the viridis colour map;
//   - the particles as disks of their true radius (light and half transparent, so that the
//     pressure shows through);
//   - intact bonds as thin dark lines between the centres, broken bonds as thicker red ones;
//   - the walls as thick black segments;
// with a colour bar of the pressure range (labelled in Pa) to the right and a legend with the
// counts below. Elements of one style share one group or path (one path per bond state, one per
// colour level of the domains), coordinates are in pixels with two decimals: an 11,600-disk
// lattice draws in 2.4 MB.
//
// Machine-readable hooks (the tests read them): <g class="particles"> holds one <circle> per
// particle; <path class="bonds-intact"> and <path class="bonds-broken"> one "M..L.." subpath per
// bond; <g class="walls"> one <line> per wall; <g class="colour-bar"> carries data-min-pa and
// data-max-pa (the range of the finite domain pressures, shortest round-trip form).
#pragma once

#include <string>

#include "seep/v1/job_service.pb.h"

namespace seep::client {

// The document, or an empty string with *error set when the fields do not fit together (array
// lengths, an id out of range), naming the field: "bond_particle_j[3]: 900 is not a particle
// (672 particles)".
std::string ParticleSvg(const std::string& job_id, const v1::GetJobFieldsResponse& response,
                        std::string* error);

}  // namespace seep::client
