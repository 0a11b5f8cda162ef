#pragma once
// An Owen-scrambled (0,2)-sequence: the first two dimensions of Sobol's sequence (van der
// Corput and the Pascal-matrix dimension), each with its own hash-based nested uniform
// scramble (Burley 2020, "Practical Hash-based Owen Scrambling", with the Laine-Karras
// permutation). Every point is uniform on [0, 1)^2, and the first 2^m points of one
// scramble have exactly one point in each of the 2^m elementary intervals of every shape
// 2^-a x 2^-(m-a): any power-of-two prefix is stratified like a jittered grid, and
// samples [a, b) of a longer run are exactly that run's (chunked references, progressive
// passes). On a pixel with an edge or a texture the error of N such points falls about
// as N^-0.75 instead of N^-0.5 (tests/core/test_low_discrepancy.cpp).
#include <cstdint>

namespace lvox {

inline uint32_t reverseBits(uint32_t v) {
  v = (v << 16) | (v >> 16);
  v = ((v & 0x00ff00ffu) << 8) | ((v & 0xff00ff00u) >> 8);
  v = ((v & 0x0f0f0f0fu) << 4) | ((v & 0xf0f0f0f0u) >> 4);
  v = ((v & 0x33333333u) << 2) | ((v & 0xccccccccu) >> 2);
  return ((v & 0x55555555u) << 1) | ((v & 0xaaaaaaaau) >> 1);
}

// Nested uniform scrambling of the binary digits of v (most significant first): digit i
// is flipped by a hash of `seed` and the digits above it, so intervals map onto intervals
// of the same size and the stratification above survives.
inline uint32_t owenScramble(uint32_t v, uint32_t seed) {
  v = reverseBits(v);
  // Laine-Karras permutation with Burley's constants: each output bit depends only on
  // the same and lower input bits (here: the digits above it before the reversal).
  v += seed;
  v ^= v * 0x6c50b47cu;
  v ^= v * 0xb82f1e52u;
  v ^= v * 0xc7afe638u;
  v ^= v * 0x8d22f6e6u;
  return reverseBits(v);
}

// Point `index` of the unscrambled sequence, as 32-bit fixed point.
inline uint32_t sobolDimension0(uint32_t index) { return reverseBits(index); }
inline uint32_t sobolDimension1(uint32_t index) {
  uint32_t v = 0;
  for (uint32_t direction = 1u << 31; index; index >>= 1, direction ^= direction >> 1)
    if (index & 1u) v ^= direction;
  return v;
}

// 32-bit fixed point to [0, 1): the top 24 bits, so the result is never rounded up to 1.
inline float fixedPointToUnit(uint32_t v) { return static_cast<float>(v >> 8) * 0x1p-24f; }

struct UnitPoint2 {
  float u, v;
};
struct FixedPoint2 {
  uint32_t u, v;  // 32-bit fixed point in [0, 1)
};

// Point `index` of the sequence scrambled by (seedU, seedV), in 32-bit fixed point: for a
// caller that splits a coordinate further (LightSet picks an emitter with it, then uses
// where it fell in the emitter's share).
inline FixedPoint2 scrambledSobol2Fixed(uint32_t index, uint32_t seedU, uint32_t seedV) {
  return {owenScramble(sobolDimension0(index), seedU), owenScramble(sobolDimension1(index), seedV)};
}
// The same point in floats.
inline UnitPoint2 scrambledSobol2(uint32_t index, uint32_t seedU, uint32_t seedV) {
  const FixedPoint2 p = scrambledSobol2Fixed(index, seedU, seedV);
  return {fixedPointToUnit(p.u), fixedPointToUnit(p.v)};
}

}  // namespace lvox
