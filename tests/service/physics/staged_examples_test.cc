// The staged example scenes run in-process through the codec (what seepd runs): their protocols
// end each stage on its condition and give the numbers examples/README.md quotes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <variant>

#include "codec/scene_codec.h"
#include "example_runs.h"
#include "seep/core/reference/terzaghi.h"
#include "seep/core/run/simulation.h"
#include "terzaghi_column_probe.h"
#include "test_support.h"

namespace seep {
namespace {

using physics_test::Metric;
using physics_test::RunExample;

// Anisotropic fracturing in stages (examples/anisotropic_fracturing.textproto): the confinement
// stage ends when the four platens hold sigma_H and sigma_h, the injection stage on the well
// pressure's fall after breakdown; the breakdown is within 20 % of Hubbert-Willis
// 3 sigma_h - sigma_H + T, and the fracture (the principal axis of the broken bonds' midpoints)
// lies within 20 degrees of the sigma_H axis (x).
TEST(StagedExamples, AnisotropicFracturingBreaksDownAndRunsAlongSigmaH) {
  constexpr double kSigmaH = 2e5, kSigmah = 1e5, kTensile = 1e5;  // as the example says
  const std::map<std::string, double> m =
      RunExample(testing::ExampleScene("anisotropic_fracturing.textproto"));
  ASSERT_FALSE(m.empty());
  const double breakdown = Metric(m, "breakdown_pressure_pa");
  const double angle = Metric(m, "fracture_angle_deg");
  std::printf(
      "anisotropic: confine %.4g s (walls %.4g %.4g %.4g %.4g Pa), inject %.4g s ended by %g, "
      "breakdown %.4g Pa (Hubbert-Willis %.4g), %g bonds broken, fracture angle %.3g deg "
      "(spread %.3g)\n",
      Metric(m, "stage1_duration_s"), Metric(m, "stage1_left_wall_stress_pa"),
      Metric(m, "stage1_right_wall_stress_pa"), Metric(m, "stage1_bottom_wall_stress_pa"),
      Metric(m, "stage1_top_wall_stress_pa"), Metric(m, "stage2_duration_s"),
      Metric(m, "stage2_ended_by"), breakdown, 3.0 * kSigmah - kSigmaH + kTensile,
      Metric(m, "bonds_broken"), angle, Metric(m, "fracture_spread_ratio"));
  // Each stage ended by its own condition; the platens held their targets when confinement ended.
  EXPECT_EQ(Metric(m, "stage1_ended_by"), 0.0);
  EXPECT_GE(Metric(m, "stage2_ended_by"), 0.0);
  EXPECT_EQ(Metric(m, "stage3_ended_by"), 0.0);
  for (const char* wall : {"left", "right"}) {
    EXPECT_NEAR(Metric(m, std::string("stage1_") + wall + "_wall_stress_pa"), kSigmaH,
                0.02 * kSigmaH);
  }
  for (const char* wall : {"bottom", "top"}) {
    EXPECT_NEAR(Metric(m, std::string("stage1_") + wall + "_wall_stress_pa"), kSigmah,
                0.02 * kSigmah);
  }
  const double hubbert_willis = 3.0 * kSigmah - kSigmaH + kTensile;
  EXPECT_NEAR(breakdown, hubbert_willis, 0.2 * hubbert_willis);
  // The axis of a line has no sign: 3 degrees and 177 degrees are both 3 degrees off x.
  EXPECT_LE(std::min(angle, 180.0 - angle), 20.0);
  EXPECT_LT(Metric(m, "fracture_spread_ratio"), 0.05);  // the breaks lie along a line
  EXPECT_GT(Metric(m, "bonds_broken"), 10.0);
  // Shut in: nothing injected after the injection stage.
  EXPECT_EQ(Metric(m, "fluid_injected_m2"), Metric(m, "stage2_fluid_injected_m2"));
}

// Two load steps on the V17 column by a schedule of the platen's servo target: the isochrones
// after the second step match the superposition of the two steps' Terzaghi solutions, with
// E_oed and k measured on the example's own column.
TEST(StagedExamples, TerzaghiTwoLoadStepsSuperpose) {
  using core::terzaghi_probe::kTopWall;
  const core::terzaghi_probe::OneThread one_thread;
  constexpr double kStep1 = 2e4, kStep2 = 1.5e4, kSecondAt = 0.03;  // as the example says
  auto decoded = service::SceneFromProto(testing::ExampleScene("terzaghi_two_steps.textproto"));
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  const core::SceneSpec column = *decoded;
  const auto& top = std::get<core::WallsEffectSpec>(column.effects[1]).walls[kTopWall];
  ASSERT_TRUE(top.drain.has_value());

  // E_oed: the first step drained (the skeleton alone, damped, to rest); the skeleton of touching
  // lattice disks with linear springs is linear, so it holds for the second step as well.
  core::SceneSpec drained = column;
  core::ContactsEffectSpec contacts = std::get<core::ContactsEffectSpec>(column.effects[0]);
  contacts.dt_safety = 0.2;
  drained.effects = {contacts, column.effects[1], core::LocalDampingEffectSpec{0.7}};
  drained.stages[0].walls.clear();  // the scene's 2e4 Pa throughout
  drained.stages[0].end = {core::DurationEnd{0.03}};
  core::Result<core::Simulation> box = core::Simulation::Create(drained);
  ASSERT_TRUE(box.ok()) << box.status().message();
  const double height = box->stepper().state().walls[kTopWall].py -
                        box->stepper().state().walls[core::terzaghi_probe::kBottomWall].py;
  const auto dry = core::terzaghi_probe::RunAndSample(drained, 100);
  ASSERT_FALSE(HasFailure());
  const double settled = dry.back().settlement;
  ASSERT_NEAR(settled, core::terzaghi_probe::SettlementAt(dry, 0.75 * dry.back().t),
              1e-4 * settled);
  const double e_oed = kStep1 * height / settled;

  core::TerzaghiParameters terzaghi;
  terzaghi.permeability =
      core::terzaghi_probe::WalledPermeability(column, top.drain->conductance_m_per_pa_s);
  terzaghi.viscosity = column.fluid.viscosity_pa_s;
  terzaghi.oedometer_modulus = e_oed;
  terzaghi.storage_porosity = column.solver.storage_factor;
  terzaghi.fluid_bulk_modulus = column.fluid.bulk_modulus_pa;
  terzaghi.drainage_length = height;
  terzaghi.load_step = 1.0;  // u0 per Pa of load: B
  ASSERT_TRUE(core::ValidateTerzaghiParameters(terzaghi).ok());
  const double b = core::InitialExcessPressure(terzaghi);

  // The example as it is, with isochrones; each step acts from its load history's centroid.
  std::vector<core::terzaghi_probe::Isochrone> isochrones;
  const auto run = core::terzaghi_probe::RunAndSample(column, 20, &isochrones);
  ASSERT_FALSE(HasFailure());
  const double t1 = core::terzaghi_probe::LoadCentroid(run, 0.0, kSecondAt, 0.0, kStep1);
  const double t2 = core::terzaghi_probe::LoadCentroid(
      run, kSecondAt, std::numeric_limits<double>::infinity(), kStep1, kStep2);
  std::printf(
      "two steps: E_oed %.4g Pa, k %.4g m^2, B %.4f, H^2/c_v %.4g s, t1 %.4g s, t2 %.4g s\n", e_oed,
      terzaghi.permeability, b, core::TimeForTimeFactor(terzaghi, 1.0), t1, t2);
  for (const double wanted : {0.05, 0.2, 0.5}) {
    const double t_wanted = t2 + core::TimeForTimeFactor(terzaghi, wanted);
    const auto& iso =
        *std::min_element(isochrones.begin(), isochrones.end(), [&](const auto& x, const auto& y) {
          return std::abs(x.t - t_wanted) < std::abs(y.t - t_wanted);
        });
    const double tv1 = core::TimeFactor(terzaghi, iso.t - t1);
    const double tv2 = core::TimeFactor(terzaghi, iso.t - t2);
    for (std::size_t k = 0; k < iso.depth.size(); ++k) {
      const double z = iso.depth[k] / height;
      const double expected = b * kStep1 * core::ExcessPressureRatio(z, tv1) +
                              b * kStep2 * core::ExcessPressureRatio(z, tv2);
      std::printf("two steps: Tv2 %.3f z/H %.3f u %.5g Pa, superposition %.5g Pa (%+.4f dsigma2)\n",
                  tv2, z, iso.pressure[k], expected, (iso.pressure[k] - expected) / kStep2);
      EXPECT_NEAR(iso.pressure[k], expected, 0.05 * kStep2) << "Tv2 " << tv2 << " z/H " << z;
    }
  }
}

// Drained biaxial shear with seepage (examples/biaxial_shear_seepage.textproto): over the shear
// stage the series gives the lid's stress and the permeability between the side platens against
// the axial strain; past the peak stress the dense packing dilates and k exceeds k at the peak.
TEST(StagedExamples, BiaxialShearPermeabilityRisesPastThePeak) {
  auto decoded = service::SceneFromProto(testing::ExampleScene("biaxial_shear_seepage.textproto"));
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  auto sim = core::Simulation::Create(*decoded);
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  const core::Status run = sim->Run({});
  ASSERT_TRUE(run.ok()) << run.message();
  const core::TimeSeries& series = sim->series();
  const auto column = [&](const std::string& name) {
    const auto it = std::find(series.columns.begin(), series.columns.end(), name);
    EXPECT_NE(it, series.columns.end()) << name;
    return static_cast<std::size_t>(it - series.columns.begin());
  };
  const std::size_t width = series.columns.size();
  const std::size_t stage = column("stage"), stress = column("top_wall_stress_pa");
  const std::size_t lid = column("top_wall_position_m"), k = column("platen_permeability_m2");
  const auto at = [&](std::size_t row, std::size_t c) { return series.values[row * width + c]; };
  std::vector<std::size_t> shear;  // rows of the shear stage
  for (std::size_t row = 0; row < series.rows(); ++row) {
    if (at(row, stage) == 2.0) shear.push_back(row);
  }
  ASSERT_GT(shear.size(), 20u);
  const double lid0 = at(shear.front(), lid);
  std::size_t peak = shear.front();
  for (const std::size_t row : shear) {
    if (at(row, stress) > at(peak, stress)) peak = row;
  }
  const double height0 = lid0 - sim->stepper().state().walls[0].py;
  for (std::size_t j = 0; j < shear.size(); j += shear.size() / 20) {
    const std::size_t row = shear[j];
    std::printf("shear: axial strain %.4f  lid stress %.5g Pa  k %.4g m^2\n",
                (lid0 - at(row, lid)) / height0, at(row, stress), at(row, k));
  }
  const double k_peak = at(peak, k);
  const double k_end = at(shear.back(), k);
  std::printf("shear: peak %.5g Pa at strain %.4f, k there %.4g, k at the end %.4g (strain %.4f)\n",
              at(peak, stress), (lid0 - at(peak, lid)) / height0, k_peak, k_end,
              (lid0 - at(shear.back(), lid)) / height0);
  // A real peak: inside the stage, and the stress fell after it.
  ASSERT_NE(peak, shear.back());
  EXPECT_LT(at(shear.back(), stress), at(peak, stress));
  EXPECT_GT(k_end, k_peak);
}

}  // namespace
}  // namespace seep
