// `seep sweep` through the real binary against a real seepd: submit --watch (one progress line
// for the sweep), show as a table, CSV and JSON, plot (an SVG with one line per other parameter's
// value), cancel, resume and delete, and a bad sweep file pointed at its line.
#include <algorithm>
#include <sstream>

#include "seepd_fixture.h"
#include "terminal_run.h"

namespace seep::testing {
namespace {

using json = nlohmann::json;

// The steady 12 x 8 lattice swept over 2 pressures x 3 residual apertures: k = a0^3 / (24 R)
// exactly (docs/physics.md §1.3), whatever the pressure.
constexpr const char* kProductSweep = R"pb(
  name: "cli-sweep"
  scene {
    name: "cli-quick"
    packing { lattice { kind: LATTICE_KIND_SQUARE columns: 12 rows: 8 radius_m: 1e-3 } }
    fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
    aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
    boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 outlet_pressure_pa: 0 }
    solver { kind: SOLVER_KIND_STEADY }
  }
  combine: SWEEP_COMBINE_PRODUCT
  axes {
    path: "boundary.inlet_pressure_pa"
    numbers: [ 1e5, 2e5 ]
  }
  axes {
    path: "aperture.residual_aperture_m"
    numbers: [ 1e-5, 2e-5, 4e-5 ]
  }
)pb";

// An explicit run that never ends within a test, swept over three pressures.
constexpr const char* kEndlessSweep = R"pb(
  scene {
    name: "cli-endless"
    packing { lattice { kind: LATTICE_KIND_SQUARE columns: 60 rows: 60 radius_m: 1e-3 } }
    fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
    aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
    boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
    solver {
      kind: SOLVER_KIND_EXPLICIT
      storage: STORAGE_VOLUME_PORE
      dt_factor: 0.9
      end_time_s: 1e6
    }
  }
  combine: SWEEP_COMBINE_PRODUCT
  axes {
    path: "boundary.inlet_pressure_pa"
    numbers: [ 1e5, 2e5, 3e5 ]
  }
)pb";

std::string SweepIdFrom(const std::string& output) {
  std::smatch m;
  if (std::regex_search(output, m, std::regex("sweep (s-[0-9a-f]{16})"))) return m[1];
  return {};
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

using CliSweeps = SeepdFixture;

TEST_F(CliSweeps, SubmitWatchShowCsvJsonAndPlot) {
  const CommandResult submit =
      Seep({"sweep", "submit", Write("sweep.textproto", kProductSweep), "--watch"});
  ASSERT_EQ(submit.exit_code, 0) << submit.output;
  const std::string id = SweepIdFrom(submit.output);
  ASSERT_FALSE(id.empty()) << submit.output;
  EXPECT_NE(submit.output.find("submitted sweep " + id + " with 6 jobs (new, request id r-"),
            std::string::npos)
      << submit.output;
  // stdout is a pipe: whole progress lines, the last one the finished sweep, then the table.
  EXPECT_NE(submit.output.find("SUCCEEDED 100.0%  sweep " + id +
                               "  6 jobs: 0 queued, 0 running, 6 succeeded, 0 failed, 0 "
                               "cancelled\n"),
            std::string::npos)
      << submit.output;
  EXPECT_EQ(submit.output.find('\r'), std::string::npos);
  EXPECT_NE(submit.output.find("POSITION  JOB "), std::string::npos) << submit.output;

  const CommandResult csv = Seep(
      {"sweep", "show", id, "--csv", "--metrics", "permeability_m2,domain_count,inflow_m2_per_s"});
  ASSERT_EQ(csv.exit_code, 0) << csv.output;
  const std::vector<std::string> lines = Split(csv.output, '\n');
  ASSERT_EQ(lines.size(), 7u) << csv.output;
  EXPECT_EQ(lines[0],
            "position,job_id,state,boundary.inlet_pressure_pa,aperture.residual_aperture_m,"
            "permeability_m2,domain_count,inflow_m2_per_s");
  const double pressures[] = {1e5, 2e5};
  const double apertures[] = {1e-5, 2e-5, 4e-5};
  std::vector<double> inflows;
  for (int p = 0; p < 6; ++p) {
    const std::vector<std::string> cells = Split(lines[p + 1], ',');
    ASSERT_EQ(cells.size(), 8u) << lines[p + 1];
    EXPECT_EQ(cells[0], std::to_string(p));
    EXPECT_EQ(cells[1].rfind("j-", 0), 0u);
    EXPECT_EQ(cells[2], "SUCCEEDED");
    EXPECT_EQ(std::stod(cells[3]), pressures[p / 3]);
    EXPECT_EQ(std::stod(cells[4]), apertures[p % 3]);
    const double a0 = apertures[p % 3];
    const double k = a0 * a0 * a0 / (24.0 * 1e-3);
    EXPECT_NEAR(std::stod(cells[5]), k, 1e-9 * k) << lines[p + 1];
    EXPECT_EQ(cells[6], "77");  // 11 x 7 pores
    inflows.push_back(std::stod(cells[7]));
  }
  // Darcy: the inflow is proportional to the pressure drop and to a0^3.
  EXPECT_NEAR(inflows[3] / inflows[0], 2.0, 1e-9);
  EXPECT_NEAR(inflows[2] / inflows[0], 64.0, 64e-9);

  // The jobs carry the sweep's label: `seep list --label sweep=<id>` finds all six.
  EXPECT_EQ(Json({"list", "--label", "sweep=" + id})["jobs"].size(), 6u);

  const json shown = Json({"sweep", "show", id});
  EXPECT_EQ(shown["id"], id);
  EXPECT_EQ(shown["counts"]["succeeded"], 6);
  ASSERT_EQ(shown["jobs"].size(), 6u);
  EXPECT_EQ(shown["jobs"][4]["settings"][1]["number"].get<double>(), 2e-5);

  const CommandResult table = Seep({"sweep", "show", id, "--metrics", "permeability_m2"});
  ASSERT_EQ(table.exit_code, 0) << table.output;
  EXPECT_TRUE(std::regex_search(
      table.output, std::regex("\n5 +j-[0-9a-f]{16} +SUCCEEDED +200000 +4e-05 +2.66666667e-12\n")))
      << table.output;

  const std::string svg = (dir_ / "k.svg").string();
  const CommandResult plot = Seep({"sweep", "plot", id, "--x", "aperture.residual_aperture_m",
                                   "--y", "permeability_m2", "--out", svg});
  ASSERT_EQ(plot.exit_code, 0) << plot.output;
  std::ifstream in(svg);
  const std::string drawn((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(drawn.rfind("<svg", 0), 0u);
  // One line per inlet pressure, named in the legend.
  EXPECT_NE(drawn.find("boundary.inlet_pressure_pa = 100000"), std::string::npos);
  EXPECT_NE(drawn.find("boundary.inlet_pressure_pa = 200000"), std::string::npos);
  EXPECT_EQ(drawn.find(">1e-14<"), std::string::npos);  // linear axes: no decade labels
  // On log axes k = a0^3 / (24 R) spans the decades 1e-14 .. 1e-11 (a0 from 1e-5 to 4e-5).
  const CommandResult log_plot =
      Seep({"sweep", "plot", id, "--x", "aperture.residual_aperture_m", "--y", "permeability_m2",
            "--log-x", "--log-y", "--out", svg});
  ASSERT_EQ(log_plot.exit_code, 0) << log_plot.output;
  std::ifstream log_in(svg);
  const std::string log_drawn((std::istreambuf_iterator<char>(log_in)),
                              std::istreambuf_iterator<char>());
  for (const char* decade : {">1e-14<", ">1e-11<", ">1e-5<", ">1e-4<"}) {
    EXPECT_NE(log_drawn.find(decade), std::string::npos) << decade;
  }
  EXPECT_EQ(log_drawn.find(">1e-10<"), std::string::npos);
  const CommandResult bad_x = Seep(
      {"sweep", "plot", id, "--x", "fluid.viscosity_pa_s", "--y", "permeability_m2", "--out", svg});
  EXPECT_EQ(bad_x.exit_code, 3);
  EXPECT_NE(bad_x.output.find("--x fluid.viscosity_pa_s: not a swept parameter"), std::string::npos)
      << bad_x.output;
  const CommandResult bad_metric = Seep({"sweep", "show", id, "--metrics", "permeability"});
  EXPECT_EQ(bad_metric.exit_code, 3);
  EXPECT_NE(bad_metric.output.find("--metrics permeability: no job of sweep"), std::string::npos)
      << bad_metric.output;
}

TEST_F(CliSweeps, WatchRedrawsOneLineCutToTheTerminal) {
  const CommandResult run = RunOnTerminal({SEEP_CLI_PATH, "--server", address_, "sweep", "submit",
                                           Write("sweep.textproto", kProductSweep), "--watch"},
                                          60);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // The final line: cursor back, line cleared, state and percent first, cut to 59 columns.
  const auto final_line = run.output.find("\r\033[KSUCCEEDED 100.0%  sweep s-");
  ASSERT_NE(final_line, std::string::npos) << run.output;
  std::size_t start = 0;
  while ((start = run.output.find("\r\033[K", start)) != std::string::npos) {
    start += 4;
    const auto end = run.output.find_first_of("\r\n", start);
    EXPECT_LE(end - start, 59u) << run.output.substr(start, end - start);
  }
  EXPECT_NE(run.output.find("POSITION  JOB", final_line), std::string::npos) << run.output;
}

TEST_F(CliSweeps, BadValueIsPointedAtItsLineAndNothingIsQueued) {
  std::string text = kProductSweep;
  text.replace(text.find("2e-5"), 4, "-2e-5");
  const CommandResult submit = Seep({"sweep", "submit", Write("bad.textproto", text)});
  EXPECT_EQ(submit.exit_code, 3) << submit.output;
  // The error points at the line that holds the bad value.
  const auto line = 1 + std::count(text.begin(), text.begin() + text.find("-2e-5"), '\n');
  EXPECT_NE(submit.output.find("bad.textproto:" + std::to_string(line) +
                               ": sweep.axes[1].numbers[1]: aperture.residual_aperture_m = "
                               "-2e-05 makes an invalid scene: "
                               "scene.aperture.residual_aperture_m: must be"),
            std::string::npos)
      << submit.output;
  EXPECT_EQ(Json({"list"})["jobs"].size(), 0u);
}

TEST_F(CliSweeps, CancelResumeAndDeleteTheWholeSweep) {
  const CommandResult submit = Seep({"sweep", "submit", Write("endless.textproto", kEndlessSweep)});
  ASSERT_EQ(submit.exit_code, 0) << submit.output;
  const std::string id = SweepIdFrom(submit.output);
  const CommandResult early_delete = Seep({"sweep", "delete", id});
  EXPECT_EQ(early_delete.exit_code, 9) << early_delete.output;  // FAILED_PRECONDITION

  const CommandResult cancel = Seep({"sweep", "cancel", id});
  ASSERT_EQ(cancel.exit_code, 0) << cancel.output;
  EXPECT_TRUE(std::regex_search(
      cancel.output,
      std::regex("sweep " + id + ": [0-9] queued job\\(s\\) cancelled, [0-9] running")))
      << cancel.output;
  // Every job ends CANCELLED (a running one at its next step).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  const auto all_cancelled = [&]() {
    json shown;
    do {
      shown = Json({"sweep", "show", id});
    } while (shown["counts"].value("cancelled", 0) != 3 &&
             std::chrono::steady_clock::now() < deadline);
    EXPECT_EQ(shown["counts"].value("cancelled", 0), 3) << shown.dump(2);
    return shown["counts"].value("cancelled", 0) == 3;
  };
  ASSERT_TRUE(all_cancelled());

  const CommandResult resume = Seep({"sweep", "resume", id});
  ASSERT_EQ(resume.exit_code, 0) << resume.output;
  EXPECT_NE(resume.output.find("sweep " + id + ": 3 job(s) queued again"), std::string::npos);
  ASSERT_EQ(Seep({"sweep", "cancel", id}).exit_code, 0);
  ASSERT_TRUE(all_cancelled());

  const CommandResult removed = Seep({"sweep", "delete", id});
  ASSERT_EQ(removed.exit_code, 0) << removed.output;
  EXPECT_NE(removed.output.find("sweep " + id + " deleted with 3 job(s)"), std::string::npos)
      << removed.output;
  EXPECT_EQ(Seep({"sweep", "show", id}).exit_code, 5);  // NOT_FOUND
  EXPECT_EQ(Json({"list"})["jobs"].size(), 0u);
}

}  // namespace
}  // namespace seep::testing
