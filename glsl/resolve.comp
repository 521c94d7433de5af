#version 460
// The resolve pass (thesis 3.2.3-3.2.4): every pixel of one eye is computed once, from the
// lattice values the trace pass wrote. A pixel takes the innermost layer whose radius
// contains it, F1, and inside that radius's blend band mixes in the next layer out, F0, by
// eq. 3.18: (1 - v) F0 + v F1, v rising linearly from 0 at the radius to 1 one band-width
// inside. A layer's value at a pixel is its lattice value there, or between lattice points
// the bicubic Catmull-Rom value (eq. 3.17, fig. 3.10) of the 4x4 points around it, taps
// clamped to the points on the image; the plan traces a margin of two lattice steps (plus
// slack) around everything shown, so every tap read was traced this frame. Each invocation
// resolves a run of PIXELS_PER_INVOCATION pixels of one row. Where v is 1 and
// the pixel is a lattice point the output is the traced value itself (the cubic at t = 0 is
// its middle value exactly), so the fovea of a foveated frame is bit-identical to a regular
// frame.
//
// Shaped for SIMD CPUs (lavapipe) as much as for GPUs: on lavapipe an `if` whose condition
// differs between lanes runs its body for every lane (masked), while a loop runs until its
// last lane leaves and a branch on a subgroup vote is a real branch. So the common case —
// a subgroup whose runs each lie inside one layer, away from blend bands and the occlusion
// edge — is decided once per run by a vote and walks lattice columns in a loop: one
// vertical cubic per column, one horizontal cubic per pixel, no per-pixel direction, no
// per-pixel layer test. A subgroup's lanes are 8 runs stacked vertically (16 x 8 pixels),
// so few subgroups touch an edge; those take the per-pixel path. Outside the occlusion mask
// and where the headset's lens hides the pixel (never traced) the pixel is black, and no
// layer is read.
//
// The pixels go to a storage buffer (PIXELS), not the frame image: on lavapipe an imageStore
// per pixel cost about 31 ms per 1440x1600 eye against about 16 for a buffer store; whoever needs
// an image gets a copy after the frame (render/passes.rs, output_image).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_vote : require
#define PASS_PUSH EyePush
#include "plan.glsl"
#include "view.glsl"
#include "colour.glsl"
#include "lattice_texels.glsl"

// The frame's pixel p of this eye (PIXELS: eye after eye, rows of pc.eye.width).
void store_pixel(ivec2 p, vec3 c) {
    pixels[eye_pixel_index(p)] = vec4(c, 1.0);
}
layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

// Overlay colours of the layers, innermost first (thesis fig. 3.5's role).
const vec3 LAYER_COLOURS[8] = vec3[8](vec3(1.0, 0.25, 0.2), vec3(1.0, 0.7, 0.1), vec3(0.3, 0.9, 0.3),
                                      vec3(0.25, 0.5, 1.0), vec3(0.7, 0.35, 1.0), vec3(0.2, 0.9, 0.9),
                                      vec3(0.9, 0.9, 0.9), vec3(0.6, 0.6, 0.6));

// Eq. 3.17: the value between v1 (t = 0) and v2 (t = 1); the operations of
// src/foveation/catmull_rom.rs.
vec3 cubic(vec3 v0, vec3 v1, vec3 v2, vec3 v3, float t) {
    vec3 a = -0.5 * v0 + 1.5 * v1 - 1.5 * v2 + 0.5 * v3;
    vec3 b = v0 - 2.5 * v1 + 2.0 * v2 - 0.5 * v3;
    vec3 c = -0.5 * v0 + 0.5 * v2;
    return ((a * t + b) * t + c) * t + v1;
}

// One layer's Catmull-Rom columns around the pixels of a run: the bicubic is separable, so a
// lattice column's vertical cubic at this row (ty) is shared by every pixel of the run whose
// horizontal taps include it. A run of 16 pixels at spacing 4 loads 5-6 columns (about 20
// lattice values) instead of 16 per pixel. The layer's parameters are read once per run:
// on lavapipe every buffer read per pixel costs about as much as the arithmetic.
struct Columns {
    uint k; // the layer (an index into LAYERS), NO_LAYER before the first use
    ivec2 anchor;
    int d;
    float inv_d;
    ivec2 lo; // the layer's lattice points on the image (taps clamp to them)
    ivec2 hi;
    ivec2 extent_min; // LATTICE[first + (j - extent_min.y) * cols + (i - extent_min.x)]
    uint first;
    uint cols;
    int cy; // the lattice row at or above this pixel row, and the row's fraction of a step
    float ty;
    int cx; // col[1] is lattice column cx
    vec3 col[4];
};

// Starts using layer k's columns on pixel row y.
void use_layer(inout Columns w, uint k, int y) {
    w.k = k;
    w.anchor = ivec2(layers[k].anchor_x, layers[k].anchor_y);
    w.d = layers[k].spacing;
    w.inv_d = 1.0 / float(w.d);
    w.lo = ivec2(layers[k].box_i0, layers[k].box_j0);
    w.hi = w.lo + ivec2(layers[k].box_cols, layers[k].box_rows) - 1;
    w.extent_min = ivec2(layers[k].col_min, layers[k].row_min);
    w.first = layers[k].first;
    w.cols = layers[k].cols;
    w.cy = floor_div(ivec2(0, y - w.anchor.y), w.d).y;
    int within_y = y - w.anchor.y - w.cy * w.d;
    w.ty = float(within_y) / float(w.d);
    w.cx = -0x40000000; // no column loaded
}

// The layer's lattice value at point ij, clamped to its points on the image.
vec3 tap(Columns w, ivec2 ij) {
    ivec2 c = clamp(ij, w.lo, w.hi) - w.extent_min;
    return lattice_texel(w.first + uint(c.y) * w.cols + uint(c.x)).rgb;
}

// Lattice column c's vertical cubic at this row (on a lattice row, ty = 0, its value there:
// the cubic at 0 is its second value exactly, so no branch, which lavapipe would run anyway).
vec3 column(Columns w, int c) {
    return cubic(tap(w, ivec2(c, w.cy - 1)), tap(w, ivec2(c, w.cy)), tap(w, ivec2(c, w.cy + 1)),
                 tap(w, ivec2(c, w.cy + 2)), w.ty);
}

// Loads the four columns around lattice column cx (col[1] is cx).
void load_columns(inout Columns w, int cx) {
    for (int i = 0; i < 4; ++i) w.col[i] = column(w, cx - 1 + i);
    w.cx = cx;
}

// Moves the window one lattice column right: one new column's vertical cubic.
void next_column(inout Columns w) {
    w.col[0] = w.col[1];
    w.col[1] = w.col[2];
    w.col[2] = w.col[3];
    w.col[3] = column(w, w.cx + 3);
    w.cx++;
}

// Layer k's value at pixel p (on row y of the run), through the run's columns w of that
// layer. At a lattice point the cubic at t = 0 returns the traced value exactly:
// bit-identical to a regular frame.
vec3 layer_value(inout Columns w, uint k, ivec2 p) {
    if (w.k != k) use_layer(w, k, p.y);
    int rel = p.x - w.anchor.x;
    // floor(rel / d) without an integer division (scalarised on SIMD CPUs), corrected for
    // the reciprocal's rounding.
    int cx = int(floor(float(rel) * w.inv_d));
    int tx = rel - cx * w.d;
    if (tx < 0) {
        cx--;
        tx += w.d;
    } else if (tx >= w.d) {
        cx++;
        tx -= w.d;
    }
    if (cx == w.cx + 1) {
        next_column(w);
    } else if (cx != w.cx) {
        load_columns(w, cx);
    }
    return cubic(w.col[0], w.col[1], w.col[2], w.col[3], float(tx) * w.inv_d);
}

// A layer's value as shown: itself, or tinted by its layer in the layers debug view.
vec3 tint(vec3 c, uint depth) {
    if (pc.eye.debug == DEBUG_LAYERS) {
        return LAYER_COLOURS[min(depth, 7u)] * (0.3 + 0.7 * clamp(luminance(c), 0.0, 1.0));
    }
    return c;
}

vec3 shown(inout Columns w, uint k, uint depth, ivec2 p) {
    return tint(layer_value(w, k, p), depth);
}

// Pixels [x0, x1) of row y, all inside layer k (the eye's layer `depth`) with blend weight 1:
// the loop walks the layer's lattice columns; a column's vertical cubic is computed once and
// used by the d pixels after it.
void resolve_run_in_layer(uint k, uint depth, int x0, int x1, int y, uint mask_words, uint lens_plane) {
    Columns w;
    use_layer(w, k, y);
    int cx = floor_div(ivec2(x0 - w.anchor.x, 0), w.d).x;
    int tx = x0 - w.anchor.x - cx * w.d; // pixel x0 is tx pixels right of column cx
    load_columns(w, cx);
    int x = x0;
    while (x < x1) {
        // At least one pixel per column: a corrupt spacing (0) must not stall the loop.
        for (int end = min(x1, x + max(w.d - tx, 1)); x < end; ++x, ++tx) {
            ivec2 p = ivec2(x, y);
            vec3 c = tint(cubic(w.col[0], w.col[1], w.col[2], w.col[3], float(tx) * w.inv_d), depth);
            if (!visibility_bit(mask_words, lens_plane, p)) c = vec3(0.0);
            store_pixel(p, c);
        }
        tx = 0;
        next_column(w);
    }
}

// Half the angle a run of n pixels spans from its middle: the pixels' tangent-space points
// lie within c = |step| (n - 1) / 2 of the middle's, and a point's direction is its tangent
// point (t, 1) projected onto the unit sphere, a projection that never lengthens distances
// (the nearest-point map onto the unit ball), so the chord between two directions is at most
// c and the angle at most 2 asin(c / 2).
float run_half_angle(float tan_step, int n) {
    float c = abs(tan_step) * 0.5 * float(n - 1);
    return 2.0 * asin(min(0.5 * c, 1.0));
}

// A margin (radians) for the rounding of the per-run angles against the per-pixel cosine
// tests: a run this close to an edge takes the per-pixel path.
const float RUN_MARGIN = 1.0e-3;

// The eye's layer every pixel of the run [x0, x1) of row y lies in, away from its blend band
// and the occlusion edge, or pc.eye.layer_count when the run touches an edge or a band.
uint run_layer(int x0, int x1, int y, vec3 gaze, float band, float cos_occlusion, vec4 tan_map, vec3 limits[MAX_LAYERS]) {
    vec3 middle = tan_direction(tan_map.xy + vec2(0.5 * float(x0 + x1 - 1), float(y)) * tan_map.zw);
    float spread = run_half_angle(tan_map.z, x1 - x0) + RUN_MARGIN;
    if (cos_occlusion >= -1.0 && angle_of(middle, vec3(0.0, 0.0, 1.0)) + spread >= acos(min(cos_occlusion, 1.0))) {
        return pc.eye.layer_count;
    }
    float theta = angle_of(middle, gaze);
    float inside = -NO_LIMIT; // the radius of the layer inside the one tested
    for (uint depth = 0u; depth < pc.eye.layer_count; ++depth) {
        float pure_edge = depth + 1u == pc.eye.layer_count ? NO_LIMIT : limits[depth].z - max(band, 0.0);
        if (theta - spread > inside && theta + spread < pure_edge) return depth;
        inside = limits[depth].z;
    }
    return pc.eye.layer_count;
}

void main() {
    uint base = eye_layer_base();
    // Per-eye values, the same for every pixel, read once per run.
    vec3 gaze = layers[base].gaze.xyz;
    float band = layers[base].gaze.w;
    float cos_occlusion = layers[base].resolve_cos.z;
    vec4 tan_map = layers[base].pixel_tan;
    vec3 limits[MAX_LAYERS]; // per layer: cos radius, cos (radius - band), radius
    for (uint depth = 0u; depth < pc.eye.layer_count; ++depth) {
        limits[depth] = vec3(layers[base + depth].resolve_cos.xy, layers[base + depth].outer);
    }
    uint lens_plane = pc.eye.index * (pc.eye.layer_count + 1u); // the eye's shown pixels
    uint mask_words = visibility[0];
    // The workgroup's 8 x 8 runs (128 x 8 pixels), numbered so that consecutive invocations
    // (a subgroup's lanes) are runs of consecutive rows.
    uint lane = gl_LocalInvocationIndex;
    int y = int(gl_WorkGroupID.y * WORKGROUP_SIZE_Y + lane % WORKGROUP_SIZE_Y);
    int x0 = int(gl_WorkGroupID.x * WORKGROUP_SIZE_X + lane / WORKGROUP_SIZE_Y) * PIXELS_PER_INVOCATION;
    int x1 = min(x0 + PIXELS_PER_INVOCATION, int(pc.eye.width));
    if (y >= int(pc.eye.height) || x0 >= x1) return;
    uint depth_of_run = run_layer(x0, x1, y, gaze, band, cos_occlusion, tan_map, limits);
    if (subgroupAll(depth_of_run < pc.eye.layer_count)) {
        resolve_run_in_layer(base + depth_of_run, depth_of_run, x0, x1, y, mask_words, lens_plane);
        return;
    }
    // Columns of the pixel's layer and of the next one out (blend bands).
    Columns inner;
    Columns outer;
    inner.k = NO_LAYER;
    outer.k = NO_LAYER;
    for (int x = x0; x < x1; ++x) {
        ivec2 p = ivec2(x, y);
        vec3 u = tan_direction(tan_map.xy + vec2(p) * tan_map.zw);
        if (!within_angle(u, vec3(0.0, 0.0, 1.0), cos_occlusion) || !visibility_bit(mask_words, lens_plane, p)) {
            store_pixel(p, vec3(0.0));
            continue;
        }
        // The innermost layer whose radius contains the pixel (cosine tests, no trig): the
        // choice the temporal and denoise passes make too.
        uint depth = shown_depth(u, base);
        // The blend weight needs the angle itself, but only inside the band.
        float v = 1.0;
        if (band > 0.0 && !within_angle(u, gaze, limits[depth].y)) {
            v = clamp((limits[depth].z - angle_of(u, gaze)) / band, 0.0, 1.0);
        }
        vec3 c = shown(inner, base + depth, depth, p);
        if (v < 1.0 && depth + 1u < pc.eye.layer_count) {
            c = mix(shown(outer, base + depth + 1u, depth + 1u, p), c, v);
        }
        if (pc.eye.debug == DEBUG_LAYERS && v < 1.0) {
            c *= 0.35 + 0.65 * abs(2.0 * v - 1.0); // dark blend bands, as in the thesis' fig. 3.5
        }
        store_pixel(p, c);
    }
}
