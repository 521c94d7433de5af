#version 460
// The fill pass (thesis 3.2.3): every pixel of one layer that the layer shows but did not
// trace gets the bicubic Catmull-Rom value (eq. 3.17, fig. 3.10) of the 4x4 lattice points
// around it. Taps beyond the image clamp to its first/last lattice point; taps never fall on
// untraced points inside the image, because the planner traces a margin of two lattice steps
// (plus slack) around everything shown. Lattice pixels are only read, the rest only written,
// so filling in place is race-free.
//
// An 8x8 tile of pixels needs at most TILE_TAPS x TILE_TAPS lattice points (spacing >= 2), so
// the workgroup loads them into shared memory once: about 0.5 image loads per pixel instead
// of 16, which is what makes the pass cheap next to tracing (image loads are slow on lavapipe).
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

// Cells an 8-pixel row spans at spacing >= 2: at most 5, plus one tap before and two after.
#define TILE_TAPS 8
shared vec4 taps[TILE_TAPS][TILE_TAPS];

// Eq. 3.17: the value between v1 (t = 0) and v2 (t = 1); same operation order as
// src/foveation/catmull_rom.rs.
vec4 cubic(vec4 v0, vec4 v1, vec4 v2, vec4 v3, float t) {
    vec4 a = -0.5 * v0 + 1.5 * v1 - 1.5 * v2 + 0.5 * v3;
    vec4 b = v0 - 2.5 * v1 + 2.0 * v2 - 0.5 * v3;
    vec4 c = -0.5 * v0 + 0.5 * v2;
    return ((a * t + b) * t + c) * t + v1;
}

void main() {
    GpuLayer L = layers[pc.layer];
    int d = L.spacing;
    ivec2 anchor = ivec2(L.anchor_x, L.anchor_y);
    ivec2 lo = ivec2(L.lattice_min_x, L.lattice_min_y);
    ivec2 hi = ivec2(L.lattice_max_x, L.lattice_max_y);
    ivec2 tile = ivec2(L.fill_min_x, L.fill_min_y) + ivec2(gl_WorkGroupID.xy) * ivec2(gl_WorkGroupSize.xy);
    // The tile's first tap: one lattice step before the cell of its first pixel.
    ivec2 first_cell = floor_div(tile - anchor, d) - 1;

    // Cooperative load of the tile's taps (clamped to the lattice points on the image).
    uint local = gl_LocalInvocationIndex;
    for (uint i = local; i < TILE_TAPS * TILE_TAPS; i += gl_WorkGroupSize.x * gl_WorkGroupSize.y) {
        ivec2 c = first_cell + ivec2(i % TILE_TAPS, i / TILE_TAPS);
        ivec2 q = clamp(anchor + c * d, lo, hi);
        taps[i / TILE_TAPS][i % TILE_TAPS] = imageLoad(layer_images, ivec3(q, L.image_layer));
    }
    barrier();

    ivec2 p = tile + ivec2(gl_LocalInvocationID.xy);
    if (p.x >= L.fill_max_x || p.y >= L.fill_max_y) return;
    ivec2 cell = floor_div(p - anchor, d);
    ivec2 within = p - anchor - cell * d;
    if (within == ivec2(0)) return; // a lattice point: traced

    // Only pixels the merge may read: inside the layer's ring and the occlusion mask, with
    // one pixel of slack for float differences.
    vec3 u = tan_direction(pixel_tan(vec2(p) + 0.5));
    vec3 gaze = tan_direction(L.gaze.xy);
    if (!within_angle(u, gaze, L.fill_cos.x) || within_angle(u, gaze, L.fill_cos.y)) return;
    if (!within_angle(u, vec3(0.0, 0.0, 1.0), L.fill_cos.z)) return;

    ivec2 k = cell - 1 - first_cell; // this pixel's first tap within the tile
    vec2 f = vec2(within) / float(d);
    vec4 rows[4];
    for (int j = 0; j < 4; ++j) {
        rows[j] = cubic(taps[k.y + j][k.x], taps[k.y + j][k.x + 1], taps[k.y + j][k.x + 2],
                        taps[k.y + j][k.x + 3], f.x);
    }
    imageStore(layer_images, ivec3(p, L.image_layer), cubic(rows[0], rows[1], rows[2], rows[3], f.y));
}
