// Seeded, portable random numbers for the simulator.
//
// Each sensor draws from its own stream, derived from (seed, stream id) by SplitMix64, so
// changing one sensor's settings does not change another sensor's noise, and the same seed gives
// byte-identical output. The normal variates use our own Box-Muller transform on
// std::mt19937_64 (whose output sequence the C++ standard fixes), not std::normal_distribution
// (whose algorithm differs between standard libraries).
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

namespace auvdock {

enum class RandomStreamId : uint64_t {
  kImu = 1,
  kDepth = 2,
  kDvl = 3,
  kAcoustic = 4,
  kSbl = 5,
  kHeading = 6,
  kLensBase = 50,         // + camera index: the randomised distortion
  kRenderLookBase = 200,  // + camera index: the randomised look
  kSyntheticDetectionsBase = 300,  // + camera index: the synthetic front-end's errors
};

std::mt19937_64 MakeRandomStream(uint64_t seed, uint64_t stream_id);
inline std::mt19937_64 MakeRandomStream(uint64_t seed, RandomStreamId id) {
  return MakeRandomStream(seed, static_cast<uint64_t>(id));
}

// The stream of one image: camera index `camera` (< 256), frame number `frame`. One stream per
// image lets the images be rendered in any order, on any number of threads, and still be the
// same for a seed (ids from 2^32 up: apart from the fixed ones above).
inline std::mt19937_64 MakeImageRandomStream(uint64_t seed, uint64_t camera, uint64_t frame) {
  return MakeRandomStream(seed, (uint64_t{1} << 32) + (frame << 8) + camera);
}

// Uniform in [0, 1) with 53 random bits.
double Uniform01(std::mt19937_64& rng);
// Uniform in [lo, hi).
inline double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * Uniform01(rng);
}
// Standard normal (Box-Muller).
double StandardNormal(std::mt19937_64& rng);
Eigen::Vector3d StandardNormal3(std::mt19937_64& rng);

}  // namespace auvdock
