#version 460
// The lattice filter: between trace and resolve, one thread per traced lattice point of one
// eye (the trace's work list and indirect dispatch), so its cost follows the rays, not the
// pixels. A point of a layer that asks for it (GpuLayer.filter_mar, .filter_px) becomes a
// Gaussian-weighted mean of the traced points of its layer within two lattice steps, each tap
// counted only on the point's own surface (object and material, the angle between the
// normals, the relative difference in distance: the lattice surfaces the trace wrote for the
// history) and weighted down by its difference in luminance against the local noise (the
// standard deviation over the 3x3 points around, as denoise.comp estimates it; this keeps the
// points an edge crosses, mixes of both sides on one side's surface by their centres, from
// lending their mix to their neighbours). The Gaussian's width follows the eye's acuity: filter_mar times the minimum angle
// of resolution at the point's eccentricity from the gaze (Guenter et al. 2012: 0.022 deg per
// deg plus 1/48 deg), and at least filter_px pixels. So the periphery's noise becomes blur
// finer than the eye resolves there, and a blue-noise sampler's error (neighbouring lattice
// points are neighbouring sampler points) mostly cancels.
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

layout(local_size_x = TRACE_WORKGROUP_SIZE) in;

// The minimum angle of resolution against eccentricity (radians against radians): Guenter et
// al. 2012's fit, 0.022 deg per deg of eccentricity plus 1/48 deg at the centre (the host's
// copy, with tests: src/foveation/acuity.rs).
const float MAR_SLOPE = 0.022;
const float MAR_CENTRE = (1.0 / 48.0) * 3.14159265 / 180.0;
// Taps within this many lattice steps of the point, on each axis (a 5 x 5 window).
const int REACH = 2;
// Below this width (in lattice steps) every tap but the centre weighs under e^-8: copied
// (acuity.rs's MIN_FILTER_WIDTH).
const float MIN_WIDTH = 0.25;
// Edge-stopping strengths, as denoise.comp's.
const float NORMAL_POWER = 64.0;
const float LUMINANCE_SIGMA = 4.0;
const float DISTANCE_SIGMA = 0.02; // relative distance difference per pixel of tap distance

// The Gaussian's width at layer k's point at pixel p (direction u), in lattice steps.
float width_in_steps(uint k, ivec2 p, vec3 u) {
    vec4 tan_map = layers[k].pixel_tan;
    int spacing = layers[k].spacing;
    // One lattice step's angle here: the chord to the direction one step to the right
    // (the image's steps are square).
    vec3 next = tan_direction(tan_map.xy + vec2(p + ivec2(spacing, 0)) * tan_map.zw);
    float step_angle = max(length(next - u), 1e-9);
    float eccentricity = angle_of(u, layers[k].gaze.xyz);
    float mar = MAR_SLOPE * eccentricity + MAR_CENTRE;
    float by_acuity = layers[k].filter_mar * mar / step_angle;
    float by_pixels = layers[k].filter_px / float(spacing);
    return max(by_acuity, by_pixels);
}

// Was layer k's lattice point q traced this frame (the plan's own test)? The others hold
// stale values.
bool traced(uint k, ivec2 q, ivec2 box_lo, ivec2 box_hi, uint mask_words) {
    if (any(lessThan(q, box_lo)) || any(greaterThan(q, box_hi))) return false;
    return traced_point(k, lattice_pixel(k, q), mask_words);
}

void main() {
    uint thread = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * TRACE_WORKGROUP_SIZE)
                + gl_GlobalInvocationID.x;
    if (thread >= stats[STAT_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT]) return;
    uint item = work[pc.eye.index * pc.eye.work_stride + thread];
    uint k = eye_layer_base() + (item >> WORK_LAYER_SHIFT);
    uint entry = item & ((1u << WORK_LAYER_SHIFT) - 1u);
    vec4 centre = lattice[entry];
    if (layers[k].filter_mar <= 0.0 && layers[k].filter_px <= 0.0) {
        lattice_filtered[entry] = centre;
        return;
    }
    uint local = entry - layers[k].first;
    ivec2 ij = ivec2(layers[k].col_min + int(local % layers[k].cols), layers[k].row_min + int(local / layers[k].cols));
    ivec2 pixel = lattice_pixel(k, ij);
    vec3 u = tan_direction(layers[k].pixel_tan.xy + vec2(pixel) * layers[k].pixel_tan.zw);
    float width = width_in_steps(k, pixel, u);
    if (width < MIN_WIDTH) {
        lattice_filtered[entry] = centre;
        return;
    }
    uvec4 sp = lattice_surface[entry];
    float dp = uintBitsToFloat(sp.x);
    // A point that sees the sky: its rays that leave the scene see the environment itself,
    // without noise, so filtering would only blur the environment and the edges against it.
    if (dp < 0.0) {
        lattice_filtered[entry] = centre;
        return;
    }
    float falloff = -0.5 / (width * width);
    vec3 np = from_octahedral(unpackSnorm2x16(sp.y));
    float spacing = float(layers[k].spacing);
    ivec2 box_lo = ivec2(layers[k].box_i0, layers[k].box_j0);
    ivec2 box_hi = box_lo + ivec2(layers[k].box_cols, layers[k].box_rows) - 1;
    uint mask_words = visibility[0];

    // The local noise: the luminance's standard deviation over the traced 3x3 points around.
    float l_sum = 0.0;
    float l_sq = 0.0;
    float l_n = 0.0;
    for (int i = 0; i < 9; ++i) {
        ivec2 q = ij + ivec2(i % 3 - 1, i / 3 - 1);
        if (!traced(k, q, box_lo, box_hi, mask_words)) continue;
        float l = luminance(lattice[lattice_index(k, q)].rgb);
        l_sum += l;
        l_sq += l * l;
        l_n += 1.0;
    }
    float sigma = sqrt(max(l_sq / l_n - (l_sum / l_n) * (l_sum / l_n), 0.0));
    float lp = luminance(centre.rgb);

    vec3 sum = vec3(0.0);
    float weights = 0.0;
    float squares = 0.0;
    for (int dy = -REACH; dy <= REACH; ++dy) {
        for (int dx = -REACH; dx <= REACH; ++dx) {
            ivec2 q = ij + ivec2(dx, dy);
            if (!traced(k, q, box_lo, box_hi, mask_words)) continue;
            uint e = lattice_index(k, q);
            uvec4 sq = lattice_surface[e];
            if (sq.z != sp.z || sq.w != sp.w) continue; // another surface (or the sky)
            vec3 nq = from_octahedral(unpackSnorm2x16(sq.y));
            float dq = uintBitsToFloat(sq.x);
            float w = exp(falloff * float(dx * dx + dy * dy));
            w *= pow(max(dot(np, nq), 0.0), NORMAL_POWER);
            w *= exp(-abs(dp - dq) / (DISTANCE_SIGMA * dp * spacing * length(vec2(dx, dy)) + 1e-6));
            vec3 c = lattice[e].rgb;
            w *= exp(-abs(luminance(c) - lp) / (LUMINANCE_SIGMA * sigma + 1e-6));
            sum += w * c;
            weights += w;
            squares += w * w;
        }
    }
    // The centre tap always counts (weight 1), so weights >= 1.
    lattice_filtered[entry] = vec4(sum / weights, weights * weights / squares);
}
