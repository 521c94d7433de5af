// Random numbers: a PCG hash seeds a per-sample PCG32 stream, so every (pixel, sample, seed)
// has its own independent, reproducible sequence - the same seed gives a bit-identical image.
#ifndef FOVEA_RNG_GLSL
#define FOVEA_RNG_GLSL

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

struct Rng {
    uint state;
};

Rng rng_init(uint pixel, uint sample_index, uint seed) {
    Rng r;
    r.state = pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)));
    return r;
}

// A float in [0, 1): the top 24 bits, so 1.0 is never returned.
float rng_next(inout Rng r) {
    r.state = r.state * 747796405u + 2891336453u;
    uint word = ((r.state >> ((r.state >> 28u) + 4u)) ^ r.state) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8u) * (1.0 / 16777216.0);
}

vec2 rng_next2(inout Rng r) {
    float a = rng_next(r);
    return vec2(a, rng_next(r));
}

#endif
