#version 460
// The trace pass (thesis 3.2.1-3.2.2): one thread per traced target pixel of this eye. The
// thread finds its span (a run of ray-buffer entries of one layer) by binary search over the
// spans' prefix sums, reads its pixel offset from the ray buffer, adds the layer's anchor
// (the gaze pixel, or 0,0 for the background) and writes the mean of the layer's spp samples
// into that layer's image. A sample's jitter and random numbers depend only on (pixel, sample,
// seed, eye), so the same pixel traced by any layer config gives bit-identical values.
#extension GL_GOOGLE_include_directive : require
#include "integrators.glsl"
#include "view.glsl"

layout(local_size_x = TRACE_WORKGROUP_SIZE) in;

vec3 camera_ray(vec2 pixel, vec2 jitter) {
    vec2 t = pixel_tan(pixel + jitter);
    return normalize(pc.cam_forward.xyz + t.x * pc.cam_right.xyz + t.y * pc.cam_up.xyz);
}

void main() {
    uint thread = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * TRACE_WORKGROUP_SIZE)
                + gl_GlobalInvocationID.x;
    if (pc.span_count == 0u) return;
    uint last = pc.span_first + pc.span_count - 1u;
    if (thread >= spans[last].prefix + spans[last].count) return;
    uint lo = pc.span_first;
    uint hi = last;
    while (lo < hi) { // the last span whose prefix is <= thread
        uint mid = (lo + hi + 1u) / 2u;
        if (spans[mid].prefix <= thread) lo = mid; else hi = mid - 1u;
    }
    GpuSpan span = spans[lo];
    uint packed = ray_offsets[span.first + (thread - span.prefix)];
    ivec2 offset = ivec2(int(packed << 16) >> 16, int(packed) >> 16);
    // Only the three fields a thread needs: the whole GpuLayer is 96 bytes per thread.
    ivec2 pixel = ivec2(layers[span.layer].anchor_x, layers[span.layer].anchor_y) + offset;
    uint spp = layers[span.layer].spp;
    uint image_layer = layers[span.layer].image_layer;

    uint pixel_index = uint(pixel.y) * pc.width + uint(pixel.x);
    uint seed = pc.seed + pc.eye * 0x9E3779B9u; // eye 0 keeps the user's seed
    vec3 sum = vec3(0.0);
    uint rays = 0u;
    uint nonfinite = 0u;
    uint overflows = 0u;
    for (uint s = 0u; s < spp; ++s) {
        Rng rng = rng_init(pixel_index, pc.sample_offset + s, seed);
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
    imageStore(layer_images, ivec3(pixel, image_layer), vec4(sum / float(spp), 1.0));
    // Each eye counts in its own block, so a stereo frame reports rays per eye.
    uint block = pc.eye * STAT_COUNT;
    if (nonfinite > 0u) atomicAdd(stats[block + STAT_NONFINITE], nonfinite);
    if (overflows > 0u) atomicAdd(stats[block + STAT_STACK_OVERFLOW], overflows);
    atomicAdd(stats[block + STAT_PATHS], spp);
    atomicAdd(stats[block + STAT_RAYS], rays);
}
