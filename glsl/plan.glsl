// Which lattice points a layer traces this frame (thesis 3.2.1, decided per point on the GPU
// from the O(layers) numbers of GpuLayer), and where a lattice point's value is kept.
//
// A point is traced when its direction is inside the layer's region widened by its margin
// (the occlusion mask from the view axis, the outer radius and the inner edge from the gaze)
// and, behind a lens, when a pixel the lens shows needs it. src/foveation/plan.rs
// (`Regions::traced`) makes the same test with the same f32 operations in the same order;
// `precise` forbids fused multiply-adds here, so the CPU planner counts exactly the points
// this code traces (tests/foveation.rs holds the two counts equal).
#ifndef FOVEA_PLAN_GLSL
#define FOVEA_PLAN_GLSL
#include "bindings.glsl"
#include "view.glsl"

// Is pixel p's bit of VISIBILITY plane `plane` set? `words` is VISIBILITY[0], the words per
// plane, read once by the caller (0, no mask: every bit is).
bool visibility_bit(uint words, uint plane, ivec2 p) {
    if (words == 0u) return true;
    uint i = uint(p.y) * pc.eye.width + uint(p.x);
    return ((visibility[1u + plane * words + i / 32u] >> (i % 32u)) & 1u) != 0u;
}

// What decides which of a layer's lattice points are traced, read once from LAYERS.
struct TracedRegion {
    vec4 tan_map; // GpuLayer.pixel_tan
    vec3 gaze;
    vec4 cos; // GpuLayer.plan_cos
    uint mask_plane;
    uint mask_words; // VISIBILITY[0]
};

TracedRegion traced_region(uint k, uint mask_words) {
    TracedRegion r;
    r.tan_map = layers[k].pixel_tan;
    r.gaze = layers[k].gaze.xyz;
    r.cos = layers[k].plan_cos;
    r.mask_plane = layers[k].mask_plane;
    r.mask_words = mask_words;
    return r;
}

// Is the lattice point at pixel p (on the image) inside region r?
bool traced_in(TracedRegion r, ivec2 p) {
    precise float tx = r.tan_map.x + float(p.x) * r.tan_map.z;
    precise float ty = r.tan_map.y + float(p.y) * r.tan_map.w;
    // θ < limit ⇔ cos θ > cos limit; unnormalised dot products against cos·|t| need no
    // division and no trig.
    precise float norm = sqrt(tx * tx + ty * ty + 1.0);
    precise float to_gaze = tx * r.gaze.x + ty * r.gaze.y + r.gaze.z;
    precise float occlusion = r.cos.x * norm;
    precise float outer = r.cos.y * norm;
    precise float inner = r.cos.z * norm;
    return 1.0 > occlusion && to_gaze > outer && to_gaze <= inner
        && visibility_bit(r.mask_words, r.mask_plane, p);
}

// Does layer k (an index into LAYERS) trace its lattice point at pixel p (on the image)?
// `mask_words` is VISIBILITY[0].
bool traced_point(uint k, ivec2 p, uint mask_words) {
    return traced_in(traced_region(k, mask_words), p);
}

// Thread t of this eye's plan: a run of up to PLAN_RUN points of one row of one layer's box
// (rows after rows, layer after layer): its layer (an index into LAYERS), first lattice point
// and length. False past the last run.
bool plan_run(uint t, out uint k, out ivec2 ij, out uint n) {
    uint base = eye_layer_base();
    k = base;
    ij = ivec2(0);
    n = 0u;
    if (t >= layers[base].plan_runs) return false;
    while (k + 1u < base + pc.eye.layer_count && t >= layers[k + 1u].box_prefix) k++;
    uint cols = layers[k].box_cols;
    uint runs_per_row = (cols + PLAN_RUN - 1u) / PLAN_RUN;
    uint local = t - layers[k].box_prefix;
    uint first = (local % runs_per_row) * PLAN_RUN;
    ij = ivec2(layers[k].box_i0 + int(first), layers[k].box_j0 + int(local / runs_per_row));
    n = min(PLAN_RUN, cols - first);
    return true;
}

// The depth (0: innermost) of the layer shown in direction u of the eye whose layers start
// at LAYERS[base]: the innermost whose radius holds it. resolve.comp shows each pixel from
// this layer, and temporal.comp and denoise.comp pick by it what they read.
uint shown_depth(vec3 u, uint base) {
    vec3 gaze = layers[base].gaze.xyz;
    uint depth = 0u;
    while (depth + 1u < pc.eye.layer_count && !within_angle(u, gaze, layers[base + depth].resolve_cos.x)) depth++;
    return depth;
}

// The pixel of layer k's lattice point ij.
ivec2 lattice_pixel(uint k, ivec2 ij) {
    return ivec2(layers[k].anchor_x, layers[k].anchor_y) + ij * layers[k].spacing;
}

// Index into LATTICE of layer k's lattice point ij (inside the ray buffer's extent).
uint lattice_index(uint k, ivec2 ij) {
    return layers[k].first + uint(ij.y - layers[k].row_min) * layers[k].cols
         + uint(ij.x - layers[k].col_min);
}

// Layer k's lattice point of LATTICE entry `entry` (the inverse of lattice_index).
ivec2 lattice_point(uint k, uint entry) {
    uint local = entry - layers[k].first;
    uint cols = layers[k].cols;
    return ivec2(layers[k].col_min + int(local % cols), layers[k].row_min + int(local / cols));
}

// A work list's item (plan.comp's encoding): its layer k (an index into LAYERS) and its
// LATTICE entry.
void work_item(uint item, out uint k, out uint entry) {
    k = eye_layer_base() + (item >> WORK_LAYER_SHIFT);
    entry = item & ((1u << WORK_LAYER_SHIFT) - 1u);
}

// The first and last of layer k's lattice points on the image and in the buffer's extent
// (its box).
ivec2 box_lo(uint k) {
    return ivec2(layers[k].box_i0, layers[k].box_j0);
}

ivec2 box_hi(uint k) {
    return box_lo(k) + ivec2(layers[k].box_cols, layers[k].box_rows) - 1;
}

// Is lattice point ij in layer k's box?
bool in_box(uint k, ivec2 ij) {
    return all(greaterThanEqual(ij, box_lo(k))) && all(lessThanEqual(ij, box_hi(k)));
}

// Layer k's lattice point nearest pixel p, within the layer's box (temporal.comp takes a
// pixel's surface from it, denoise.comp its albedo).
ivec2 nearest_lattice_point(uint k, ivec2 p) {
    int spacing = layers[k].spacing;
    ivec2 rel = p - ivec2(layers[k].anchor_x, layers[k].anchor_y);
    return clamp(floor_div(rel + spacing / 2, spacing), box_lo(k), box_hi(k));
}

#endif
