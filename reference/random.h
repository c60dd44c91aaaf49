// Random numbers for the reference solver: PCG32 (O'Neill 2014, XSH-RR
// 64/32) seeded per path through SplitMix64, so that every path draws from
// its own stream and the result cannot depend on which thread traced it.
#pragma once

#include <cstdint>

namespace skybake::reference {

// SplitMix64's finaliser: a bijective mix of 64 bits, used to turn structured
// keys (seed, query, estimator, wavelength, path) into well-spread states.
inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class Pcg32 {
 public:
  Pcg32(uint64_t seed, uint64_t stream) : state_(0), increment_((stream << 1u) | 1u) {
    Next();
    state_ += seed;
    Next();
  }

  uint32_t Next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rotation = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rotation) | (xorshifted << ((32u - rotation) & 31u));
  }

  // Uniform in [0, 1) with 53 random bits, so -log(1 - u) reaches past 36
  // mean free paths instead of stopping at 22 as 32 bits would.
  double Uniform() {
    uint64_t high = Next(), low = Next();
    return static_cast<double>(((high << 32) | low) >> 11) * 0x1p-53;
  }

 private:
  uint64_t state_;
  uint64_t increment_;
};

// The generator of one path: a pure function of its key.
inline Pcg32 PathGenerator(uint64_t seed, uint64_t query_stream, uint64_t estimator, uint64_t wavelength,
                           uint64_t path) {
  uint64_t key = SplitMix64(seed);
  key = SplitMix64(key ^ query_stream);
  key = SplitMix64(key ^ (estimator << 8 | wavelength));
  uint64_t state = SplitMix64(key ^ path);
  uint64_t stream = SplitMix64(state ^ 0x6A09E667F3BCC909ull);
  return Pcg32(state, stream);
}

}  // namespace skybake::reference
