// The validation of boundary regions (core/src/spec/boundary_region_validation.cc): each bad
// shape, name and condition named by its field; every pair of shape kinds refused when they
// overlap with different conditions and accepted when apart (circles tested exactly, so a circle
// beside a box's corner is apart); overlap with the same condition accepted, unless a stage sets
// the two apart.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "scene_test_util.h"

namespace seep::core {
namespace {

using scene_test::kRadius;

// A 20 x 10 square lattice, 0.04 m x 0.02 m, with no region yet.
SceneSpec Base() { return scene_test::LatticeScene(LatticeKind::kSquare, 20, 10, FlowAxis::kX); }

BoundaryRegionSpec MakeRegion(std::string name, RegionShape shape, RegionCondition condition) {
  return BoundaryRegionSpec{std::move(name), std::move(shape), condition};
}

// A valid pair to break one field of: a box on the left, a circle on the right.
SceneSpec TwoRegions() {
  SceneSpec s = Base();
  s.boundary.regions = {MakeRegion("a", BoxShape{0.0, 0.0, 0.005, 0.02}, FixedPressure{1e5}),
                        MakeRegion("b", CircleShape{0.03, 0.01, 0.004}, FixedFlux{-1e-7})};
  return s;
}

// Stages need a transient solver; one step each.
SceneSpec WithStages(SceneSpec s, std::size_t count) {
  s.solver.kind = SolverKind::kImplicit;
  s.solver.dt_factor = 10.0;
  for (std::size_t k = 0; k < count; ++k) {
    StageSpec stage;
    stage.end = {StepsEnd{1}};
    s.stages.push_back(stage);
  }
  return s;
}

struct Case {
  const char* label;
  std::function<void(SceneSpec&)> change;
  const char* message;  // the start of the expected message
};

void ExpectRefused(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    SceneSpec s = TwoRegions();
    c.change(s);
    const Status status = ValidateScene(s);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << status.message();
    EXPECT_EQ(status.message().rfind(c.message, 0), 0u) << status.message();
  }
}

PolygonShape Square(double x0, double y0, double side) {
  return PolygonShape{{x0, x0 + side, x0 + side, x0}, {y0, y0, y0 + side, y0 + side}};
}

TEST(BoundaryRegionValidation, TheValidPairIsAccepted) {
  const Status status = ValidateScene(TwoRegions());
  EXPECT_TRUE(status.ok()) << status.message();
}

TEST(BoundaryRegionValidation, EachBadFieldIsNamed) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const auto shape = [](std::size_t k, RegionShape v) {
    return [k, v](SceneSpec& s) { s.boundary.regions[k].shape = v; };
  };
  ExpectRefused({
      {"no name", [](SceneSpec& s) { s.boundary.regions[0].name.clear(); },
       "scene.boundary.regions[0].name: is required"},
      {"capitals", [](SceneSpec& s) { s.boundary.regions[1].name = "Outlet-1"; },
       "scene.boundary.regions[1].name: only a-z, 0-9 and _"},
      {"twice", [](SceneSpec& s) { s.boundary.regions[1].name = "a"; },
       "scene.boundary.regions[1].name: 'a' is the name of regions[0] too"},
      {"box x", shape(0, BoxShape{0.01, 0.0, 0.005, 0.02}),
       "scene.boundary.regions[0].box.x1_m: must be > x0_m (got 0.005 <= 0.01)"},
      {"box y", shape(0, BoxShape{0.0, 0.02, 0.005, 0.02}),
       "scene.boundary.regions[0].box.y1_m: must be > y0_m"},
      {"box nan", shape(0, BoxShape{kNan, 0.0, 0.005, 0.02}),
       "scene.boundary.regions[0].box.x0_m: must be finite (got nan)"},
      {"circle r 0", shape(1, CircleShape{0.03, 0.01, 0.0}),
       "scene.boundary.regions[1].circle.r_m: must be a finite number > 0 (got 0)"},
      {"circle r < 0", shape(1, CircleShape{0.03, 0.01, -1e-3}),
       "scene.boundary.regions[1].circle.r_m: must be a finite number > 0"},
      {"circle centre", shape(1, CircleShape{kInf, 0.01, 1e-3}),
       "scene.boundary.regions[1].circle.cx_m: must be finite (got inf)"},
      {"half-plane normal", shape(1, HalfPlaneShape{0.03, 0.0, 0.0, 0.0}),
       "scene.boundary.regions[1].half_plane: the normal (nx, ny) must not be zero"},
      {"half-plane nan", shape(1, HalfPlaneShape{0.03, 0.0, kNan, 1.0}),
       "scene.boundary.regions[1].half_plane.nx: must be finite"},
      {"polygon lengths", shape(1, PolygonShape{{0.03, 0.035, 0.035}, {0.01, 0.01}}),
       "scene.boundary.regions[1].polygon: x_m and y_m must have equal lengths (got 3 and 2)"},
      {"polygon 2", shape(1, PolygonShape{{0.03, 0.035}, {0.01, 0.01}}),
       "scene.boundary.regions[1].polygon: needs at least 3 vertices (got 2)"},
      {"polygon nan", shape(1, PolygonShape{{0.03, kNan, 0.035}, {0.01, 0.01, 0.015}}),
       "scene.boundary.regions[1].polygon.x_m[1]: must be finite"},
      {"polygon repeat",
       shape(1, PolygonShape{{0.03, 0.03, 0.035, 0.035}, {0.01, 0.01, 0.01, 0.015}}),
       "scene.boundary.regions[1].polygon: vertex 1 repeats vertex 0"},
      {"polygon line", shape(1, PolygonShape{{0.03, 0.032, 0.036}, {0.01, 0.011, 0.013}}),
       "scene.boundary.regions[1].polygon: has no area"},
      // A bow tie (lopsided, so that its two lobes do not cancel to no area): edges 0 and 2 cross.
      {"polygon bow tie",
       shape(1, PolygonShape{{0.03, 0.035, 0.035, 0.03}, {0.005, 0.015, 0.005, 0.02}}),
       "scene.boundary.regions[1].polygon: edges 0 and 2 meet"},
      // A spike: the third vertex folds back along the second edge.
      {"polygon spike",
       shape(1, PolygonShape{{0.03, 0.035, 0.035, 0.035}, {0.005, 0.005, 0.015, 0.01}}),
       "scene.boundary.regions[1].polygon: edges 1 and 2 meet"},
      {"pressure", [](SceneSpec& s) { s.boundary.regions[0].condition = FixedPressure{kInf}; },
       "scene.boundary.regions[0].pressure_pa: must be finite (got inf)"},
      {"rate", [](SceneSpec& s) { s.boundary.regions[1].condition = FixedFlux{kNan}; },
       "scene.boundary.regions[1].flux_m2_s: must be finite (got nan)"},
      {"stage index",
       [](SceneSpec& s) {
         s = WithStages(s, 1);
         s.stages[0].regions = {StageRegionSpec{5, 1e5}};
       },
       "scene.stages[0].regions[0].region: the scene has 2 boundary regions (got index 5)"},
      {"stage twice",
       [](SceneSpec& s) {
         s = WithStages(s, 1);
         s.stages[0].regions = {StageRegionSpec{0, 1e5}, StageRegionSpec{0, 2e5}};
       },
       "scene.stages[0].regions[1].region: region 0 is listed twice in this stage"},
      {"stage value",
       [](SceneSpec& s) {
         s = WithStages(s, 2);
         s.stages[1].regions = {StageRegionSpec{1, ScheduleSpec{{0.0, 1.0}, {0.0, kNan}}}};
       },
       "scene.stages[1].regions[0].value.schedule.value[1]: must be finite"},
  });
}

// Every pair of shape kinds that shares area with a different condition is refused, naming both.
TEST(BoundaryRegionValidation, ConflictingOverlapsAreNamedForEveryPairOfShapes) {
  const auto pair = [](RegionShape a, RegionShape b) {
    return [a, b](SceneSpec& s) {
      s.boundary.regions[0].shape = a;
      s.boundary.regions[1].shape = b;
    };
  };
  const char* kBoth =
      "scene.boundary.regions[1] ('b'): overlaps regions[0] ('a') with a different condition; a "
      "domain in both would have two";
  const BoxShape box{0.0, 0.0, 0.01, 0.01};
  ExpectRefused({
      {"box box", pair(box, BoxShape{0.009, 0.009, 0.02, 0.02}), kBoth},
      {"box inside box", pair(box, BoxShape{0.002, 0.002, 0.003, 0.003}), kBoth},
      {"box circle", pair(box, CircleShape{0.012, 0.005, 0.0025}), kBoth},
      {"circle inside box", pair(box, CircleShape{0.005, 0.005, 0.001}), kBoth},
      {"circle circle", pair(CircleShape{0.01, 0.01, 0.003}, CircleShape{0.015, 0.01, 0.0025}),
       kBoth},
      {"circle half-plane",
       pair(CircleShape{0.01, 0.01, 0.003}, HalfPlaneShape{0.0125, 0.0, 1.0, 0.0}), kBoth},
      {"half-plane half-plane",
       pair(HalfPlaneShape{0.01, 0.0, -1.0, 0.0}, HalfPlaneShape{0.005, 0.0, 1.0, 0.1}), kBoth},
      {"half-plane box",
       pair(HalfPlaneShape{0.0, 0.015, 0.0, 1.0}, BoxShape{0.0, 0.01, 0.002, 0.016}), kBoth},
      {"polygon box", pair(Square(0.0, 0.0, 0.01), BoxShape{0.004, 0.004, 0.005, 0.005}), kBoth},
      {"polygon circle", pair(Square(0.0, 0.0, 0.01), CircleShape{0.0105, 0.005, 0.001}), kBoth},
      {"polygon half-plane", pair(Square(0.0, 0.0, 0.01), HalfPlaneShape{0.005, 0.0, -1.0, -1.0}),
       kBoth},
      {"polygon polygon",
       pair(Square(0.0, 0.0, 0.01), PolygonShape{{0.005, 0.02, 0.0125}, {0.005, 0.005, 0.02}}),
       kBoth},
      // Touching counts (a centroid on the common edge would be in both): conservative.
      {"boxes that touch", pair(box, BoxShape{0.01, 0.0, 0.02, 0.01}), kBoth},
      // The same number as a pressure and as a rate is a different condition.
      {"kinds",
       [](SceneSpec& s) {
         s.boundary.regions[0] = MakeRegion("a", BoxShape{0.0, 0.0, 0.01, 0.01}, FixedFlux{1e5});
         s.boundary.regions[1] =
             MakeRegion("b", CircleShape{0.01, 0.01, 0.001}, FixedPressure{1e5});
       },
       kBoth},
      // The example: the fourth region overlaps the second.
      {"four regions",
       [](SceneSpec& s) {
         s.boundary.regions = {
             MakeRegion("x", BoxShape{0.0, 0.0, 0.002, 0.002}, FixedPressure{0.0}),
             MakeRegion("a", BoxShape{0.01, 0.0, 0.015, 0.01}, FixedPressure{1e5}),
             MakeRegion("y", CircleShape{0.03, 0.015, 0.002}, FixedFlux{1e-7}),
             MakeRegion("b", CircleShape{0.015, 0.01, 0.002}, FixedPressure{2e5})};
       },
       "scene.boundary.regions[3] ('b'): overlaps regions[1] ('a') with a different condition; "
       "a domain in both would have two"},
  });
}

TEST(BoundaryRegionValidation, ShapesApartOrWithTheSameConditionAreAccepted) {
  const auto accepted = [](RegionShape a, RegionShape b, RegionCondition ca, RegionCondition cb) {
    SceneSpec s = Base();
    s.boundary.regions = {MakeRegion("a", a, ca), MakeRegion("b", b, cb)};
    return ValidateScene(s);
  };
  const FixedPressure high{1e5}, low{0.0};
  const BoxShape box{0.0, 0.0, 0.01, 0.01};
  // A circle beside the box's corner: its bounding box overlaps the box, the circle does not (a
  // polygon that circumscribes it would).
  const double d = 0.003 / std::sqrt(2.0) + 1e-6;
  for (const auto& [label, a, b] : std::vector<std::tuple<const char*, RegionShape, RegionShape>>{
           {"boxes apart", box, BoxShape{0.0101, 0.0, 0.02, 0.01}},
           {"circle at a corner", box, CircleShape{0.01 + d, 0.01 + d, 0.003}},
           {"circles apart", CircleShape{0.01, 0.01, 0.003},
            CircleShape{0.016 + 1e-7, 0.01, 0.003}},
           {"circle and half-plane", CircleShape{0.01, 0.01, 0.003},
            HalfPlaneShape{0.0131, 0.0, 1.0, 0.0}},
           // Nearly parallel half-planes that meet only 60 m away (1500 sample lengths).
           {"half-planes", HalfPlaneShape{0.005, 0.0, -1.0, 0.0},
            HalfPlaneShape{0.035, 0.0, 1.0, 0.0005}},
           {"polygon and box", Square(0.0, 0.0, 0.01), BoxShape{0.0, 0.0101, 0.01, 0.02}},
           {"polygon in a polygon's notch",
            PolygonShape{{0.0, 0.02, 0.02, 0.011, 0.011, 0.0},
                         {0.0, 0.0, 0.02, 0.02, 0.005, 0.005}},
            Square(0.0, 0.006, 0.0105)},
       }) {
    SCOPED_TRACE(label);
    const Status apart = accepted(a, b, high, low);
    EXPECT_TRUE(apart.ok()) << apart.message();
  }
  // Overlapping with the same condition: a domain in both has one either way.
  const Status same = accepted(box, BoxShape{0.005, 0.005, 0.02, 0.02}, high, high);
  EXPECT_TRUE(same.ok()) << same.message();
}

// Two regions that overlap with the same condition stay together through the stages.
TEST(BoundaryRegionValidation, AStageMustNotSetOverlappingRegionsApart) {
  SceneSpec s = WithStages(Base(), 2);
  s.boundary.regions = {MakeRegion("a", BoxShape{0.0, 0.0, 0.01, 0.01}, FixedPressure{1e5}),
                        MakeRegion("b", BoxShape{0.005, 0.0, 0.015, 0.01}, FixedPressure{1e5})};
  s.stages[1].regions = {StageRegionSpec{0, 2e5}, StageRegionSpec{1, 2e5}};
  const Status both = ValidateScene(s);
  EXPECT_TRUE(both.ok()) << both.message();
  s.stages[1].regions.pop_back();
  const Status one = ValidateScene(s);
  EXPECT_EQ(one.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(one.message(),
            "scene.stages[1].regions: regions[0] ('a') and regions[1] ('b') overlap, so a stage "
            "must set both to the same value or neither (a domain in both would have two "
            "conditions)");
}

}  // namespace
}  // namespace seep::core
