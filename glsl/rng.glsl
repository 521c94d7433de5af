// Random numbers: a PCG hash seeds a per-sample PCG32 stream, so every (pixel, sample, seed)
// has its own independent, reproducible sequence - the same seed gives a bit-identical image.
// (sampler.glsl draws a path's numbers from it or from a blue-noise sequence.)
#ifndef FOVEA_RNG_GLSL
#define FOVEA_RNG_GLSL

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A float in [0, 1) from 32 random bits: the top 24, so 1.0 is never returned.
float bits_to_unit(uint x) {
    return float(x >> 8u) * (1.0 / 16777216.0);
}

// The stream's next number: one PCG32 step.
float pcg_next(inout uint state) {
    state = state * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return bits_to_unit((word >> 22u) ^ word);
}

#endif
