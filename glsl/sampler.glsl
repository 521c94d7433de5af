// The path's random numbers, dimension by dimension (SPEC_SAMPLER picks the sampler):
//
// SAMPLER_INDEPENDENT: a PCG32 stream per (pixel, sample, seed), every number independent of
//   every other - the error of neighbouring pixels is white noise.
// SAMPLER_ZSOBOL: Ahmed & Wonka's screen-space blue-noise sampler ("Screen-Space Blue-Noise
//   Diffusion of Monte Carlo Sampling Error via Hierarchical Ordering of Pixels", SIGGRAPH Asia
//   2020), the ordering pbrt-v4's ZSobolSampler uses. A lattice point's samples are consecutive
//   indices of one Owen-scrambled 2-D Sobol sequence, points taken in Morton (Z) order: the 4
//   points of a 2x2 quad hold an aligned block of 4*spp indices, a 4x4 block 16*spp, and so on,
//   so every such block is a stratified (0,m,2)-net and its mean error is small - the error
//   left is in the high spatial frequencies the eye (and the periphery's blur) sees least.
//   Each call takes a fresh dimension pair: its own nested-uniform (Owen) shuffle of the index
//   keeps aligned blocks aligned while decorrelating one pair from the next (Burley, "Practical
//   Hash-based Owen Scrambling", JCGT 2020), its own Owen scramble of the point's values.
//   Scrambles are hashed from the frame's seed, so every frame is an independent unbiased
//   estimate and a history of frames converges to the image.
#ifndef FOVEA_SAMPLER_GLSL
#define FOVEA_SAMPLER_GLSL

#include "bindings.glsl"
#include "rng.glsl"

// A Morton tile's side in lattice points is at most 2^ZSOBOL_TILE_BITS: larger images repeat the
// ordering tile by tile, each tile scrambled with its own seed.
#define ZSOBOL_TILE_BITS 8u

struct Sampler {
    uint state; // independent: the PCG32 stream's state; zsobol: the sample's sequence index
    uint seed;  // zsobol: the tile's, frame's and eye's scramble seed
    uint dim;   // zsobol: the dimension pairs taken so far
};

// Laine & Karras' hash as Burley improved it: each bit of x flips depending only on lower
// bits, so applied to bit-reversed x it is an Owen (nested uniform) scramble.
uint laine_karras(uint x, uint seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Owen scrambling: bit b of x flips by a hash of the bits above it. On a sequence index it maps
// aligned blocks of 2^k indices onto aligned blocks; on a point's coordinate it keeps every
// elementary interval's count.
uint nested_uniform_scramble(uint x, uint seed) {
    return bitfieldReverse(laine_karras(bitfieldReverse(x), seed));
}

// Sobol's second dimension (primitive polynomial x + 1: direction numbers v_k = v_{k-1} ^
// v_{k-1} >> 1); with the first (the bit reversal) it is a (0,2)-sequence.
uint sobol_dim1(uint i) {
    uint x = 0u;
    for (uint v = 0x80000000u; i != 0u; i >>= 1, v ^= v >> 1) {
        if ((i & 1u) != 0u) x ^= v;
    }
    return x;
}

// Interleaves the low 16 bits of v with zeros (v's bit b moves to bit 2b).
uint spread_bits(uint v) {
    v &= 0xffffu;
    v = (v | (v << 8)) & 0x00ff00ffu;
    v = (v | (v << 4)) & 0x0f0f0f0fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

// What every sample of one lattice point shares, computed once per point: for zsobol the
// point's block of sequence indices (its Morton index shifted past the sample bits) and its
// tile's scramble seed; for the independent sampler its pixel and hashed seed.
struct SamplerPoint {
    uint base;
    uint seed;
};

// Lattice point `point` of a lattice of `spacing`, traced at `spp` samples (the independent
// sampler keys on `pixel_index`, the pixel's row-major index, as it always has).
SamplerPoint sampler_point(ivec2 point, uint spacing, uint pixel_index, uint spp, uint seed) {
    if (SAMPLER == SAMPLER_INDEPENDENT) return SamplerPoint(pixel_index, pcg_hash(seed));
    // A pixel's block of indices is spp rounded up to a power of two; the tile shrinks so that
    // tile and block fit 32 bits.
    uint block_bits = spp <= 1u ? 0u : uint(findMSB(spp - 1u)) + 1u;
    uint tile_bits = min(ZSOBOL_TILE_BITS, (32u - block_bits) / 2u);
    uvec2 p = uvec2(point);
    uvec2 in_tile = p & ((1u << tile_bits) - 1u);
    uvec2 tile = p >> tile_bits;
    uint morton = spread_bits(in_tile.x) | (spread_bits(in_tile.y) << 1);
    // Spacing enters the seed: lattices of different spacings must not repeat each other's
    // numbers where they overlap on screen.
    return SamplerPoint(morton << block_bits, pcg_hash(seed ^ pcg_hash(tile.x ^ pcg_hash(tile.y ^ pcg_hash(spacing)))));
}

// Sample `sample_index` of the point.
Sampler sampler_start(SamplerPoint point, uint sample_index) {
    Sampler s;
    s.dim = 0u;
    if (SAMPLER == SAMPLER_INDEPENDENT) {
        s.state = pcg_hash(point.base ^ pcg_hash(sample_index ^ point.seed));
        s.seed = 0u;
    } else {
        s.state = point.base | sample_index;
        s.seed = point.seed;
    }
    return s;
}

// The next dimension pair's Owen-shuffled index (zsobol) and its scramble seed.
uint zsobol_pair(inout Sampler s, out uint h) {
    h = pcg_hash(s.seed ^ pcg_hash(s.dim++));
    return nested_uniform_scramble(s.state, h);
}

// The pair's first coordinate: the Owen-scrambled van der Corput point of index i.
uint zsobol_x(uint i, uint h) {
    return nested_uniform_scramble(bitfieldReverse(i), pcg_hash(h ^ 0x68bc21ebu));
}

vec2 sample_2d(inout Sampler s) {
    if (SAMPLER == SAMPLER_INDEPENDENT) {
        float a = pcg_next(s.state);
        return vec2(a, pcg_next(s.state));
    }
    uint h;
    uint i = zsobol_pair(s, h);
    uint y = nested_uniform_scramble(sobol_dim1(i), pcg_hash(h ^ 0x02e5be93u));
    return vec2(bits_to_unit(zsobol_x(i, h)), bits_to_unit(y));
}

// One number. The independent sampler takes one from its stream; zsobol takes a whole pair's
// first coordinate (a 1-D projection of a (0,2)-sequence is stratified too), so a number's
// dimension never depends on how many 1-D numbers came before it.
float sample_1d(inout Sampler s) {
    if (SAMPLER == SAMPLER_INDEPENDENT) return pcg_next(s.state);
    uint h;
    uint i = zsobol_pair(s, h);
    return bits_to_unit(zsobol_x(i, h));
}

#endif
