// Portable, seedable random numbers for the simulator. std:: distributions are
// implementation-defined; these are not, so a seed gives the same world everywhere.
// That also needs one draw per statement (or per declarator): C++ leaves the order in which
// a call's arguments or an operator's operands are evaluated unspecified, so two draws in
// `f(rng.uniform(), rng.uniform())` come in one order under gcc and the other under clang.
// scripts/test.sh compares the two compilers' simulated sequences byte for byte.
#pragma once

#include <cmath>
#include <cstdint>

namespace scfloam::sim {

// SplitMix64 finalizer: a good 64-bit mixing function, used to derive independent
// streams from (seed, purpose, frame, column, ...) so thread scheduling never matters.
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
inline std::uint64_t hash_combine(std::uint64_t a, std::uint64_t b) { return mix64(a ^ mix64(b)); }

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(mix64(seed)) {}
  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int uniform_int(int lo, int hi_inclusive) {
    return lo + static_cast<int>(uniform() * (hi_inclusive - lo + 1));
  }
  bool chance(double p) { return uniform() < p; }
  // Standard normal by Box-Muller (no cached second value: keeps the stream simple).
  double normal() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  std::uint64_t state_;
};

}  // namespace scfloam::sim
