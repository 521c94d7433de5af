#version 460
// One dispatch renders spp samples for every pixel of the frame and writes their mean.
// Camera rays follow OpenXR's view convention: per-eye asymmetric tangents left/right/up/down.
#extension GL_GOOGLE_include_directive : require
#include "integrators.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

vec3 camera_ray(vec2 pixel, vec2 jitter) {
    vec2 uv = (pixel + jitter) / vec2(pc.width, pc.height); // y grows downward in the image
    float tx = mix(pc.cam_tan.x, pc.cam_tan.y, uv.x);
    float ty = mix(pc.cam_tan.z, pc.cam_tan.w, uv.y);
    return normalize(pc.cam_forward.xyz + tx * pc.cam_right.xyz + ty * pc.cam_up.xyz);
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.width || pixel.y >= pc.height) return;
    uint pixel_index = pixel.y * pc.width + pixel.x;
    vec3 sum = vec3(0.0);
    uint rays = 0u;
    uint nonfinite = 0u;
    uint overflows = 0u;
    for (uint s = 0u; s < pc.spp; ++s) {
        Rng rng = rng_init(pixel_index, pc.sample_offset + s, pc.seed);
        vec3 d = camera_ray(vec2(pixel), rng_next2(rng));
        bool overflow = false;
        vec3 L = INTEGRATOR == INTEGRATOR_SEED ? trace_seed(pc.cam_position.xyz, d, rng, rays, overflow)
                                               : trace_pt(pc.cam_position.xyz, d, rng, rays, overflow);
        if (overflow) overflows++;
        // A non-finite sample is dropped (counted as black) and reported, never written.
        if (any(isnan(L)) || any(isinf(L))) {
            nonfinite++;
        } else {
            sum += L;
        }
    }
    imageStore(out_image, ivec2(pixel), vec4(sum / float(max(pc.spp, 1u)), 1.0));
    if (nonfinite > 0u) atomicAdd(stats[STAT_NONFINITE], nonfinite);
    if (overflows > 0u) atomicAdd(stats[STAT_STACK_OVERFLOW], overflows);
    atomicAdd(stats[STAT_PATHS], pc.spp);
    atomicAdd(stats[STAT_RAYS], rays);
}
