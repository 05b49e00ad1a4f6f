// `seep export` and `seep plot` through the real seepd and seep binaries: the 1D transient example
// (examples/transient_1d.textproto: a 41 x 4 square lattice, 164 particles, 40 x 3 = 120 domains,
// 39 x 3 + 40 x 2 interior pipes and 3 + 3 reservoir pipes = 203) is run with a checkpoint every
// 500 steps, then exported as VTK (loaded back with VTK's own readers from python3-vtk9) and CSV
// (its pressures against the analytic series), at one and at every checkpoint, and plotted as
// SVG (parsed back with python's XML parser). Also the errors: unknown job, unknown step, unknown
// series column.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "process.h"
#include "seepd_fixture.h"

namespace seep::testing {
namespace {

using nlohmann::json;

const std::string kTransientExample = std::string(SEEP_EXAMPLES_DIR) + "/transient_1d.textproto";
constexpr std::size_t kParticles = 164;
constexpr std::size_t kDomains = 120;
constexpr std::size_t kPipes = 203;
// CSV rows as maps keyed by the header.
std::vector<std::map<std::string, double>> ReadCsv(const std::filesystem::path& path) {
  std::istringstream in(ReadFile(path));
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, double>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream cell_stream(line);
    std::string cell;
    while (std::getline(cell_stream, cell, ',')) cells.push_back(cell);
    if (header.empty()) {
      header = cells;
      continue;
    }
    std::map<std::string, double> row;
    for (std::size_t i = 0; i < cells.size() && i < header.size(); ++i) {
      row[header[i]] = std::stod(cells[i]);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

// Loads VTK files with VTK's XML readers; prints "<file> points=P cells=C arrays=a,b" per file,
// exits 1 if a reader reports an error.
const char* const kVtkCheck = R"(
import sys, vtk
class Errors:
    count = 0
def on_error(obj, event):
    Errors.count += 1
for path in sys.argv[1:]:
    reader = vtk.vtkXMLUnstructuredGridReader() if path.endswith('.vtu') else vtk.vtkXMLPolyDataReader()
    reader.AddObserver('ErrorEvent', on_error)
    reader.SetFileName(path)
    reader.Update()
    data = reader.GetOutput()
    arrays = [data.GetCellData().GetArrayName(i) for i in range(data.GetCellData().GetNumberOfArrays())]
    arrays += [data.GetPointData().GetArrayName(i) for i in range(data.GetPointData().GetNumberOfArrays())]
    print('%s points=%d cells=%d arrays=%s' % (path.split('/')[-1], data.GetNumberOfPoints(), data.GetNumberOfCells(), ','.join(arrays)))
sys.exit(1 if Errors.count else 0)
)";

// Parses an SVG with python's XML parser; prints the data-label of every series polyline.
const char* const kSvgCheck = R"(
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
for p in root.iter('{http://www.w3.org/2000/svg}polyline'):
    if p.get('class') == 'series':
        print('series %s points=%d' % (p.get('data-label'), len(p.get('points').split())))
)";

class ExportE2e : public SeepdFixture {
 protected:
  std::vector<std::string> ExtraSeepdFlags() const override {
    return {"--workers", "1", "--checkpoint-every-steps", "500", "--checkpoints-kept", "10"};
  }

  std::string RunExample() {
    const CommandResult run = Seep({"submit", kTransientExample, "--watch"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    std::smatch m;
    if (std::regex_search(run.output, m, std::regex("submitted job (j-[0-9a-f]+)"))) return m[1];
    ADD_FAILURE() << "no job id in: " << run.output;
    return {};
  }
};

TEST_F(ExportE2e, ExportWritesVtkAndCsvThatLoadBack) {
  const std::string id = RunExample();
  ASSERT_FALSE(id.empty());

  // The final state as VTK, with the job's series.
  const std::filesystem::path vtk_dir = dir_ / "vtk";
  CommandResult r = Seep({"export", id, "--out", vtk_dir.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json listed = json::parse(r.output, nullptr, false);
  ASSERT_FALSE(listed.is_discarded()) << r.output;
  ASSERT_EQ(listed["steps"].size(), 1u);
  const auto final_step = listed["steps"][0].get<std::uint64_t>();
  EXPECT_GT(final_step, 1000u);  // about 1500 explicit steps
  const std::string suffix = std::to_string(final_step);
  const std::filesystem::path particles = vtk_dir / ("particles_" + suffix + ".vtp");
  const std::filesystem::path domains = vtk_dir / ("domains_" + suffix + ".vtu");
  const std::filesystem::path pipes = vtk_dir / ("pipes_" + suffix + ".vtp");
  for (const auto& p : {particles, domains, pipes, vtk_dir / "series.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(p)) << p;
  }
  EXPECT_EQ(listed["files"].size(), 4u);
  const auto series = ReadCsv(vtk_dir / "series.csv");
  ASSERT_GT(series.size(), 2u);
  EXPECT_EQ(series.front().count("time_s"), 1u);
  EXPECT_NEAR(series.back().at("time_s"), 3.1484e-3, 1e-12);

  // VTK's own readers load them without error, with the counts of the lattice.
  r = RunCommand({kPython, "-c", kVtkCheck, particles.string(), domains.string(), pipes.string()});
  ASSERT_EQ(r.exit_code, 0) << "python3-vtk9 installed? " << r.output;
  EXPECT_NE(r.output.find("particles_" + suffix + ".vtp points=164 cells=164 arrays=radius_m"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("domains_" + suffix +
                          ".vtu points=164 cells=120 arrays=pressure_pa,apparent_volume_m2,"
                          "pore_volume_m2,analytic_pressure_pa,axis_coordinate_m"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("pipes_" + suffix + ".vtp points=406 cells=203 arrays=flow_m2_per_s"),
            std::string::npos)
      << r.output;

  // The same state as CSV: the pressures follow the series of docs/physics.md §3.2 at T = 0.2. The
  // explicit chain of 40 cells at 0.9 dt_crit measures 7.3e-5 of the drop; 1e-3 leaves room for
  // another build's round-off, while a wrong time or axis origin would be off by 1e-2 or more.
  const std::filesystem::path csv_dir = dir_ / "csv";
  r = Seep({"export", id, "--out", csv_dir.string(), "--format", "csv"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadCsv(csv_dir / ("particles_" + suffix + ".csv")).size(), kParticles);
  EXPECT_EQ(ReadCsv(csv_dir / ("pipes_" + suffix + ".csv")).size(), kPipes);
  const auto domain_rows = ReadCsv(csv_dir / ("domains_" + suffix + ".csv"));
  ASSERT_EQ(domain_rows.size(), kDomains);
  double worst = 0.0;
  for (const auto& row : domain_rows) {
    worst = std::max(worst, std::abs(row.at("pressure_pa") - row.at("analytic_pressure_pa")) / 1e5);
  }
  std::printf("export: max |P - P_series| / p1 over the domains at T = 0.2: %.3e\n", worst);
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(worst, 0.0);

  // Every checkpoint: every 500 steps and the end, in ascending order.
  std::string expected_steps;
  json expected_list = json::array();
  for (std::uint64_t s = 500; s < final_step; s += 500) {
    expected_steps += std::to_string(s) + ", ";
    expected_list.push_back(s);
  }
  expected_steps += suffix;
  expected_list.push_back(final_step);
  r = Seep({"export", id, "--out", (dir_ / "all").string(), "--all-steps", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json all = json::parse(r.output, nullptr, false);
  ASSERT_FALSE(all.is_discarded()) << r.output;
  EXPECT_EQ(all["steps"], expected_list) << r.output;
  EXPECT_EQ(all["files"].size(), 3 * expected_list.size() + 1) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "all" / "domains_500.vtu"));

  // One chosen checkpoint; an unknown one names the available steps; an unknown job.
  r = Seep({"export", id, "--out", (dir_ / "one").string(), "--step", "1000"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "one" / "pipes_1000.vtp"));
  r = Seep({"export", id, "--out", (dir_ / "bad").string(), "--step", "401"});
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("available steps: " + expected_steps), std::string::npos) << r.output;
  r = Seep({"export", "j-0000000000000000", "--out", (dir_ / "none").string()});
  EXPECT_EQ(r.exit_code, 5) << r.output;
}

TEST_F(ExportE2e, PlotWritesParseableSvgWithTheAnalyticCurve) {
  const std::string id = RunExample();
  ASSERT_FALSE(id.empty());

  const std::string profile = (dir_ / "profile.svg").string();
  CommandResult r = Seep({"plot", id, "--out", profile});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunCommand({kPython, "-c", kSvgCheck, profile});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The analytic series through all 120 domains.
  EXPECT_NE(r.output.find("series analytic (linear_transient) points=120"), std::string::npos)
      << r.output;

  const std::string series = (dir_ / "series.svg").string();
  r = Seep({"plot", id, "--out", series, "--what", "series", "--column", "outflow_m2_per_s",
            "--column", "inflow_m2_per_s"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunCommand({kPython, "-c", kSvgCheck, series});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("series outflow_m2_per_s points="), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("series inflow_m2_per_s points="), std::string::npos) << r.output;

  r = Seep({"plot", id, "--out", series, "--what", "series", "--column", "no_such_column"});
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("time_s"), std::string::npos) << r.output;  // lists the columns
}

// With the one worker busy on a long run, a queued job has no checkpoint: FAILED_PRECONDITION (9)
// saying so, for export and plot alike.
TEST_F(ExportE2e, AJobWithoutCheckpointIsAFailedPrecondition) {
  std::string scene = ReadFile(kTransientExample);
  scene = std::regex_replace(scene, std::regex("end_time_s: 3.1484e-3"), "end_time_s: 30");
  const std::filesystem::path long_scene = dir_ / "long.textproto";
  std::ofstream(long_scene) << scene;
  CommandResult r = Seep({"submit", long_scene.string(), "--name", "long"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.output, m, std::regex("submitted job (j-[0-9a-f]+)")));
  const std::string long_id = m[1];
  r = Seep({"submit", kTransientExample, "--name", "queued"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(std::regex_search(r.output, m, std::regex("submitted job (j-[0-9a-f]+)")));
  const std::string queued_id = m[1];

  r = Seep({"export", queued_id, "--out", (dir_ / "none").string()});
  EXPECT_EQ(r.exit_code, 9) << r.output;
  EXPECT_NE(r.output.find("has no checkpoint yet"), std::string::npos) << r.output;
  r = Seep({"plot", queued_id, "--out", (dir_ / "none.svg").string()});
  EXPECT_EQ(r.exit_code, 9) << r.output;
  // The queued job first: once the long one stops, the worker would take it and finish it.
  EXPECT_EQ(Seep({"cancel", queued_id}).exit_code, 0);
  EXPECT_EQ(Seep({"cancel", long_id}).exit_code, 0);
}

}  // namespace
}  // namespace seep::testing
