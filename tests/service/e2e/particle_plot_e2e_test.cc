// `seep plot --what particles` through the real seepd and seep binaries: a small hydraulic
// fracturing scene (examples/hydraulic_fracturing.textproto on a 16 x 18 lattice, for 0.06 s) is
// run to completion with a checkpoint every 800 steps, and its pictures at the end and at the first
// checkpoint are parsed back with python's XML parser. Each count in the picture is held against
// a number that does not come from the picture's code: the particles against the result's
// particle_count and the exported particles CSV, the broken bonds against the result's
// bonds_broken, the colour bar's range against the exported domain pressures (the same step's
// CSV), and the walls against the particles they must enclose. Also the errors: a bad --what
// value and a step without a checkpoint.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "process.h"
#include "seepd_fixture.h"

namespace seep::testing {
namespace {

// Prints what the picture holds, one "key value..." line each.
const char* const kPictureCheck = R"(
import sys, xml.etree.ElementTree as ET
ns = '{http://www.w3.org/2000/svg}'
root = ET.parse(sys.argv[1]).getroot()
def of_class(name):
    return [e for e in root.iter() if e.get('class') == name]
print('circles', sum(len(g.findall(ns + 'circle')) for g in of_class('particles')))
for name in ('bonds-intact', 'bonds-broken'):
    print(name, sum(p.get('d').count('M') for p in of_class(name)))
for g in of_class('walls'):
    for l in g.findall(ns + 'line'):
        print('wall', l.get('x1'), l.get('y1'), l.get('x2'), l.get('y2'))
for g in of_class('particles'):
    for c in g.findall(ns + 'circle'):
        print('centre', c.get('cx'), c.get('cy'))
for g in of_class('colour-bar'):
    print('range', g.get('data-min-pa'), g.get('data-max-pa'))
for name in ('bar-min', 'bar-max'):
    for t in of_class(name):
        print(name, t.text)
)";

// What kPictureCheck printed.
struct Picture {
  int circles = -1;
  int intact = -1;
  int broken = -1;
  std::vector<std::vector<double>> walls;  // x1 y1 x2 y2, pixels
  std::vector<std::pair<double, double>> centres;
  double min_pa = std::numeric_limits<double>::quiet_NaN();
  double max_pa = std::numeric_limits<double>::quiet_NaN();
  std::string min_label, max_label;
};

Picture ReadPicture(const std::string& svg_path) {
  const CommandResult r = RunCommand({kPython, "-c", kPictureCheck, svg_path});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  Picture p;
  std::istringstream lines(r.output);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string key;
    in >> key;
    if (key == "circles") in >> p.circles;
    if (key == "bonds-intact") in >> p.intact;
    if (key == "bonds-broken") in >> p.broken;
    if (key == "wall") {
      std::vector<double> w(4);
      in >> w[0] >> w[1] >> w[2] >> w[3];
      p.walls.push_back(w);
    }
    if (key == "centre") {
      double x = 0.0, y = 0.0;
      in >> x >> y;
      p.centres.emplace_back(x, y);
    }
    if (key == "range") in >> p.min_pa >> p.max_pa;
    if (key == "bar-min") p.min_label = line.substr(key.size() + 1);
    if (key == "bar-max") p.max_label = line.substr(key.size() + 1);
  }
  return p;
}

// One column of a CSV file with a header.
std::vector<double> CsvColumn(const std::filesystem::path& path, const std::string& name) {
  std::istringstream in(ReadFile(path));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream head(line);
  for (std::string cell; std::getline(head, cell, ',');) header.push_back(cell);
  const auto column = std::find(header.begin(), header.end(), name) - header.begin();
  std::vector<double> values;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::ptrdiff_t c = 0; c <= column && std::getline(row, cell, ','); ++c) {
    }
    values.push_back(std::stod(cell));
  }
  return values;
}

std::string PaLabel(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.4g Pa", value);
  return text;
}

class ParticlePlotE2e : public SeepdFixture {
 protected:
  std::vector<std::string> ExtraSeepdFlags() const override {
    return {"--workers", "1", "--checkpoint-every-steps", "800", "--checkpoints-kept", "100"};
  }

  // The fracturing example on a 16 x 18 lattice run twice as long: breakdown, the fracture, and
  // then long enough for the opening fracture to move particles past half the Verlet skin, so
  // that the DEM rebuilds its neighbour list and drops the broken bonds from its table (a seepd
  // that reported only the bonds still in the table drew no broken bond at the end of this run,
  // though 28 broke). In seconds.
  std::string RunSmallFracture() {
    std::string scene = ReadFile(Example("hydraulic_fracturing.textproto"));
    scene = std::regex_replace(scene, std::regex("columns: 24 rows: 28"), "columns: 16 rows: 18");
    scene = std::regex_replace(scene, std::regex("end_time_s: 0.03"), "end_time_s: 0.06");
    scene = std::regex_replace(scene, std::regex("name: \"hydraulic-fracturing\""),
                               "name: \"small-fracture\"");
    const CommandResult run = Seep({"submit", Write("small.textproto", scene), "--watch"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return JobIdFrom(run.output);
  }

  // The exported CSVs of one step (0 = the newest) into dir_/name.
  std::filesystem::path ExportCsv(const std::string& id, std::uint64_t step,
                                  const std::string& name) {
    std::vector<std::string> args = {"export",   id,   "--out", (dir_ / name).string(),
                                     "--format", "csv"};
    if (step > 0) args.insert(args.end(), {"--step", std::to_string(step)});
    const CommandResult r = Seep(args);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return dir_ / name;
  }

  // The colour bar's range is the exported pressures' range, exactly and as labelled.
  static void ExpectBarRange(const Picture& p, const std::vector<double>& pressures) {
    ASSERT_FALSE(pressures.empty());
    const auto [lo, hi] = std::minmax_element(pressures.begin(), pressures.end());
    EXPECT_EQ(p.min_pa, *lo);
    EXPECT_EQ(p.max_pa, *hi);
    EXPECT_EQ(p.min_label, PaLabel(*lo));
    EXPECT_EQ(p.max_label, PaLabel(*hi));
  }
};

TEST_F(ParticlePlotE2e, PictureCountsMatchTheResultAndTheExportedFields) {
  const std::string id = RunSmallFracture();
  ASSERT_FALSE(id.empty());
  const nlohmann::json result = Json({"result", id});
  const nlohmann::json& metrics = result["result"]["metrics"];
  const auto particles = metrics["particle_count"].get<double>();
  const auto bonds_broken = metrics["bonds_broken"].get<double>();
  ASSERT_GT(bonds_broken, 0.0) << "the small sample did not break down: " << result.dump();

  const std::string final_svg = (dir_ / "final.svg").string();
  CommandResult r = Seep({"plot", id, "--what", "particles", "-o", final_svg});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("wrote " + final_svg), std::string::npos) << r.output;
  EXPECT_LT(std::filesystem::file_size(final_svg), 2u << 20);
  const Picture last = ReadPicture(final_svg);
  EXPECT_EQ(last.circles, static_cast<int>(particles));
  EXPECT_EQ(last.broken, static_cast<int>(bonds_broken));
  EXPECT_GT(last.intact, last.broken);  // the fracture is a line through an intact sample

  const std::filesystem::path csv = ExportCsv(id, 0, "final");
  const nlohmann::json fields = Json({"export", id, "--out", (dir_ / "steps").string()});
  const auto final_step = fields["steps"][0].get<std::uint64_t>();
  EXPECT_EQ(CsvColumn(csv / ("particles_" + std::to_string(final_step) + ".csv"), "x_m").size(),
            static_cast<std::size_t>(particles));
  ExpectBarRange(
      last, CsvColumn(csv / ("domains_" + std::to_string(final_step) + ".csv"), "pressure_pa"));
  EXPECT_GT(last.max_pa, last.min_pa);

  // Four walls closing a box: every wall end is another wall's end, and every centre is inside.
  ASSERT_EQ(last.walls.size(), 4u);
  double x_lo = HUGE_VAL, x_hi = -HUGE_VAL, y_lo = HUGE_VAL, y_hi = -HUGE_VAL;
  for (const auto& w : last.walls) {
    for (int e = 0; e < 2; ++e) {
      const double x = w[2 * e], y = w[2 * e + 1];
      x_lo = std::min(x_lo, x);
      x_hi = std::max(x_hi, x);
      y_lo = std::min(y_lo, y);
      y_hi = std::max(y_hi, y);
      int shared = 0;
      for (const auto& other : last.walls) {
        if (&other == &w) continue;
        for (int f = 0; f < 2; ++f) {
          if (std::hypot(other[2 * f] - x, other[2 * f + 1] - y) < 0.02) ++shared;
        }
      }
      EXPECT_EQ(shared, 1) << "wall end " << x << " " << y;
    }
  }
  ASSERT_EQ(last.centres.size(), static_cast<std::size_t>(particles));
  for (const auto& [x, y] : last.centres) {
    EXPECT_TRUE(x > x_lo && x < x_hi && y > y_lo && y < y_hi) << x << " " << y;
  }

  // The first checkpoint, before the breakdown: every bond of the set-up intact, the same bonds
  // as at the end (broken ones are no longer in the DEM's table there, yet still drawn).
  const std::uint64_t first_step = 800;  // --checkpoint-every-steps
  ASSERT_GT(final_step, first_step);
  const std::string first_svg = (dir_ / "first.svg").string();
  r = Seep({"plot", id, "--what", "particles", "--step", std::to_string(first_step), "--out",
            first_svg});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Picture first = ReadPicture(first_svg);
  EXPECT_EQ(first.circles, static_cast<int>(particles));
  EXPECT_EQ(first.broken, 0);
  EXPECT_EQ(first.intact, last.intact + last.broken);
  EXPECT_EQ(first.walls.size(), 4u);
  const std::filesystem::path first_csv = ExportCsv(id, first_step, "first");
  ExpectBarRange(first, CsvColumn(first_csv / ("domains_" + std::to_string(first_step) + ".csv"),
                                  "pressure_pa"));
}

TEST_F(ParticlePlotE2e, ABadWhatOrAStepWithoutCheckpointIsAClearError) {
  const std::string id = RunSmallFracture();
  ASSERT_FALSE(id.empty());
  CommandResult r = Seep({"plot", id, "--what", "particle", "-o", (dir_ / "x.svg").string()});
  EXPECT_EQ(r.exit_code, 64) << r.output;
  EXPECT_NE(r.output.find("--what"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("particles"), std::string::npos) << r.output;  // names the choices
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.svg"));

  r = Seep({"plot", id, "--what", "particles", "--step", "801", "-o", (dir_ / "y.svg").string()});
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("no checkpoint at step 801; available steps: 800, 1600"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "y.svg"));
}

}  // namespace
}  // namespace seep::testing
