// The albedo the denoiser filters without (while a layer denoises): trace.comp stores each
// lattice point's (LATTICE_ALBEDO), temporal.comp keeps each pixel's mean over the frames
// (HISTORY_ALBEDO) and divides what it shows by it, and denoise.comp's last iteration
// multiplies it back. So the denoiser smooths the illumination only, and a
// texture's detail is not blurred with the noise (SVGF's demodulation, Schied et al. 2017).
#ifndef FOVEA_ALBEDO_GLSL
#define FOVEA_ALBEDO_GLSL

// An albedo channel below this is taken as this: dividing by a black channel would turn its
// tiny radiance into a large one that the other channels' filter weights do not expect.
const float ALBEDO_FLOOR = 0.01;

// Stored as the square root in 10 bits per channel: finer steps where albedos are dark, and
// fine enough for the history's running mean, whose steps shrink as its count grows.
uint pack_albedo(vec3 a) {
    uvec3 q = uvec3(round(sqrt(clamp(a, 0.0, 1.0)) * 1023.0));
    return q.r | (q.g << 10) | (q.b << 20);
}

vec3 unpack_albedo(uint bits) {
    vec3 s = vec3(uvec3(bits, bits >> 10, bits >> 20) & 1023u) / 1023.0;
    return s * s;
}

// An albedo as a divisor: each channel at least ALBEDO_FLOOR.
vec3 floored_albedo(vec3 a) {
    return max(a, vec3(ALBEDO_FLOOR));
}

// What the frame is divided by and multiplied back with.
vec3 albedo_divisor(uint bits) {
    return floored_albedo(unpack_albedo(bits));
}

#endif
