#include "base_requests.h"

#include <google/protobuf/text_format.h>

#include <stdexcept>

namespace seep::fuzz {
namespace {

template <typename Message>
Message ParseOrThrow(const char* text) {
  Message message;
  if (!google::protobuf::TextFormat::ParseFromString(text, &message)) {
    throw std::logic_error(std::string("a base request does not parse: ") + text);
  }
  return message;
}

constexpr const char* kFluidAndAperture = R"pb(
  fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
  aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
)pb";

std::vector<BaseScene> MakeBaseScenes() {
  const std::string common = kFluidAndAperture;
  const std::vector<std::pair<std::string, std::string>> texts = {
      {"steady-lattice", R"pb(
         packing { lattice { kind: LATTICE_KIND_SQUARE columns: 8 rows: 6 radius_m: 1e-3 } }
         boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 outlet_pressure_pa: 0 }
         solver { kind: SOLVER_KIND_STEADY })pb"},
      {"explicit-transient", R"pb(
         packing { lattice { kind: LATTICE_KIND_SQUARE columns: 10 rows: 4 radius_m: 1e-3 } }
         boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 initial_pressure_pa: 0 }
         solver {
           kind: SOLVER_KIND_EXPLICIT
           storage: STORAGE_VOLUME_PORE
           dt_factor: 0.9
           end_time_s: 2e-4
           progress_every: 50
         })pb"},
      {"implicit-staged", R"pb(
         packing { lattice { kind: LATTICE_KIND_SQUARE columns: 8 rows: 5 radius_m: 1e-3 } }
         boundary { axis: FLOW_AXIS_Y inlet_pressure_pa: 1e5 }
         solver { kind: SOLVER_KIND_IMPLICIT storage: STORAGE_VOLUME_APPARENT dt_factor: 10 }
         stages {
           name: "load"
           inlet_pressure_pa { value: 2e5 }
           end { steps: 20 }
         }
         stages {
           name: "ramp"
           inlet_pressure_pa {
             schedule {
               time_s: [ 0, 1e-3 ]
               value: [ 2e5, 1e5 ]
             }
           }
           end { steps: 20 }
         })pb"},
      {"random-packing", R"pb(
         packing {
           random {
             seed: 7
             width_m: 0.02
             height_m: 0.01
             min_radius_m: 8e-4
             max_radius_m: 1e-3
             particle_count: 40
             target_porosity: 0.2
           }
           contact_gap_m: 2e-5
         }
         boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
         solver { kind: SOLVER_KIND_STEADY })pb"},
      {"particle-list", R"pb(
         packing {
           particles {
             x_m: [ 0, 2e-3, 4e-3, 0, 2e-3, 4e-3, 0, 2e-3, 4e-3 ]
             y_m: [ 0, 0, 0, 2e-3, 2e-3, 2e-3, 4e-3, 4e-3, 4e-3 ]
             radius_m: [ 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3 ]
           }
         }
         boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
         solver { kind: SOLVER_KIND_STEADY })pb"},
      {"regions", R"pb(
         packing { lattice { kind: LATTICE_KIND_SQUARE columns: 12 rows: 8 radius_m: 1e-3 } }
         boundary {
           axis: FLOW_AXIS_X
           closed_inlet: true
           outlet_pressure_pa: 0
           regions {
             name: "well"
             circle { cx_m: 6e-3 cy_m: 8e-3 r_m: 2e-3 }
             pressure_pa: 1e5
           }
           regions {
             name: "sink"
             polygon {
               x_m: [ 1e-3, 4e-3, 1e-3 ]
               y_m: [ 1e-3, 1e-3, 4e-3 ]
             }
             flux_m2_s: -1e-9
           }
         }
         solver { kind: SOLVER_KIND_STEADY })pb"},
      {"radial", R"pb(
         packing { lattice { kind: LATTICE_KIND_HEX columns: 14 rows: 16 radius_m: 1e-3 } }
         boundary {
           radial {
             well_radius_m: 3e-3
             outer_radius_m: 12e-3
             well_pressure_pa: 1e5
             outer_pressure_pa: 0
           }
         }
         solver { kind: SOLVER_KIND_STEADY })pb"},
      {"moving-disks", R"pb(
         packing {
           lattice { kind: LATTICE_KIND_HEX columns: 8 rows: 8 radius_m: 1e-3 }
           contact_gap_m: 2e-6
         }
         boundary {
           radial {
             well_radius_m: 2.5e-3
             outer_radius_m: 1.0
             well_pressure_pa: 0
             outer_pressure_pa: 0
           }
         }
         solver {
           kind: SOLVER_KIND_EXPLICIT
           storage: STORAGE_VOLUME_PORE
           dt_factor: 0.9
           end_time_s: 2e-4
         }
         effects {
           contacts {
             law {
               kn_n_per_m: 1e8
               kt_n_per_m: 5e7
               friction: 0.5
               damping: NORMAL_DAMPING_CRITICAL_RATIO
               damping_ratio: 0.3
             }
             density_kg_m3: 2650
             dt_safety: 0.2
           }
         }
         effects {
           bonds {
             normal_stiffness_pa_per_m: 1e11
             shear_stiffness_pa_per_m: 5e10
             radius_multiplier: 1
             tensile_strength_pa: 1e5
             shear_strength_pa: 2e5
             tolerance_m: 1e-6
           }
         }
         effects {
           walls {
             walls { side: WALL_SIDE_LEFT servo_stress_pa: 1e5 servo_max_speed_m_s: 0.02 }
             walls { side: WALL_SIDE_RIGHT servo_stress_pa: 1e5 servo_max_speed_m_s: 0.02 }
             walls { side: WALL_SIDE_BOTTOM }
             walls { side: WALL_SIDE_TOP normal_velocity_m_s: 0.01 }
           }
         }
         effects { local_damping { alpha: 0.3 } }
         effects { flow {} }
         effects { fluid_forces {} }
         effects { volume_change {} }
         effects { aperture_update {} }
         effects { redetection {} }
         effects { injection { rate_m2_s: 2e-4 } })pb"},
  };
  std::vector<BaseScene> scenes;
  for (const auto& [name, text] : texts) {
    BaseScene base{name, ParseOrThrow<v1::Scene>((common + text).c_str())};
    base.scene.set_name("fuzz-" + name);
    scenes.push_back(std::move(base));
  }
  return scenes;
}

}  // namespace

const std::vector<BaseScene>& BaseScenes() {
  static const std::vector<BaseScene> scenes = MakeBaseScenes();
  return scenes;
}

const v1::Calibration& BaseCalibration() {
  // The base scene's own fluid, boundary and lattice, with the calibration's aperture law.
  static const v1::Calibration calibration = [] {
    v1::Calibration c = ParseOrThrow<v1::Calibration>(R"pb(
      name: "fuzz-calibration"
      target_permeabilities_m2: [ 1e-13 ]
      max_iterations: 10
      tags: "fuzz"
      stress { uniform_normal_force_n: 5 })pb");
    *c.mutable_scene() = BaseScenes().front().scene;
    c.mutable_scene()->clear_name();
    c.mutable_scene()->clear_solver();
    c.mutable_scene()->mutable_aperture()->clear_residual_aperture_m();
    c.mutable_scene()->mutable_aperture()->set_reference_force_n(10);
    return c;
  }();
  return calibration;
}

const v1::Sweep& BaseSweep() {
  static const v1::Sweep sweep = [] {
    // A zipped pair of axes (the mutations switch it to a product, or make it uneven).
    v1::Sweep s = ParseOrThrow<v1::Sweep>(R"pb(
      name: "fuzz-sweep"
      combine: SWEEP_COMBINE_ZIP
      axes {
        path: "fluid.viscosity_pa_s"
        numbers: [ 1e-3, 2e-3 ]
      }
      axes {
        path: "boundary.outlet_pressure_pa"
        numbers: [ 0, 5e4 ]
      })pb");
    *s.mutable_scene() = BaseScenes().front().scene;
    return s;
  }();
  return sweep;
}

}  // namespace seep::fuzz
