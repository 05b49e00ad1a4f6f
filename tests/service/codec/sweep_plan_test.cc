// Field paths set through protobuf reflection, and sweeps expanded into their points: every
// refusal names the Sweep field at fault and why.
#include "codec/sweep_plan.h"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "codec/field_path.h"

namespace seep::service {
namespace {

v1::Scene BaseScene() {
  v1::Scene scene;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "base"
        packing {
          random {
            seed: 7
            width_m: 0.02
            height_m: 0.02
            min_radius_m: 4e-4
            max_radius_m: 6e-4
            particle_count: 200
            target_porosity: 0.2
          }
        }
        fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
        aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
        boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
        solver { kind: SOLVER_KIND_STEADY }
        effects { flow {} }
        effects { injection { rate_m2_s: 1e-6 } }
      )pb",
      &scene));
  return scene;
}

v1::SweepSetting Number(double x) {
  v1::SweepSetting s;
  s.set_number(x);
  return s;
}
v1::SweepSetting Text(const std::string& t) {
  v1::SweepSetting s;
  s.set_text(t);
  return s;
}

// The message of setting `path` to `value` in the base scene; "" when it succeeds.
std::string SetError(const std::string& path, const v1::SweepSetting& value, v1::Scene* scene) {
  const core::Result<FieldSlot> slot = ResolveFieldPath(*scene, path);
  if (!slot.ok()) return slot.status().message();
  const core::Status set = SetFieldValue(*slot, value);
  return set.ok() ? "" : set.message();
}

TEST(FieldPath, SetsNestedRepeatedIntegerAndEnumFields) {
  v1::Scene scene = BaseScene();
  EXPECT_EQ(SetError("boundary.inlet_pressure_pa", Number(2.5e5), &scene), "");
  EXPECT_EQ(scene.boundary().inlet_pressure_pa(), 2.5e5);
  EXPECT_EQ(SetError("effects[1].injection.rate_m2_s", Number(3e-6), &scene), "");
  EXPECT_EQ(scene.effects(1).injection().rate_m2_s(), 3e-6);
  EXPECT_EQ(SetError("packing.random.seed", Number(42), &scene), "");
  EXPECT_EQ(scene.packing().random().seed(), 42u);
  EXPECT_EQ(SetError("solver.kind", Text("SOLVER_KIND_IMPLICIT"), &scene), "");
  EXPECT_EQ(scene.solver().kind(), v1::SOLVER_KIND_IMPLICIT);
  EXPECT_EQ(SetError("name", Text("renamed"), &scene), "");
  EXPECT_EQ(scene.name(), "renamed");
  // Nothing else moved: the scene differs from the base in exactly those five fields.
  v1::Scene expected = BaseScene();
  expected.mutable_boundary()->set_inlet_pressure_pa(2.5e5);
  expected.mutable_effects(1)->mutable_injection()->set_rate_m2_s(3e-6);
  expected.mutable_packing()->mutable_random()->set_seed(42);
  expected.mutable_solver()->set_kind(v1::SOLVER_KIND_IMPLICIT);
  expected.set_name("renamed");
  EXPECT_EQ(scene.SerializeAsString(), expected.SerializeAsString());
}

TEST(FieldPath, RefusesBadPathsNamingTheStepAndWhy) {
  v1::Scene scene = BaseScene();
  EXPECT_EQ(SetError("boundary.inlet_presure_pa", Number(1), &scene)
                .rfind("seep.v1.Boundary has no field 'inlet_presure_pa' (its fields: axis, ", 0),
            0u);
  EXPECT_EQ(SetError("effects[5].injection.rate_m2_s", Number(1), &scene),
            "effects[5]: the base has 2 element(s) there");
  EXPECT_EQ(SetError("effects.injection.rate_m2_s", Number(1), &scene),
            "'effects' is a repeated field: name one element, e.g. effects[0]");
  EXPECT_EQ(SetError("effects[0].injection.rate_m2_s", Number(1), &scene),
            "'injection' is a member of oneof 'kind', and the base sets 'flow': a sweep changes "
            "fields the base has, not which member of a oneof it uses");
  scene.add_effects();
  EXPECT_EQ(SetError("effects[2].injection.rate_m2_s", Number(1), &scene),
            "'injection' is a member of oneof 'kind', which the base leaves unset: a sweep "
            "changes fields the base has, not which member of a oneof it uses");
  EXPECT_EQ(SetError("packing.lattice.columns", Number(4), &scene),
            "'lattice' is a member of oneof 'source', and the base sets 'random': a sweep "
            "changes fields the base has, not which member of a oneof it uses");
  EXPECT_EQ(SetError("packing.random.target_coordination", Number(4), &scene),
            "'target_coordination' is a member of oneof 'target', and the base sets "
            "'target_porosity': a sweep changes fields the base has, not which member of a oneof "
            "it uses");
  EXPECT_EQ(SetError("boundary", Number(1), &scene)
                .rfind("'boundary' is a message (seep.v1.Boundary)", 0),
            0u);
  EXPECT_EQ(SetError("boundary..axis", Number(1), &scene),
            "has an empty step (two dots, or a leading dot)");
  EXPECT_EQ(SetError("effects[x].flow", Number(1), &scene),
            "'effects[x]' is not a field name with an index such as effects[0]");
  EXPECT_EQ(SetError("name.first", Text("a"), &scene),
            "'name' is a string field (give texts), not a message: the path cannot go on past it");
}

TEST(FieldPath, RefusesValuesOfTheWrongType) {
  v1::Scene scene = BaseScene();
  EXPECT_EQ(SetError("boundary.inlet_pressure_pa", Text("high"), &scene),
            "the field is a floating-point field (give numbers); got a text");
  EXPECT_EQ(SetError("packing.random.particle_count", Number(10.5), &scene),
            "is not an integer (got 10.5)");
  EXPECT_EQ(SetError("packing.random.particle_count", Number(-1), &scene),
            "is outside the field's range 0..4294967295 (got -1)");
  EXPECT_EQ(SetError("packing.random.seed", Number(1e17), &scene),
            "is beyond 2^53, where numbers lose digits (1e+17)");
  EXPECT_EQ(SetError("solver.kind", Text("SOLVER_KIND_FAST"), &scene),
            "'SOLVER_KIND_FAST' is not a value of seep.v1.SolverKind (its values: "
            "SOLVER_KIND_UNSPECIFIED, SOLVER_KIND_STEADY, SOLVER_KIND_EXPLICIT, "
            "SOLVER_KIND_IMPLICIT, SOLVER_KIND_CRANK_NICOLSON)");
  EXPECT_EQ(SetError("boundary.closed_inlet", Number(1), &scene),
            "the field is a bool field (give flags); got a number");
}

v1::Sweep SweepOf(const std::string& text) {
  v1::Sweep sweep;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &sweep)) << text;
  return sweep;
}

// The plan's points as "v1,v2|v1,v2|...".
std::string Points(const SweepPlan& plan) {
  std::string out;
  for (const SweepPoint& p : plan.points) {
    if (!out.empty()) out += "|";
    for (std::size_t i = 0; i < p.settings.size(); ++i) {
      if (i > 0) out += ",";
      out += SettingValueText(p.settings[i]);
    }
  }
  return out;
}

TEST(SweepPlan, ProductVariesTheLastAxisFastestAndReplicatesInnermost) {
  const v1::Scene base = BaseScene();
  const auto plan = PlanSweep(SweepOf(R"pb(
                                combine: SWEEP_COMBINE_PRODUCT
                                axes {
                                  path: "boundary.inlet_pressure_pa"
                                  numbers: [ 1, 2 ]
                                }
                                axes {
                                  path: "solver.kind"
                                  texts: [ "SOLVER_KIND_STEADY", "SOLVER_KIND_IMPLICIT" ]
                                }
                                replicates { seed_path: "packing.random.seed" count: 2 }
                              )pb"),
                              base, 100);
  ASSERT_TRUE(plan.ok()) << plan.status().ToString();
  EXPECT_EQ(plan->parameters, (std::vector<std::string>{"boundary.inlet_pressure_pa", "solver.kind",
                                                        "packing.random.seed"}));
  // Seeds from the base's own (7) on.
  EXPECT_EQ(Points(*plan),
            "1,SOLVER_KIND_STEADY,7|1,SOLVER_KIND_STEADY,8|1,SOLVER_KIND_IMPLICIT,7|"
            "1,SOLVER_KIND_IMPLICIT,8|2,SOLVER_KIND_STEADY,7|2,SOLVER_KIND_STEADY,8|"
            "2,SOLVER_KIND_IMPLICIT,7|2,SOLVER_KIND_IMPLICIT,8");
  EXPECT_EQ(
      plan->points[5].value_fields,
      (std::vector<std::string>{"axes[0].numbers[1]", "axes[1].texts[0]", "replicates.count"}));
}

TEST(SweepPlan, ZipPairsTheValuesInOrder) {
  const auto plan = PlanSweep(SweepOf(R"pb(
                                combine: SWEEP_COMBINE_ZIP
                                axes {
                                  path: "boundary.inlet_pressure_pa"
                                  numbers: [ 1, 2, 3 ]
                                }
                                axes {
                                  path: "fluid.viscosity_pa_s"
                                  numbers: [ 4, 5, 6 ]
                                }
                                replicates {
                                  seed_path: "packing.random.seed"
                                  seeds: [ 11, 3 ]
                                }
                              )pb"),
                              BaseScene(), 100);
  ASSERT_TRUE(plan.ok()) << plan.status().ToString();
  EXPECT_EQ(Points(*plan), "1,4,11|1,4,3|2,5,11|2,5,3|3,6,11|3,6,3");
}

TEST(SweepPlan, RefusalsNameTheSweepField) {
  const v1::Scene base = BaseScene();
  const auto refusal = [&](const std::string& text) {
    const auto plan = PlanSweep(SweepOf(text), base, 10);
    EXPECT_FALSE(plan.ok()) << text;
    EXPECT_EQ(plan.status().code(), core::StatusCode::kInvalidArgument);
    return plan.status().message();
  };
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_ZIP
                         axes {
                           path: "boundary.inlet_pressure_pa"
                           numbers: [ 1, 2, 3 ]
                         }
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 4, 5 ]
                         })pb"),
            "sweep.axes[1]: a zipped sweep needs axes of equal length: axes[0] has 3 values, "
            "axes[1] has 2");
  EXPECT_EQ(refusal(R"pb(axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 4, 5 ]
                         })pb"),
            "sweep.combine: must be SWEEP_COMBINE_PRODUCT or SWEEP_COMBINE_ZIP (got "
            "SWEEP_COMBINE_UNSPECIFIED)");
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 4 ]
                         }
                         axes {
                           path: "fluid.viscosity"
                           numbers: [ 4 ]
                         })pb")
                .rfind("sweep.axes[1].path: 'fluid.viscosity': seep.v1.Fluid has no field "
                       "'viscosity'",
                       0),
            0u);
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "packing.random.particle_count"
                           numbers: [ 10, 20.5 ]
                         })pb"),
            "sweep.axes[0].numbers[1]: packing.random.particle_count = 20.5: is not an integer "
            "(got 20.5)");
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 1 ]
                           texts: [ "a" ]
                         })pb"),
            "sweep.axes[0]: give the values of 'fluid.viscosity_pa_s' in exactly one of "
            "numbers, texts or flags (it has 2 non-empty lists)");
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 1 ]
                         }
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 2 ]
                         })pb"),
            "sweep.axes[1].path: 'fluid.viscosity_pa_s' is swept by axes[0] already");
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 1, 2, 3, 4 ]
                         }
                         axes {
                           path: "fluid.bulk_modulus_pa"
                           numbers: [ 1, 2, 3 ]
                         })pb"),
            "sweep: 12 jobs exceed the limit of 10 per sweep");
  // Counts and lists past the limit are refused from the request's sizes, naming the field,
  // before a value is copied (replicates.count 2^32-1 once built 4e9 settings first).
  EXPECT_EQ(refusal(R"pb(replicates { seed_path: "packing.random.seed" count: 4294967295 })pb"),
            "sweep.replicates.count: 4294967295 replicates exceed the limit of 10 jobs per sweep");
  EXPECT_EQ(refusal(R"pb(replicates { seed_path: "packing.random.seed" count: 11 })pb"),
            "sweep.replicates.count: 11 replicates exceed the limit of 10 jobs per sweep");
  EXPECT_EQ(refusal(R"pb(replicates {
                           seed_path: "packing.random.seed"
                           seeds: [ 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11 ]
                         })pb"),
            "sweep.replicates.seeds: 11 seeds exceed the limit of 10 jobs per sweep");
  EXPECT_EQ(refusal(R"pb(combine: SWEEP_COMBINE_ZIP
                         axes {
                           path: "fluid.viscosity_pa_s"
                           numbers: [ 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11 ]
                         })pb"),
            "sweep.axes[0]: 11 values exceed the limit of 10 jobs per sweep");
  EXPECT_EQ(refusal(R"pb(replicates { seed_path: "fluid.viscosity_pa_s" count: 2 })pb"),
            "sweep.replicates.seed_path: 'fluid.viscosity_pa_s': a seed is an integer field; "
            "this one is a floating-point field (give numbers)");
  EXPECT_EQ(refusal(""), "sweep.axes: a sweep needs at least one axis or replicates");
}

}  // namespace
}  // namespace seep::service
