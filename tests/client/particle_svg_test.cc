// The particle picture from hand-made fields: three disks in a row, two bonds (one broken), one
// triangular domain and a floor; what it draws where, and the fields it refuses.
#include "particle_svg.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "colour_map.h"

namespace seep::client {
namespace {

v1::GetJobFieldsResponse ThreeDisks() {
  v1::GetJobFieldsResponse r;
  r.set_step(12);
  r.set_time_s(0.5);
  v1::JobFields& f = *r.mutable_fields();
  for (const double x : {0.0, 2.0, 4.0}) {
    f.add_particle_x_m(x);
    f.add_particle_y_m(1.0);
    f.add_particle_radius_m(1.0);
  }
  f.add_bond_particle_i(0);
  f.add_bond_particle_j(1);
  f.add_bond_broken(false);
  f.add_bond_particle_i(1);
  f.add_bond_particle_j(2);
  f.add_bond_broken(true);
  // One domain over a wall vertex (id 3 = wall vertex 0), pressures 10 and 30 Pa in two.
  f.add_wall_vertex_x_m(1.0);
  f.add_wall_vertex_y_m(0.0);
  for (const int id : {0, 3, 1, 1, 3, 2}) f.add_domain_loop_particles(id);
  for (const int offset : {0, 3, 6}) f.add_domain_loop_offsets(offset);
  f.add_domain_pressure_pa(10.0);
  f.add_domain_pressure_pa(30.0);
  f.add_wall_x0_m(-1.0);
  f.add_wall_y0_m(0.0);
  f.add_wall_x1_m(5.0);
  f.add_wall_y1_m(0.0);
  return r;
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++n;
  }
  return n;
}

// The content of the element with class="name" (the first one), up to its closing tag.
std::string Element(const std::string& svg, const std::string& name) {
  const std::size_t at = svg.find("class=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const std::size_t start = svg.rfind('<', at);
  const std::size_t end = svg.find(svg[start + 1] == 'g' ? "</g>" : "/>", at);
  return svg.substr(start, end - start);
}

TEST(ParticleSvg, DrawsEveryPartInItsGroupToScale) {
  std::string error;
  const std::string svg = ParticleSvg("j-1", ThreeDisks(), &error);
  ASSERT_TRUE(error.empty()) << error;
  EXPECT_EQ(svg.rfind("<svg ", 0), 0u);
  EXPECT_NE(svg.find("job j-1: step 12, t = 0.5 s"), std::string::npos);
  // The scene is 6 m by 2 m (disks from x = -1 to 5, the floor too): 150 px per metre, the
  // origin at (20, 340) px.
  const std::string particles = Element(svg, "particles");
  EXPECT_EQ(Count(particles, "<circle"), 3);
  EXPECT_NE(particles.find("<circle cx=\"170.00\" cy=\"190.00\" r=\"150.00\"/>"), std::string::npos)
      << particles;
  EXPECT_NE(Element(svg, "bonds-intact").find("d=\"M170.00 190.00L470.00 190.00\""),
            std::string::npos);
  EXPECT_NE(Element(svg, "bonds-broken").find("d=\"M470.00 190.00L770.00 190.00\""),
            std::string::npos);
  EXPECT_NE(
      Element(svg, "walls").find("<line x1=\"20.00\" y1=\"340.00\" x2=\"920.00\" y2=\"340.00\"/>"),
      std::string::npos)
      << Element(svg, "walls");
  // The wall vertex is at (1, 0): the first domain's second corner.
  const std::string domains = Element(svg, "domains");
  EXPECT_NE(domains.find("M170.00 190.00L320.00 340.00L470.00 190.00Z"), std::string::npos)
      << domains;
  // The ends of the colour map at the ends of the pressure range, labelled in Pa.
  EXPECT_NE(domains.find("fill=\"" + ViridisColour(0.0) + "\""), std::string::npos);
  EXPECT_NE(domains.find("fill=\"" + ViridisColour(1.0) + "\""), std::string::npos);
  const std::string bar = Element(svg, "colour-bar");
  EXPECT_NE(bar.find("data-min-pa=\"10\" data-max-pa=\"30\""), std::string::npos) << bar;
  EXPECT_NE(bar.find("class=\"bar-min\""), std::string::npos);
  EXPECT_NE(bar.find(">10 Pa</text>"), std::string::npos);
  EXPECT_NE(bar.find(">20 Pa</text>"), std::string::npos);
  EXPECT_NE(bar.find(">30 Pa</text>"), std::string::npos);
  EXPECT_NE(svg.find("intact bonds (1)"), std::string::npos);
  EXPECT_NE(svg.find("broken bonds (1)"), std::string::npos);
}

TEST(ParticleSvg, DomainsOfOneColourShareOnePathAndNotANumberIsGrey) {
  v1::GetJobFieldsResponse r = ThreeDisks();
  r.mutable_fields()->set_domain_pressure_pa(1, 10.0);       // both at 10 Pa: no range
  r.mutable_fields()->add_domain_pressure_pa(std::nan(""));  // along the three centres
  for (const int id : {0, 1, 2}) r.mutable_fields()->add_domain_loop_particles(id);
  r.mutable_fields()->add_domain_loop_offsets(9);
  std::string error;
  const std::string svg = ParticleSvg("j-1", r, &error);
  ASSERT_TRUE(error.empty()) << error;
  const std::string domains = Element(svg, "domains");
  // The middle of the map (level 128 of 0..255) for both, grey for the pressure that is not a
  // number (and outside the range).
  EXPECT_EQ(Count(domains, "<path"), 2) << domains;
  EXPECT_NE(
      domains.find("<path fill=\"#9e9e9e\" d=\"M170.00 190.00L470.00 190.00L770.00 190.00Z\""),
      std::string::npos)
      << domains;
  EXPECT_NE(domains.find("<path fill=\"" + ViridisColour(128.0 / 255.0) +
                         "\" d=\"M170.00 190.00L320.00 340.00L470.00 190.00ZM470.00"),
            std::string::npos)
      << domains;
  EXPECT_NE(Element(svg, "colour-bar").find("data-min-pa=\"10\" data-max-pa=\"10\""),
            std::string::npos);
}

TEST(ParticleSvg, ViridisEndsAndMiddleAreItsStops) {
  EXPECT_EQ(ViridisColour(0.0), "#440154");
  EXPECT_EQ(ViridisColour(0.5), "#21918c");
  EXPECT_EQ(ViridisColour(1.0), "#fde725");
  EXPECT_EQ(ViridisColour(2.0), "#fde725");
  EXPECT_EQ(ViridisColour(0.05), "#461365");  // halfway between #440154 and #482475
}

TEST(ParticleSvg, WithoutDomainsOrBondsItSaysSoAndDrawsTheRest) {
  v1::GetJobFieldsResponse r = ThreeDisks();
  v1::JobFields& f = *r.mutable_fields();
  f.clear_domain_pressure_pa();
  f.clear_domain_loop_offsets();
  f.clear_domain_loop_particles();
  f.clear_bond_particle_i();
  f.clear_bond_particle_j();
  f.clear_bond_broken();
  std::string error;
  const std::string svg = ParticleSvg("j-1", r, &error);
  ASSERT_TRUE(error.empty()) << error;
  EXPECT_EQ(Count(svg, "<circle"), 4);  // three disks and the legend's sample
  EXPECT_EQ(svg.find("class=\"colour-bar\""), std::string::npos);
  EXPECT_NE(svg.find(">no domains</text>"), std::string::npos);
  EXPECT_EQ(svg.find("bonds-intact"), std::string::npos);
  EXPECT_NE(svg.find("intact bonds (0)"), std::string::npos);
}

TEST(ParticleSvg, FieldsThatDoNotFitTogetherAreRefusedNamingTheField) {
  const auto refused = [](void (*spoil)(v1::JobFields*)) {
    v1::GetJobFieldsResponse r = ThreeDisks();
    spoil(r.mutable_fields());
    std::string error;
    EXPECT_TRUE(ParticleSvg("j-1", r, &error).empty());
    return error;
  };
  EXPECT_EQ(refused([](v1::JobFields* f) { f->set_bond_particle_j(1, 3); }),
            "the fields of job j-1 at step 12 do not fit together: bond_particle_j[1]: 3 is not "
            "a particle (3 particles)");
  EXPECT_EQ(refused([](v1::JobFields* f) { f->add_bond_broken(false); }),
            "the fields of job j-1 at step 12 do not fit together: bond_broken: 3 entries, "
            "expected 2 (as many as bond_particle_i)");
  EXPECT_EQ(refused([](v1::JobFields* f) { f->set_domain_loop_particles(4, 4); }),
            "the fields of job j-1 at step 12 do not fit together: domain_loop_particles[4]: 4 "
            "is neither a particle nor a wall vertex (3 particles, 1 wall vertices)");
  EXPECT_EQ(refused([](v1::JobFields* f) { f->set_domain_loop_offsets(2, 7); }),
            "the fields of job j-1 at step 12 do not fit together: domain_loop_offsets[1..2]: "
            "3..7 is not a range of the 6 loop ids");
  EXPECT_EQ(refused([](v1::JobFields* f) { f->add_wall_y1_m(0.0); }),
            "the fields of job j-1 at step 12 do not fit together: wall_y1_m: 2 entries, "
            "expected 1 (as many as wall_x0_m)");
}

}  // namespace
}  // namespace seep::client
