#version 460
// The lattice filter: between trace and resolve, one thread per traced lattice point of one
// eye (the trace's work list and indirect dispatch), so its cost follows the rays, not the
// pixels. A point of a layer that asks for it (GpuLayer.filter_mar, .filter_px) becomes a
// Gaussian-weighted mean of the traced points of its layer within two lattice steps, each tap
// counted only on the point's own surface (object and material, the angle between the
// normals, the relative difference in distance: the lattice surfaces the trace wrote for the
// history) and weighted down by its difference in luminance against the local noise (the
// standard deviation over the 3x3 points around, as SVGF estimates it without history: the
// filter smooths this frame's points, which have none; this keeps the points an edge
// crosses, mixes of both sides on one side's surface by their centres, from lending their
// mix to their neighbours). The Gaussian's width follows the eye's acuity:
// filter_mar times the minimum angle of resolution at the point's eccentricity from the gaze
// (Guenter et al. 2012: 0.022 deg per deg plus 1/48 deg), and at least filter_px pixels. So
// the periphery's noise becomes blur finer than the eye resolves there, and a blue-noise
// sampler's error (neighbouring lattice points are neighbouring sampler points) mostly
// cancels.
//
// Resolve reads what this writes (LATTICE_FILTERED, bound as its LATTICE_TEXELS) in place of
// the traced values; the temporal pass still adds the traced values themselves to the
// history, so the history converges to the unbiased image. The value's alpha is the number
// of points the mean is worth, (sum w)^2 / sum w^2 (the variance cut of a weighted mean of
// independent values): the temporal pass weighs resolve's estimate by it against the
// pixel's own history. A point whose width is under a quarter of a lattice step (the fovea,
// or a layer that asks for none), and a point that sees the sky, is copied as traced, bit
// for bit, worth 1.
#extension GL_GOOGLE_include_directive : require
#define WRITES_LATTICE_FILTERED
#define PASS_PUSH EyePush
#include "plan.glsl"
#include "view.glsl"
#include "surface.glsl"
#include "colour.glsl"
#include "acuity.glsl"
#include "lattice_texels.glsl"

layout(local_size_x = TRACE_WORKGROUP_SIZE) in;

// Taps within this many lattice steps of the point, on each axis (a 5 x 5 window).
const int REACH = 2;
// Below this width (in lattice steps) every tap but the centre weighs under e^-8: copied
// (acuity.rs's MIN_FILTER_WIDTH).
const float MIN_WIDTH = 0.25;
// Edge-stopping strengths, as denoise.comp's (its normal power, 64, is power_64 below).
const float LUMINANCE_SIGMA = 4.0;
const float DISTANCE_SIGMA = 0.02; // relative distance difference per pixel of tap distance
const float LOG2_E = 1.44269504;

// Layer k's lattice as the filter walks it, read once from LAYERS (on lavapipe every buffer
// read per tap costs about as much as the arithmetic).
struct Lattice {
    TracedRegion region;
    ivec2 anchor;
    int spacing;
    ivec2 box_lo; // the points on the image
    ivec2 box_hi;
    ivec2 extent_min; // LATTICE[first + (j - extent_min.y) * cols + (i - extent_min.x)]
    uint first;
    uint cols;
};

Lattice lattice_of(uint k) {
    Lattice l;
    l.region = traced_region(k, visibility[0]);
    l.anchor = ivec2(layers[k].anchor_x, layers[k].anchor_y);
    l.spacing = layers[k].spacing;
    l.box_lo = box_lo(k);
    l.box_hi = box_hi(k);
    l.extent_min = ivec2(layers[k].col_min, layers[k].row_min);
    l.first = layers[k].first;
    l.cols = layers[k].cols;
    return l;
}

// The Gaussian's width at layer k's point at pixel p (direction u) of lattice l, in lattice
// steps.
float width_in_steps(Lattice l, uint k, ivec2 p, vec3 u) {
    vec4 tan_map = l.region.tan_map;
    // The direction one lattice step to the right.
    vec3 next = tan_direction(tan_map.xy + vec2(p + ivec2(l.spacing, 0)) * tan_map.zw);
    float by_acuity = layers[k].filter_mar * acuity_in_steps(u, next, l.region.gaze);
    float by_pixels = layers[k].filter_px / float(l.spacing);
    return max(by_acuity, by_pixels);
}

// Was point q traced this frame (the plan's own test)? The others hold stale values.
bool traced(Lattice l, ivec2 q) {
    if (any(lessThan(q, l.box_lo)) || any(greaterThan(q, l.box_hi))) return false;
    return traced_in(l.region, l.anchor + q * l.spacing);
}

uint index_of(Lattice l, ivec2 q) {
    ivec2 c = q - l.extent_min;
    return l.first + uint(c.y) * l.cols + uint(c.x);
}

// Point q's traced value (through the texel view: one vector load on lavapipe).
vec3 value_at(Lattice l, ivec2 q) {
    return lattice_texel(index_of(l, q)).rgb;
}

// n^64 by squaring (pow is exp(log) per tap).
float power_64(float n) {
    n *= n;
    n *= n;
    n *= n;
    n *= n;
    n *= n;
    return n * n;
}

void main() {
    uint thread = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * TRACE_WORKGROUP_SIZE)
                + gl_GlobalInvocationID.x;
    if (thread >= stats[STAT_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT]) return;
    uint item = work[pc.eye.index * pc.eye.work_stride + thread];
    if (item == WORK_EMPTY) return; // a slot that pads the plan's reservation
    uint k;
    uint entry;
    work_item(item, k, entry);
    if ((thread & (layers[k].lanes - 1u)) != 0u) return; // a point's later trace lanes
    vec4 centre = lattice_texel(entry);
    if (layers[k].filter_mar <= 0.0 && layers[k].filter_px <= 0.0) {
        lattice_filtered[entry] = centre;
        return;
    }
    Lattice l = lattice_of(k);
    uint local = entry - l.first;
    ivec2 ij = l.extent_min + ivec2(local % l.cols, local / l.cols);
    ivec2 pixel = l.anchor + ij * l.spacing;
    vec3 u = tan_direction(l.region.tan_map.xy + vec2(pixel) * l.region.tan_map.zw);
    float width = width_in_steps(l, k, pixel, u);
    uvec4 sp = lattice_surface_at(entry);
    float dp = uintBitsToFloat(sp.x);
    // A point that sees the sky is copied too: its rays that leave the scene see the
    // environment itself, without noise, so filtering would only blur the environment and
    // the edges against it.
    if (width < MIN_WIDTH || dp < 0.0) {
        lattice_filtered[entry] = centre;
        return;
    }
    vec3 np = from_octahedral(unpackSnorm2x16(sp.y));

    // The local noise: the luminance's standard deviation over the traced 3x3 points around.
    float l_sum = 0.0;
    float l_sq = 0.0;
    float l_n = 0.0;
    for (int i = 0; i < 9; ++i) {
        ivec2 q = ij + ivec2(i % 3 - 1, i / 3 - 1);
        if (!traced(l, q)) continue;
        float y = luminance(value_at(l, q));
        l_sum += y;
        l_sq += y * y;
        l_n += 1.0;
    }
    float sigma = sqrt(max(l_sq / l_n - (l_sum / l_n) * (l_sum / l_n), 0.0));
    float lp = luminance(centre.rgb);

    // Each tap's weight is one exponential of the sum of its falloffs (in log2 units: the
    // Gaussian, the distance and the luminance) times the normals' agreement.
    float gauss = -0.5 * LOG2_E / (width * width);
    float by_distance = -LOG2_E / (DISTANCE_SIGMA * dp * float(l.spacing));
    float by_luminance = -LOG2_E / (LUMINANCE_SIGMA * sigma + 1e-6);
    vec3 sum = vec3(0.0);
    float weights = 0.0;
    float squares = 0.0;
    for (int dy = -REACH; dy <= REACH; ++dy) {
        for (int dx = -REACH; dx <= REACH; ++dx) {
            ivec2 q = ij + ivec2(dx, dy);
            if (!traced(l, q)) continue;
            uint e = index_of(l, q);
            uvec4 sq = lattice_surface_at(e);
            if (sq.z != sp.z || sq.w != sp.w) continue; // another surface (or the sky)
            vec3 nq = from_octahedral(unpackSnorm2x16(sq.y));
            float dq = uintBitsToFloat(sq.x);
            vec3 c = value_at(l, q);
            float r2 = float(dx * dx + dy * dy);
            float exponent = gauss * r2 + by_distance * abs(dp - dq) * inversesqrt(max(r2, 1.0))
                           + by_luminance * abs(luminance(c) - lp);
            float w = exp2(exponent) * power_64(max(dot(np, nq), 0.0));
            sum += w * c;
            weights += w;
            squares += w * w;
        }
    }
    // The centre tap always counts (weight 1), so weights >= 1.
    lattice_filtered[entry] = vec4(sum / weights, weights * weights / squares);
}
