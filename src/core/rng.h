#pragma once
// Deterministic random numbers: every pixel (and every sample stream) gets its own PCG32
// stream derived from (seed, pixel index), so images do not depend on the thread count.
#include <cstdint>
#include <pcg_random.hpp>

namespace lvox {

// SplitMix64's finaliser: neighbouring inputs (seeds, pixels) give unrelated outputs.
inline uint64_t splitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

class Rng {
 public:
  // PCG streams that differ only in their increment are correlated, so the state is
  // scrambled from both the seed and the stream as well.
  Rng(uint64_t seed, uint64_t stream)
      : gen_(splitMix64(splitMix64(seed) ^ stream), splitMix64(stream ^ ~seed)) {}

  // Uniform in [0, 1): 24 random bits, so the result is never rounded up to 1.
  float uniform() { return static_cast<float>(gen_() >> 8) * 0x1p-24f; }
  double uniformDouble() {
    const uint64_t hi = gen_(), lo = gen_();
    return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1p-53;
  }
  uint32_t next() { return gen_(); }

 private:
  pcg32 gen_;
};

}  // namespace lvox
