// Boundary regions on a scene's network (spec/boundary_region.h): which domains each region
// holds, and the conditions on them.
//
// Membership, decided at every detection (set-up, each re-detection, a restore that re-runs one):
// a domain whose centroid (DomainNetwork::centroid_x/y, at detection) lies in the region's shape,
// boundary included, and that the linear, radial or walls-only boundary left free. A reservoir, a
// fixed or injected well and a drained wall's node are never taken. A domain in two regions
// (validation allows it only when their conditions are equal) belongs to the first listed.
//
// Conditions:
//   pressure region  each of its domains is a fixed-pressure node at pressure_pa (held at its
//                    centroid, like the well, when the fluid has weight);
//   flux region      each of its domains is a source of rate_m2_s x V_d / sum V_d, V_d the
//                    domain's apparent volume at detection (so the split does not follow the
//                    storage model, and a stage or a restore between detections gives the same
//                    split). The domain's pressure evolves; the books count its fluid as injected.
//
// An empty region: at set-up a region without a domain is FAILED_PRECONDITION naming it
// (CheckRegionsHoldDomains); at a re-detection the particles moved, and refusing then would end a
// long run for a region that may fill again at the next one, so it is allowed (the re-detection
// logs it): a pressure region without domains holds nothing and a flux region injects nothing
// until a domain's centroid is back in it (region_<name>_domains reports 0, and the books show
// the missing injection).
#pragma once

#include "seep/core/flow/flow_network.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::core {

// Fills *regions (one per scene region) with the free domains of `data` (the network the boundary
// built, before FlowNetwork::Create) each region holds, and gives them their role: fixed pressure
// or source. The values come from SetRegionConditions, once the network exists.
void AssignBoundaryRegions(const SceneSpec& scene, const DomainNetwork& domains,
                           FlowNetworkData* data, std::vector<RegionNodes>* regions);

// Sets each region's domains to the pressure or the share of the rate `scene` gives the region
// now: after the build, and whenever a stage changes a region's value.
Status SetRegionConditions(const SceneSpec& scene, SceneNetwork* net);

// Every region holds at least one domain (the set-up's check); FAILED_PRECONDITION naming the
// first that does not: "scene.boundary.regions[2] ('outlet'): contains no domain centroid".
Status CheckRegionsHoldDomains(const SceneSpec& scene, const SceneNetwork& net);

}  // namespace seep::core
