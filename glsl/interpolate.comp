#version 460
// The fill pass (thesis 3.2.3): every pixel of one layer that the layer shows but did not
// trace gets the bicubic Catmull-Rom value (eq. 3.17, fig. 3.10) of the 4x4 lattice points
// around it. Taps beyond the image clamp to its first/last lattice point; taps never fall on
// untraced points inside the image, because the planner traces a margin of two lattice steps
// (plus slack) around everything shown. Lattice pixels are only read, the rest only written,
// so filling in place is race-free.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

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
    ivec2 p = ivec2(L.fill_min_x, L.fill_min_y) + ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= L.fill_max_x || p.y >= L.fill_max_y) return;
    int d = L.spacing;
    ivec2 anchor = ivec2(L.anchor_x, L.anchor_y);
    ivec2 cell = floor_div(p - anchor, d);
    ivec2 within = p - anchor - cell * d;
    if (within == ivec2(0)) return; // a lattice point: traced

    // Only pixels the merge may read: inside the layer's ring and the occlusion mask, with
    // one pixel of slack for float differences.
    vec2 t = pixel_tan(vec2(p) + 0.5);
    float slack = L.gaze.z;
    float theta = angle_between(t, L.gaze.xy);
    if (theta >= L.outer + slack || theta <= L.inner - slack) return;
    if (angle_between(t, vec2(0.0)) >= L.occlusion + slack) return;

    ivec2 lo = ivec2(L.lattice_min_x, L.lattice_min_y);
    ivec2 hi = ivec2(L.lattice_max_x, L.lattice_max_y);
    vec2 f = vec2(within) / float(d);
    vec4 rows[4];
    for (int j = 0; j < 4; ++j) {
        int y = clamp(anchor.y + (cell.y + j - 1) * d, lo.y, hi.y);
        vec4 v[4];
        for (int i = 0; i < 4; ++i) {
            int x = clamp(anchor.x + (cell.x + i - 1) * d, lo.x, hi.x);
            v[i] = imageLoad(layer_images, ivec3(x, y, L.image_layer));
        }
        rows[j] = cubic(v[0], v[1], v[2], v[3], f.x);
    }
    imageStore(layer_images, ivec3(p, L.image_layer), cubic(rows[0], rows[1], rows[2], rows[3], f.y));
}
