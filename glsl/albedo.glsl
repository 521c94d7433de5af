// The albedo the denoiser filters without (LATTICE_ALBEDO, while a layer denoises): trace.comp
// stores each lattice point's, temporal.comp divides what it shows by it and denoise.comp's
// last iteration multiplies it back. So the denoiser smooths the illumination only, and a
// texture's detail is not blurred with the noise (SVGF's demodulation, Schied et al. 2017).
#ifndef FOVEA_ALBEDO_GLSL
#define FOVEA_ALBEDO_GLSL

// An albedo channel below this is taken as this: dividing by a black channel would turn its
// tiny radiance into a large one that the other channels' filter weights do not expect.
const float ALBEDO_FLOOR = 0.01;

// Stored as the square root in 8 bits per channel: finer steps where albedos are dark.
uint pack_albedo(vec3 a) {
    return packUnorm4x8(vec4(sqrt(clamp(a, 0.0, 1.0)), 1.0));
}

vec3 unpack_albedo(uint bits) {
    vec3 s = unpackUnorm4x8(bits).rgb;
    return max(s * s, vec3(ALBEDO_FLOOR));
}

#endif
