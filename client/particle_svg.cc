// The particle picture of `seep plot --what particles` (see particle_svg.h).
#include "particle_svg.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "colour_map.h"
#include "plot/svg_chart.h"

namespace seep::client {
namespace {

constexpr double kDrawingPx = 900.0;  // the longer side of the scene
constexpr double kMarginPx = 20.0;
constexpr double kTitlePx = 40.0;
constexpr double kColourBarPx = 150.0;  // the bar, its ticks and labels
constexpr double kLegendPx = 44.0;
constexpr double kMinWidthPx = 700.0;  // the legend's width
constexpr double kBarWidthPx = 18.0;
constexpr double kBarMaxHeightPx = 400.0;

constexpr const char* kIntactColour = "#262626";
constexpr const char* kBrokenColour = "#e41a1c";

// "name: has N entries, expected M (as many as other)", or empty when the sizes agree.
std::string SizeMismatch(const char* name, int size, const char* other, int expected) {
  if (size == expected) return {};
  return fmt::format("{}: {} entries, expected {} (as many as {})", name, size, expected, other);
}

// The first way in which the arrays the picture reads do not fit together, or empty.
std::string CheckFields(const v1::JobFields& f) {
  const int particles = f.particle_x_m_size();
  const int wall_vertices = f.wall_vertex_x_m_size();
  const int domains = f.domain_pressure_pa_size();
  const int bonds = f.bond_particle_i_size();
  const int walls = f.wall_x0_m_size();
  for (const std::string& e : {
           SizeMismatch("particle_y_m", f.particle_y_m_size(), "particle_x_m", particles),
           SizeMismatch("particle_radius_m", f.particle_radius_m_size(), "particle_x_m", particles),
           SizeMismatch("wall_vertex_y_m", f.wall_vertex_y_m_size(), "wall_vertex_x_m",
                        wall_vertices),
           // No domains may come with no offsets or with the one offset 0.
           SizeMismatch("domain_loop_offsets", f.domain_loop_offsets_size(),
                        "domain_pressure_pa plus one",
                        domains == 0 && f.domain_loop_offsets_size() == 0 ? 0 : domains + 1),
           SizeMismatch("bond_particle_j", f.bond_particle_j_size(), "bond_particle_i", bonds),
           SizeMismatch("bond_broken", f.bond_broken_size(), "bond_particle_i", bonds),
           SizeMismatch("wall_y0_m", f.wall_y0_m_size(), "wall_x0_m", walls),
           SizeMismatch("wall_x1_m", f.wall_x1_m_size(), "wall_x0_m", walls),
           SizeMismatch("wall_y1_m", f.wall_y1_m_size(), "wall_x0_m", walls),
       }) {
    if (!e.empty()) return e;
  }
  const int loop_ids = f.domain_loop_particles_size();
  for (int d = 0; d < domains; ++d) {
    const int begin = f.domain_loop_offsets(d);
    const int end = f.domain_loop_offsets(d + 1);
    if (begin < 0 || end < begin || end > loop_ids) {
      return fmt::format("domain_loop_offsets[{}..{}]: {}..{} is not a range of the {} loop ids", d,
                         d + 1, begin, end, loop_ids);
    }
  }
  for (int k = 0; k < loop_ids; ++k) {
    const int id = f.domain_loop_particles(k);
    if (id < 0 || id >= particles + wall_vertices) {
      return fmt::format(
          "domain_loop_particles[{}]: {} is neither a particle nor a wall vertex ({} particles, "
          "{} wall vertices)",
          k, id, particles, wall_vertices);
    }
  }
  for (int b = 0; b < bonds; ++b) {
    for (const auto& [name, id] : {std::pair{"bond_particle_i", f.bond_particle_i(b)},
                                   std::pair{"bond_particle_j", f.bond_particle_j(b)}}) {
      if (id < 0 || id >= particles) {
        return fmt::format("{}[{}]: {} is not a particle ({} particles)", name, b, id, particles);
      }
    }
  }
  return {};
}

// Scene metres to picture pixels: the scene's extent (disks and walls) scaled so that its longer
// side is kDrawingPx, y pointing up.
class Frame {
 public:
  explicit Frame(const v1::JobFields& f) {
    const auto add = [this](double x, double y, double r) {
      x_min_ = std::min(x_min_, x - r);
      x_max_ = std::max(x_max_, x + r);
      y_min_ = std::min(y_min_, y - r);
      y_max_ = std::max(y_max_, y + r);
    };
    for (int k = 0; k < f.particle_x_m_size(); ++k) {
      add(f.particle_x_m(k), f.particle_y_m(k), f.particle_radius_m(k));
    }
    for (int w = 0; w < f.wall_x0_m_size(); ++w) {
      add(f.wall_x0_m(w), f.wall_y0_m(w), 0.0);
      add(f.wall_x1_m(w), f.wall_y1_m(w), 0.0);
    }
    if (!(x_min_ < x_max_)) {
      x_min_ = std::isfinite(x_min_) ? x_min_ - 0.5 : 0.0;
      x_max_ = x_min_ + 1.0;
    }
    if (!(y_min_ < y_max_)) {
      y_min_ = std::isfinite(y_min_) ? y_min_ - 0.5 : 0.0;
      y_max_ = y_min_ + 1.0;
    }
    scale_ = kDrawingPx / std::max(x_max_ - x_min_, y_max_ - y_min_);
  }

  double X(double x) const { return kMarginPx + (x - x_min_) * scale_; }
  double Y(double y) const { return kTitlePx + (y_max_ - y) * scale_; }
  double Length(double metres) const { return metres * scale_; }
  double width() const { return Length(x_max_ - x_min_); }
  double height() const { return Length(y_max_ - y_min_); }

 private:
  double x_min_ = std::numeric_limits<double>::infinity();
  double x_max_ = -std::numeric_limits<double>::infinity();
  double y_min_ = std::numeric_limits<double>::infinity();
  double y_max_ = -std::numeric_limits<double>::infinity();
  double scale_ = 1.0;
};

// The finite domain pressures' range; lo > hi when there is none.
struct PressureRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool empty() const { return !(lo <= hi); }
  double Fraction(double p) const { return hi > lo ? (p - lo) / (hi - lo) : 0.5; }
};

PressureRange RangeOf(const v1::JobFields& f) {
  PressureRange range;
  for (const double p : f.domain_pressure_pa()) {
    if (!std::isfinite(p)) continue;
    range.lo = std::min(range.lo, p);
    range.hi = std::max(range.hi, p);
  }
  return range;
}

// Loop id k: particle k below the particle count, else wall vertex k - count.
void VertexPosition(const v1::JobFields& f, int id, double* x, double* y) {
  const int particles = f.particle_x_m_size();
  *x = id < particles ? f.particle_x_m(id) : f.wall_vertex_x_m(id - particles);
  *y = id < particles ? f.particle_y_m(id) : f.wall_vertex_y_m(id - particles);
}

// One path per colour: the pressures quantised to kColourLevels levels of the map (finer than
// the eye tells apart), each domain a closed subpath of the path of its level, and one grey path
// for pressures that are not numbers (visible, and in no colour of the map). Sharing the fill
// keeps a 10k-disk picture's twenty thousand domains to a few hundred elements.
void DrawDomains(const v1::JobFields& f, const Frame& frame, const PressureRange& range,
                 std::string* svg) {
  constexpr int kColourLevels = 256;
  std::vector<std::string> paths(kColourLevels + 1);  // the last one: not a number
  for (int d = 0; d < f.domain_pressure_pa_size(); ++d) {
    const double p = f.domain_pressure_pa(d);
    const int level = std::isfinite(p)
                          ? static_cast<int>(std::lround(range.Fraction(p) * (kColourLevels - 1)))
                          : kColourLevels;
    std::string& path = paths[static_cast<std::size_t>(level)];
    for (int k = f.domain_loop_offsets(d); k < f.domain_loop_offsets(d + 1); ++k) {
      double x = 0.0;
      double y = 0.0;
      VertexPosition(f, f.domain_loop_particles(k), &x, &y);
      path += fmt::format("{}{:.2f} {:.2f}", k == f.domain_loop_offsets(d) ? "M" : "L", frame.X(x),
                          frame.Y(y));
    }
    if (f.domain_loop_offsets(d + 1) > f.domain_loop_offsets(d)) path += 'Z';
  }
  *svg += "<g class=\"domains\" stroke=\"none\">\n";
  for (int level = 0; level <= kColourLevels; ++level) {
    const std::string& path = paths[static_cast<std::size_t>(level)];
    if (path.empty()) continue;
    const std::string colour =
        level < kColourLevels ? ViridisColour(level / double{kColourLevels - 1}) : "#9e9e9e";
    *svg += fmt::format("<path fill=\"{}\" d=\"{}\"/>\n", colour, path);
  }
  *svg += "</g>\n";
}

void DrawParticles(const v1::JobFields& f, const Frame& frame, std::string* svg) {
  *svg +=
      "<g class=\"particles\" fill=\"#ffffff\" fill-opacity=\"0.55\" stroke=\"#4d4d4d\" "
      "stroke-width=\"0.5\">\n";
  for (int k = 0; k < f.particle_x_m_size(); ++k) {
    *svg += fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.2f}\"/>\n",
                        frame.X(f.particle_x_m(k)), frame.Y(f.particle_y_m(k)),
                        frame.Length(f.particle_radius_m(k)));
  }
  *svg += "</g>\n";
}

// One path per bond state, a subpath from centre to centre per bond; returns the bonds drawn.
int DrawBonds(const v1::JobFields& f, const Frame& frame, bool broken, std::string* svg) {
  std::string path;
  int count = 0;
  for (int b = 0; b < f.bond_particle_i_size(); ++b) {
    if (f.bond_broken(b) != broken) continue;
    const int i = f.bond_particle_i(b);
    const int j = f.bond_particle_j(b);
    path += fmt::format("M{:.2f} {:.2f}L{:.2f} {:.2f}", frame.X(f.particle_x_m(i)),
                        frame.Y(f.particle_y_m(i)), frame.X(f.particle_x_m(j)),
                        frame.Y(f.particle_y_m(j)));
    ++count;
  }
  if (count > 0) {
    *svg += fmt::format(
        "<path class=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" "
        "stroke-linecap=\"round\" d=\"{}\"/>\n",
        broken ? "bonds-broken" : "bonds-intact", broken ? kBrokenColour : kIntactColour,
        broken ? "1.8" : "0.7", path);
  }
  return count;
}

void DrawWalls(const v1::JobFields& f, const Frame& frame, std::string* svg) {
  *svg += "<g class=\"walls\" stroke=\"#000000\" stroke-width=\"3\" stroke-linecap=\"square\">\n";
  for (int w = 0; w < f.wall_x0_m_size(); ++w) {
    *svg += fmt::format("<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\"/>\n",
                        frame.X(f.wall_x0_m(w)), frame.Y(f.wall_y0_m(w)), frame.X(f.wall_x1_m(w)),
                        frame.Y(f.wall_y1_m(w)));
  }
  *svg += "</g>\n";
}

// The bar (high at the top) with five labelled ticks, right of the drawing.
void DrawColourBar(const PressureRange& range, const Frame& frame, std::string* svg) {
  const double left = kMarginPx + frame.width() + 30.0;
  const double top = kTitlePx + 20.0;
  if (range.empty()) {
    *svg += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\">no domains</text>\n",
                        left, top);
    return;
  }
  const double height = std::min(frame.height() - 20.0, kBarMaxHeightPx);
  *svg += fmt::format("<g class=\"colour-bar\" data-min-pa=\"{}\" data-max-pa=\"{}\">\n", range.lo,
                      range.hi);
  *svg += "<defs><linearGradient id=\"viridis\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">";
  for (std::size_t k = 0; k < kViridisStops.size(); ++k) {
    *svg += fmt::format("<stop offset=\"{:.1f}\" stop-color=\"{}\"/>",
                        static_cast<double>(k) / static_cast<double>(kViridisStops.size() - 1),
                        kViridisStops[k]);
  }
  *svg += "</linearGradient></defs>\n";
  *svg += fmt::format(
      "<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\">domain pressure</text>\n"
      "<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" fill=\"url(#viridis)\" "
      "stroke=\"#444444\"/>\n",
      left, top - 14.0, left, top, kBarWidthPx, height);
  for (int k = 0; k <= 4; ++k) {
    const double fraction = k / 4.0;
    const double value = k == 4 ? range.hi : range.lo + fraction * (range.hi - range.lo);
    const double y = top + height * (1.0 - fraction);
    *svg += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"#444444\"/>\n"
        "<text class=\"{3}\" x=\"{4:.2f}\" y=\"{5:.2f}\" font-size=\"12\">{6:.4g} Pa</text>\n",
        left + kBarWidthPx, y, left + kBarWidthPx + 5.0,
        k == 0 ? "bar-min" : (k == 4 ? "bar-max" : "bar-tick"), left + kBarWidthPx + 8.0, y + 4.0,
        value);
  }
  *svg += "</g>\n";
}

// Samples of the four styles with their counts, under the drawing.
void DrawLegend(const v1::JobFields& f, int intact, int broken, const Frame& frame,
                std::string* svg) {
  const double y = kTitlePx + frame.height() + 28.0;
  double x = kMarginPx + 10.0;
  *svg += fmt::format(
      "<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"6\" fill=\"#ffffff\" stroke=\"#4d4d4d\"/>\n"
      "<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\">particles ({})</text>\n",
      x, y, x + 12.0, y + 4.0, f.particle_x_m_size());
  x += 150.0;
  const auto line_sample = [&](const char* colour, const char* width, const std::string& label) {
    *svg += fmt::format(
        "<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"{}\" "
        "stroke-width=\"{}\"/>\n"
        "<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\">{}</text>\n",
        x - 6.0, y, x + 18.0, y, colour, width, x + 24.0, y + 4.0, label);
    x += 170.0;
  };
  line_sample(kIntactColour, "0.7", fmt::format("intact bonds ({})", intact));
  line_sample(kBrokenColour, "1.8", fmt::format("broken bonds ({})", broken));
  line_sample("#000000", "3", fmt::format("walls ({})", f.wall_x0_m_size()));
}

}  // namespace

std::string ParticleSvg(const std::string& job_id, const v1::GetJobFieldsResponse& response,
                        std::string* error) {
  const v1::JobFields& f = response.fields();
  if (std::string why = CheckFields(f); !why.empty()) {
    *error = fmt::format("the fields of job {} at step {} do not fit together: {}", job_id,
                         response.step(), why);
    return {};
  }
  const Frame frame(f);
  const PressureRange range = RangeOf(f);
  const double width = std::max(kMarginPx + frame.width() + kColourBarPx, kMinWidthPx);
  const double height = kTitlePx + frame.height() + kLegendPx;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0:.0f}\" height=\"{1:.0f}\" "
      "viewBox=\"0 0 {0:.0f} {1:.0f}\" font-family=\"sans-serif\">\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      "<text x=\"{2:.2f}\" y=\"24\" font-size=\"14\" font-weight=\"bold\">job {3}: step {4}, "
      "t = {5:.6g} s</text>\n",
      width, height, kMarginPx, plot::EscapeXml(job_id), response.step(), response.time_s());
  DrawDomains(f, frame, range, &svg);
  DrawParticles(f, frame, &svg);
  const int intact = DrawBonds(f, frame, /*broken=*/false, &svg);
  const int broken = DrawBonds(f, frame, /*broken=*/true, &svg);
  DrawWalls(f, frame, &svg);
  DrawColourBar(range, frame, &svg);
  DrawLegend(f, intact, broken, frame, &svg);
  svg += "</svg>\n";
  return svg;
}

}  // namespace seep::client
