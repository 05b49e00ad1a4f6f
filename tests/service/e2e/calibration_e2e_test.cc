// Calibration through the real seepd and seep binaries: submit the example sweep
// (examples/calibration_sweep.textproto) with `seep calibrate --watch`, query its records back
// with `seep calibrations` (table filters, CSV, JSON, tags) and `seep calibrations lookup`, and
// take the packing of an earlier simulation job with --from-job.
#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "process.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "seepd_fixture.h"

namespace seep::testing {
namespace {

using nlohmann::json;

const std::string kCalibrationExample =
    std::string(SEEP_EXAMPLES_DIR) + "/calibration_sweep.textproto";
const std::vector<double> kTargets = {1e-14, 3e-14, 1e-13, 3e-13, 1e-12};
// The example's tolerance on |k - k_target| / k_target.
constexpr double kTolerance = 1e-6;

// 17 significant digits: the double itself, for command-line arguments.
std::string Full(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

// CSV output as one map per row, keyed by the header's names.
std::vector<std::map<std::string, std::string>> ParseCsv(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream cell_stream(line);
    std::string cell;
    while (std::getline(cell_stream, cell, ',')) cells.push_back(cell);
    if (header.empty()) {
      header = cells;
      continue;
    }
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < cells.size() && i < header.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(std::move(row));
  }
  return rows;
}

class CalibrationE2e : public SeepdFixture {
 protected:
  std::vector<std::string> ExtraSeepdFlags() const override { return {"--workers", "1"}; }

  // Runs the example sweep to SUCCEEDED; returns its job id.
  std::string CalibrateExample() {
    const CommandResult run = Seep({"calibrate", kCalibrationExample, "--watch", "--tag", "e2e"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("SUCCEEDED"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("kind      CALIBRATION"), std::string::npos) << run.output;
    return JobIdFrom(run.output);
  }

  json Json(std::vector<std::string> args) {
    args.push_back("--json");
    const CommandResult r = Seep(args);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return json::parse(r.output, nullptr, /*allow_exceptions=*/false);
  }
};

TEST_F(CalibrationE2e, SweepIsStoredAndQueriedBackThroughTheCli) {
  const std::string id = CalibrateExample();
  ASSERT_FALSE(id.empty());

  // The job's result: per-target a0 and the sweep's worst error.
  const json result = Json({"result", id});
  ASSERT_FALSE(result.is_discarded());
  EXPECT_EQ(result["result"]["metrics"]["target_count"].get<double>(), 5.0);
  EXPECT_LT(result["result"]["metrics"]["max_relative_error"].get<double>(), kTolerance);

  // Every record, as JSON: five, one per target, each reproducing its target within tolerance.
  const json all = Json({"calibrations"});
  ASSERT_FALSE(all.is_discarded());
  ASSERT_EQ(all["records"].size(), 5u) << all.dump(2);
  std::set<double> targets;
  for (const json& r : all["records"]) {
    EXPECT_EQ(r["job_id"], id);
    const double target = r["target_permeability_m2"].get<double>();
    const double k = r["permeability_m2"].get<double>();
    targets.insert(target);
    EXPECT_LT(std::abs(k - target) / target, kTolerance) << r.dump();
    EXPECT_EQ(r["converged"], true);
    EXPECT_GT(r["residual_aperture_m"].get<double>(), 0.0);
    // The example compresses every contact: apertures proportional to a0, so the first guess
    // and one cube-root correction suffice.
    EXPECT_EQ(r["iterations"].get<int>(), 2) << r.dump();
    EXPECT_EQ(r["stress"]["aperture_proportional_to_a0"], true);
    EXPECT_EQ(r["packing"]["particle_count"], "300");  // uint64 travels as a JSON string
    EXPECT_EQ(r["tags"], json({"e2e", "example", "random-300"}));
    EXPECT_EQ(r["scene_sha256"].get<std::string>().size(), 64u);
  }
  EXPECT_EQ(targets, std::set<double>(kTargets.begin(), kTargets.end()));
  // k ~ a0^3 on this setup: a0 ratios are cube roots of the k ratios (to the tolerance).
  std::map<double, double> a0;
  for (const json& r : all["records"]) {
    a0[r["target_permeability_m2"].get<double>()] = r["residual_aperture_m"].get<double>();
  }
  EXPECT_NEAR(a0[1e-12] / a0[1e-14], std::cbrt(100.0), 1e-5);

  // A k range as CSV: exactly the three targets inside [2e-14, 5e-13], in full precision.
  const CommandResult csv = Seep({"calibrations", "--k-min", "2e-14", "--k-max", "5e-13", "--csv"});
  ASSERT_EQ(csv.exit_code, 0) << csv.output;
  const auto rows = ParseCsv(csv.output);
  ASSERT_EQ(rows.size(), 3u) << csv.output;
  std::set<double> csv_targets;
  for (const auto& row : rows) {
    const double target = std::stod(row.at("target_permeability_m2"));
    const double k = std::stod(row.at("permeability_m2"));
    csv_targets.insert(target);
    EXPECT_LT(std::abs(k - target) / target, kTolerance);
    EXPECT_EQ(std::stod(row.at("residual_aperture_m")), a0[target]);  // 17 digits round-trip
    EXPECT_EQ(row.at("job_id"), id);
    EXPECT_EQ(row.at("tags"), "e2e;example;random-300");
  }
  EXPECT_EQ(csv_targets, (std::set<double>{3e-14, 1e-13, 3e-13}));

  // Porosity and k together, as JSON; the porosity is the packing's own.
  const double porosity = all["records"][0]["packing"]["porosity_2d"].get<double>();
  const double radius = all["records"][0]["packing"]["mean_radius_m"].get<double>();
  const json both =
      Json({"calibrations", "--k-min", "1e-13", "--k-max", "1e-12", "--porosity-min",
            std::to_string(porosity - 0.01), "--porosity-max", std::to_string(porosity + 0.01)});
  EXPECT_EQ(both["records"].size(), 3u);
  const json none = Json({"calibrations", "--porosity-min", std::to_string(porosity + 0.01)});
  EXPECT_TRUE(none.empty() || none["records"].empty()) << none.dump();

  // Tags: every one given must be present.
  EXPECT_EQ(Json({"calibrations", "--tag", "e2e", "--tag", "example"})["records"].size(), 5u);
  const CommandResult untagged = Seep({"calibrations", "--tag", "e2e", "--tag", "nope"});
  ASSERT_EQ(untagged.exit_code, 0) << untagged.output;
  EXPECT_EQ(std::count(untagged.output.begin(), untagged.output.end(), '\n'), 1)
      << untagged.output;  // the header only

  // Look-up between two stored targets: the nearest record is k = 3e-13 (ln(1.5)/3 away; the
  // packing terms are 0), and a0 is interpolated log-log between 1e-13 and 3e-13.
  const json found = Json({"calibrations", "lookup", "--porosity", Full(porosity), "--mean-radius",
                           Full(radius), "--k", "2e-13"});
  ASSERT_FALSE(found.is_discarded());
  ASSERT_GE(found["nearest"].size(), 2u) << found.dump(2);
  EXPECT_EQ(found["nearest"][0]["record"]["target_permeability_m2"].get<double>(), 3e-13);
  EXPECT_NEAR(found["nearest"][0]["distance"].get<double>(), std::log(1.5) / 3.0, 1e-9);
  ASSERT_EQ(found["interpolated"], true) << found.dump(2);
  EXPECT_EQ(found["lower"]["target_permeability_m2"].get<double>(), 1e-13);
  EXPECT_EQ(found["upper"]["target_permeability_m2"].get<double>(), 3e-13);
  const double interpolated = found["residual_aperture_m"].get<double>();
  const double t = std::log(2.0) / std::log(3.0);
  EXPECT_NEAR(interpolated / (a0[1e-13] * std::pow(a0[3e-13] / a0[1e-13], t)), 1.0, 1e-12);
  // k ~ a0^3 here, so the interpolation is the calibration's answer: a0(1e-13) 2^(1/3), to the
  // calibration tolerance (each a0 carries at most 1e-6/3 relative).
  EXPECT_NEAR(interpolated / (a0[1e-13] * std::cbrt(2.0)), 1.0, 1e-6);

  // The human form names the interpolation; outside the stored range there is none.
  const CommandResult text = Seep({"calibrations", "lookup", "--porosity", Full(porosity),
                                   "--mean-radius", Full(radius), "--k", "2e-13"});
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("interpolated a0 = "), std::string::npos) << text.output;
  const json outside = Json({"calibrations", "lookup", "--porosity", Full(porosity),
                             "--mean-radius", Full(radius), "--k", "5e-12"});
  EXPECT_FALSE(outside.contains("interpolated")) << outside.dump(2);
  EXPECT_EQ(outside["nearest"][0]["record"]["target_permeability_m2"].get<double>(), 1e-12);
}

TEST_F(CalibrationE2e, BadCalibrationIsRejectedNamingTheFieldAndLeavesNoJob) {
  const std::string bad = (dir_ / "bad.textproto").string();
  std::ofstream(bad) << std::regex_replace(ReadFile(kCalibrationExample), std::regex("3e-13"),
                                           "-3e-13");
  const CommandResult run = Seep({"calibrate", bad});
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("calibration.target_permeabilities_m2[3]: must be a finite number > 0"),
            std::string::npos)
      << run.output;
  const CommandResult list = Seep({"list"});
  EXPECT_EQ(std::count(list.output.begin(), list.output.end(), '\n'), 1) << list.output;

  // Both a scene and a calibration in one request: INVALID_ARGUMENT naming the choice.
  auto stub =
      v1::SeepService::NewStub(grpc::CreateChannel(address_, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  v1::SubmitJobRequest request;
  request.mutable_scene()->set_name("x");
  request.mutable_calibration()->set_name("y");
  v1::SubmitJobResponse response;
  const grpc::Status status = stub->SubmitJob(&ctx, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(status.error_message().rfind("calibration: set either scene", 0), 0u)
      << status.error_message();
}

TEST_F(CalibrationE2e, TakesThePackingOfAnEarlierSimulationJob) {
  // examples/darcy_random_packing.textproto grows the same packing (seed 7) as the sweep.
  const CommandResult simulation = Seep(
      {"submit", std::string(SEEP_EXAMPLES_DIR) + "/darcy_random_packing.textproto", "--watch"});
  ASSERT_EQ(simulation.exit_code, 0) << simulation.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(simulation.output, m, std::regex("submitted job (j-[0-9a-f]+)")));
  const std::string simulation_id = m[1];

  // The sweep without its packing source, two targets, the packing taken from that job.
  const std::string file = (dir_ / "from_job.textproto").string();
  {
    std::ofstream out(file);
    out << R"pb(
      name: "from-job"
      scene {
        packing { contact_gap_m: 2e-5 }
        fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
        aperture { reference_force_n: 10 gap_multiplier: 0.5 }
        boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
      }
      stress { uniform_normal_force_n: 5 }
      target_permeabilities_m2: [ 1e-13, 3e-13 ]
    )pb";
  }
  const CommandResult run = Seep({"calibrate", file, "--from-job", simulation_id, "--watch"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string id = JobIdFrom(run.output);
  const json from_job = Json({"calibrations", "--job", id});
  ASSERT_EQ(from_job["records"].size(), 2u) << from_job.dump(2);

  // The example sweep on the packing it generates itself: the same packing, the same setup hash,
  // the same a0 for the same target.
  const std::string example_id = CalibrateExample();
  const json example =
      Json({"calibrations", "--job", example_id, "--k-min", "1e-13", "--k-max", "1e-13"});
  ASSERT_EQ(example["records"].size(), 1u);
  const json& mine = from_job["records"][1]["target_permeability_m2"].get<double>() == 1e-13
                         ? from_job["records"][1]
                         : from_job["records"][0];
  EXPECT_EQ(mine["packing"]["porosity_2d"], example["records"][0]["packing"]["porosity_2d"]);
  EXPECT_EQ(mine["scene_sha256"], example["records"][0]["scene_sha256"]);
  EXPECT_EQ(mine["residual_aperture_m"], example["records"][0]["residual_aperture_m"]);

  // ListJobs by kind: two calibrations, one simulation.
  auto stub =
      v1::SeepService::NewStub(grpc::CreateChannel(address_, grpc::InsecureChannelCredentials()));
  for (const auto& [kind, count] :
       {std::pair{v1::JOB_KIND_CALIBRATION, 2}, std::pair{v1::JOB_KIND_SIMULATION, 1}}) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::ListJobsRequest request;
    request.add_kinds(kind);
    v1::ListJobsResponse response;
    ASSERT_TRUE(stub->ListJobs(&ctx, request, &response).ok());
    EXPECT_EQ(response.jobs_size(), count) << v1::JobKind_Name(kind);
    for (const auto& job : response.jobs()) EXPECT_EQ(job.kind(), kind);
  }

  // The same through the CLI: `seep list --kind calibration` shows the two calibrations.
  const CommandResult listed = Seep({"list", "--kind", "calibration"});
  ASSERT_EQ(listed.exit_code, 0) << listed.output;
  EXPECT_EQ(std::count(listed.output.begin(), listed.output.end(), '\n'), 3) << listed.output;
  EXPECT_EQ(listed.output.find(simulation_id), std::string::npos) << listed.output;
  EXPECT_EQ(Seep({"list", "--kind", "nonsense"}).exit_code, 3);

  // An unknown earlier job: NOT_FOUND (exit 5) naming the field.
  const CommandResult missing = Seep({"calibrate", file, "--from-job", "j-0000000000000000"});
  EXPECT_EQ(missing.exit_code, 5) << missing.output;
  EXPECT_NE(missing.output.find("calibration.from_job_id:"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace seep::testing
