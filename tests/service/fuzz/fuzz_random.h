// The request fuzzer's random source: SplitMix64, whose output for a seed is fixed by its few
// lines (the standard library's distributions are not: another library draws other requests
// from the same seed), so a seed printed with a failure reproduces the same requests anywhere.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace seep::fuzz {

class FuzzRandom {
 public:
  explicit FuzzRandom(std::uint64_t seed) : state_(seed) {}

  std::uint64_t Next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, n) for n > 0 (the modulo's bias is immaterial at these sizes).
  std::uint64_t Below(std::uint64_t n) { return n == 0 ? 0 : Next() % n; }
  int Int(int lo, int hi) {
    return lo + static_cast<int>(Below(static_cast<std::uint64_t>(hi - lo + 1)));
  }
  // Uniform in [0, 1).
  double Unit() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  bool Chance(double p) { return Unit() < p; }
  template <typename T>
  const T& Pick(const std::vector<T>& from) {
    return from[Below(from.size())];
  }

 private:
  std::uint64_t state_;
};

// The seed of request `index` of a run seeded `run_seed`: each request draws from its own stream,
// so that request i is the same whatever the ones before it drew.
inline std::uint64_t RequestSeed(std::uint64_t run_seed, std::uint64_t index) {
  FuzzRandom mix(run_seed ^ (index * 0xd1b54a32d192ed03ULL));
  mix.Next();
  return mix.Next();
}

}  // namespace seep::fuzz
