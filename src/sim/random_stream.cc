#include "auvdock/sim/random_stream.h"

#include <cmath>

namespace auvdock {

namespace {

uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

std::mt19937_64 MakeRandomStream(uint64_t seed, uint64_t stream_id) {
  return std::mt19937_64(SplitMix64(SplitMix64(seed) ^ (stream_id * 0xd1342543de82ef95ULL)));
}

double Uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}

double StandardNormal(std::mt19937_64& rng) {
  double u1 = Uniform01(rng);
  while (u1 <= 0.0) u1 = Uniform01(rng);
  const double u2 = Uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

Eigen::Vector3d StandardNormal3(std::mt19937_64& rng) {
  const double a = StandardNormal(rng);
  const double b = StandardNormal(rng);
  const double c = StandardNormal(rng);
  return Eigen::Vector3d(a, b, c);
}

}  // namespace auvdock
