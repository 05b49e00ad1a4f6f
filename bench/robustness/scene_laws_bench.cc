// seep_scene_laws_bench: the laws of tests/core/metamorphic/scene_laws.h over as many generated
// scenes as it is given time for (the CTest suite runs 200 fixed seeds; this runs thousands).
//
//   seep_scene_laws_bench [--seconds S] [--first-seed N] [--count N] [--seed N] [--threads-law]
//                         [--real-water]
//
// Seeds from --first-seed on (default 1,000: past the CTest suite's 1-200), until --count scenes
// or --seconds have passed. --seed N checks that one scene and prints it (what to reproduce a
// failure with). Each scene: a translation, a quarter turn and a mirror, a resume at a step drawn
// from the seed, and the fluid books; --threads-law adds one thread against two (every loop on
// the team); --real-water lets the moving scenes draw real water too (scene_generator.h says why
// the CTest suite does not). Prints one line per failure (seed, family, law, what broke) and a
// summary: scenes, laws checked, failures, time, scenes per family. Exit status 1 when any law
// failed.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "scene_generator.h"
#include "scene_laws.h"

namespace {

using seep::core::SceneSpec;
using seep::core::SolverKind;
using namespace seep::core::metamorphic;  // NOLINT(google-build-using-namespace)

struct Options {
  double seconds = 600.0;
  std::uint64_t first_seed = 1000;
  std::uint64_t count = 1'000'000;
  std::uint64_t one_seed = 0;
  bool threads_law = false;
  bool real_water = false;
};

bool ParseOptions(int argc, char** argv, Options* o) {
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    const bool has_value = k + 1 < argc;
    if (arg == "--threads-law") {
      o->threads_law = true;
    } else if (arg == "--real-water") {
      o->real_water = true;
    } else if (arg == "--seconds" && has_value) {
      o->seconds = std::strtod(argv[++k], nullptr);
    } else if (arg == "--first-seed" && has_value) {
      o->first_seed = std::strtoull(argv[++k], nullptr, 10);
    } else if (arg == "--count" && has_value) {
      o->count = std::strtoull(argv[++k], nullptr, 10);
    } else if (arg == "--seed" && has_value) {
      o->one_seed = std::strtoull(argv[++k], nullptr, 10);
    } else {
      std::fprintf(stderr,
                   "usage: %s [--seconds S] [--first-seed N] [--count N] [--seed N] "
                   "[--threads-law] [--real-water]\n(unknown or incomplete argument: %s)\n",
                   argv[0], arg.c_str());
      return false;
    }
  }
  if (!(o->seconds > 0.0) || o->count == 0) {
    std::fprintf(stderr, "--seconds and --count must be > 0\n");
    return false;
  }
  return true;
}

// What the scene is, in a line (the seed reproduces all of it).
std::string Describe(const GeneratedScene& g) {
  const SceneSpec& s = g.scene;
  const char* solver = s.solver.kind == SolverKind::kSteady     ? "steady"
                       : s.solver.kind == SolverKind::kExplicit ? "explicit"
                       : s.solver.kind == SolverKind::kImplicit ? "implicit"
                                                                : "crank-nicolson";
  std::string effects;
  for (const auto& e : s.effects) effects += fmt::format(" {}", seep::core::EffectName(e));
  return fmt::format("{} [{}], {} steps, K_f {:.3g} Pa, effects:{}", s.name, solver, g.steps,
                     s.fluid.bulk_modulus_pa, effects);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!ParseOptions(argc, argv, &o)) return 2;
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const std::uint64_t first = o.one_seed > 0 ? o.one_seed : o.first_seed;
  const std::uint64_t count = o.one_seed > 0 ? 1 : o.count;
  std::uint64_t scenes = 0, laws = 0, failures = 0, sensitive = 0;
  std::map<std::string, std::uint64_t> per_family;
  for (std::uint64_t seed = first; seed < first + count && elapsed() < o.seconds; ++seed) {
    const GeneratedScene g = GenerateScene(seed, {o.real_water});
    if (o.one_seed > 0)
      std::printf("seed %llu: %s\n", static_cast<unsigned long long>(seed), Describe(g).c_str());
    ++scenes;
    ++per_family[FamilyName(g.family)];
    std::vector<std::pair<const char*, std::string>> verdicts;
    const LawScene scene(g.scene);
    const double spread = RoundingSpread(scene, g.steps);
    if (spread > kIsometryTolerance) ++sensitive;
    verdicts.emplace_back("translation",
                          CheckIsometry(scene, g.steps, SeedTranslation(seed), spread));
    verdicts.emplace_back("quarter turn", CheckIsometry(scene, g.steps, {Turn::kQuarter}, spread));
    verdicts.emplace_back("mirror", CheckIsometry(scene, g.steps, {Turn::kMirrorX}, spread));
    if (g.scene.solver.kind != SolverKind::kSteady) {
      verdicts.emplace_back("resume", CheckResume(scene, g.steps, SeedResumeStep(seed, g.steps)));
    }
    if (o.threads_law) verdicts.emplace_back("threads", CheckThreads(scene, g.steps));
    verdicts.emplace_back("books", CheckBooks(scene, g.steps));
    for (const auto& [law, verdict] : verdicts) {
      ++laws;
      if (verdict.empty()) continue;
      ++failures;
      std::printf("FAILED seed %llu (%s) %s: %s\n  scene: %s\n",
                  static_cast<unsigned long long>(seed), FamilyName(g.family), law, verdict.c_str(),
                  Describe(g).c_str());
      std::fflush(stdout);
    }
  }
  std::printf(
      "%llu scenes (seeds %llu-%llu), %llu laws checked, %llu failed, %.0f s; %llu scenes where "
      "one rounding moves the state by more than %.0e;",
      static_cast<unsigned long long>(scenes), static_cast<unsigned long long>(first),
      static_cast<unsigned long long>(first + scenes - 1), static_cast<unsigned long long>(laws),
      static_cast<unsigned long long>(failures), elapsed(),
      static_cast<unsigned long long>(sensitive), kIsometryTolerance);
  for (const auto& [family, n] : per_family) {
    std::printf(" %s %llu", family.c_str(), static_cast<unsigned long long>(n));
  }
  std::printf("\n");
  return failures == 0 ? 0 : 1;
}
