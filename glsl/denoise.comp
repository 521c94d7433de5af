#version 460
// The periphery's denoiser: one iteration of an edge-aware a-trous wavelet filter (Dammertz
// et al. 2010, the spatial filter of SVGF), over the pixels of the layers that ask for it
// (GpuLayer.denoise iterations; a pixel whose layer asks for fewer is copied, and so is the
// sky). Iteration i spreads a 5x5 B3-spline kernel over taps 2^i pixels apart; a tap
// counts only on the same surface (object and material, the temporal pass's per-pixel
// surfaces), weighted down by the angle between the normals, the relative differences in
// distance and in albedo, and the difference in luminance against the local noise. The noise
// is SVGF's: each pixel's alpha carries the variance of its luminance (temporal.comp: a
// lattice point's, from a dense layer's history's own frames once it has a few, else from
// the 3x3 lattice points around, over the samples' worth in the pixel's history), smoothed
// over the 3x3 pixels around for the edge-stop, and each iteration writes its own output's
// variance (the taps' variances by their squared weights). So flat noisy regions are
// smoothed, edges between surfaces are not crossed, and what a long history has resolved is
// kept: the filter blurs only while history is short.
//
// A layer's denoise_mar limits the blur by the eye's acuity: iteration i runs at a pixel only
// while the filter's width after it (the B3 kernel's standard deviation is its tap spacing,
// so after iterations 0..i it is sqrt((4^(i+1) - 1) / 3) pixels: 1, 2.2, 4.6, 9.2) stays
// within denoise_mar minimum angles of resolution at the pixel's eccentricity (acuity.glsl).
// So the gaze stays sharp and the periphery is smoothed only as far as it cannot resolve.
//
// It filters the illumination: temporal.comp showed the frame divided by each pixel's albedo
// (its mean over the history, ALBEDO_BEFORE) and the last iteration multiplies it back
// (albedo.glsl), so textures stay sharp.
//
// DenoisePush says which iteration this is and whether it is the last. Iterations take turns
// between the frame's pixels and the denoiser's buffer: each reads one (DENOISE_INPUT) and
// writes the other (bound as DENOISE). The input and this frame's surfaces (SURFACE_TEXELS)
// are read through texel views, for lavapipe's sake (bindings.glsl).
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH DenoisePush
#include "plan.glsl"
#include "surface.glsl"
#include "colour.glsl"
#include "albedo.glsl"
#include "acuity.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

// Edge-stopping strengths (SVGF's defaults where it has them; the normals' power, 64, is
// power_64 below). The luminance's is the layer's (GpuLayer.denoise_sigma, 4 by default):
// tighter in a fovea keeps shading detail the eye resolves there.
const float DISTANCE_SIGMA = 0.02; // relative distance difference per pixel of tap spacing
const float LOG2_E = 1.44269504;
// A tap's weight falls by e for each ALBEDO_SIGMA its albedo differs from the centre's, relative
// to the larger, in the channel that differs most (see main). 0.125 scored best of 0.0625, 0.125,
// 0.25 and 0.5 on the textured room in motion (reports/tune-motion-window-lavapipe/albedo-weight/
// sigma/); looser spreads more of the texture's leftover, tighter filters less next to texels.
const float ALBEDO_SIGMA = 0.125;

uint pixel_index(ivec2 p) {
    return eye_pixel_index(p);
}

vec4 read_input(ivec2 p) {
    return uintBitsToFloat(texelFetch(denoise_input, int(pixel_index(p))));
}

// The surface at pixel p this frame (SURFACE_*: distance, normal, object, material).
uvec4 read_surface(ivec2 p) {
    return pixel_surface(pixel_index(p));
}

// n^64 by squaring (pow is exp(log) per tap, which lavapipe pays per lane).
float power_64(float n) {
    n *= n;
    n *= n;
    n *= n;
    n *= n;
    n *= n;
    return n * n;
}

// The filter's width, in pixels, after iterations 0..i (see above).
float width_after(uint i) {
    return sqrt((float(1u << (2u * i + 2u)) - 1.0) / 3.0);
}

// Whether iteration i keeps layer k's blur at pixel p (direction u) within its acuity limit.
bool within_acuity(uint k, ivec2 p, vec3 u, uint i) {
    float limit_mar = layers[k].denoise_mar;
    if (limit_mar <= 0.0) return true;
    uint base = eye_layer_base();
    vec3 right = tan_direction(layers[base].pixel_tan.xy + vec2(p + ivec2(1, 0)) * layers[base].pixel_tan.zw);
    return width_after(i) <= limit_mar * acuity_in_steps(u, right, layers[base].gaze.xyz);
}

// The pixel's albedo (the mean temporal keeps, which it divided the frame by), which the last
// iteration multiplies back.
vec3 pixel_albedo(ivec2 p) {
    return albedo_divisor(albedo_before[pixel_index(p)].albedo);
}

// The last iteration's output variance has no reader: the frame's pixels leave it with alpha
// 1, as resolve writes them, since the output image and the frame's read-back copy them whole
// (a swapchain that composites by alpha would show the variance).
void write_output(ivec2 p, vec4 c) {
    denoise_pixels[pixel_index(p)] = vec4(c.rgb, pc.last != 0u ? 1.0 : c.a);
}

// A pixel this iteration leaves as it is (its albedo multiplied back on the last).
void pass_through(ivec2 p, vec4 centre, vec3 albedo) {
    write_output(p, vec4(centre.rgb * albedo, centre.a));
}

bool on_image(ivec2 q) {
    return all(greaterThanEqual(q, ivec2(0))) && q.x < int(pc.eye.width) && q.y < int(pc.eye.height);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (!on_image(p)) return;
    vec4 centre = read_input(p);
    uint base = eye_layer_base();
    uint iteration = pc.iteration;
    vec3 u = tan_direction(layers[base].pixel_tan.xy + vec2(p) * layers[base].pixel_tan.zw);
    uint k = base + shown_depth(u, base);
    if (pc.eye.debug == DEBUG_LAYERS) { // the layer tints stay as resolve made them
        write_output(p, centre);
        return;
    }
    vec3 albedo = pc.last != 0u ? pixel_albedo(p) : vec3(1.0);
    if (iteration >= layers[k].denoise || !within_acuity(k, p, u, iteration)) {
        pass_through(p, centre, albedo);
        return;
    }
    uvec4 sp = read_surface(p);
    float dp = uintBitsToFloat(sp.x);
    // The sky, and pixels the lens hides (distance < 0), are copied too: no path reaches a
    // surface there, so there is no path noise to filter, only the environment seen
    // straight (a filter would blur its texture), and the taps of a surface never count
    // them. Around a small object (cornell at the Vive's field) that is most of the image.
    if (dp < 0.0) {
        pass_through(p, centre, albedo);
        return;
    }
    vec3 np = from_octahedral(unpackSnorm2x16(sp.y));

    // The local noise: the pixels' luminance variance (alpha), by a 3x3 binomial kernel.
    float variance = 0.0;
    for (int i = 0; i < 9; ++i) {
        ivec2 o = ivec2(i % 3 - 1, i / 3 - 1);
        ivec2 q = clamp(p + o, ivec2(0), ivec2(pc.eye.width, pc.eye.height) - 1);
        variance += read_input(q).a * float((2 - abs(o.x)) * (2 - abs(o.y))) / 16.0;
    }
    float sigma = sqrt(variance);
    float lp = luminance(centre.rgb);
    vec3 ap = pc.last != 0u ? albedo : pixel_albedo(p); // the last iteration read it above

    const float KERNEL[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);
    int step = 1 << iteration;
    // Each tap's falloffs in distance and luminance add in one exp2 (log2 units); the
    // distance's is per unit of the tap's distance in pixels.
    float by_distance = -LOG2_E / (DISTANCE_SIGMA * dp * float(step) + 1e-6);
    float by_luminance = -LOG2_E / (layers[k].denoise_sigma * sigma + 1e-6);
    const float by_albedo = -LOG2_E / ALBEDO_SIGMA;
    vec3 sum = vec3(0.0);
    float spread = 0.0; // the output's variance, times weights^2
    float weights = 0.0;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            ivec2 q = p + step * ivec2(dx, dy);
            if (!on_image(q)) continue;
            uvec4 sq = read_surface(q);
            if (sq.z != sp.z || sq.w != sp.w) continue; // another surface, or hidden
            vec4 tap = read_input(q);
            vec3 c = tap.rgb;
            float w = KERNEL[abs(dx)] * KERNEL[abs(dy)];
            float exponent = by_luminance * abs(luminance(c) - lp);
            vec3 nq = from_octahedral(unpackSnorm2x16(sq.y));
            float dq = uintBitsToFloat(sq.x);
            w *= power_64(max(dot(np, nq), 0.0));
            // Another albedo: the illumination filtered is the radiance over the history's
            // mean albedo, and next to a texel's edge in motion the two are resampled
            // differently (temporal.comp: the radiance bilinearly, the albedo sharpened and
            // clamped), so some of the texture is left in it there, which the wider
            // iterations spread over the texels around (a moving checkerboard's flat texels
            // kept 0.78 of the plain history's error without this weight, 0.32 with it:
            // tests/textures.rs).
            vec3 aq = pixel_albedo(q);
            vec3 apart = abs(aq - ap) / max(aq, ap);
            exponent += by_albedo * max(apart.r, max(apart.g, apart.b));
            exponent += by_distance * abs(dp - dq) * inversesqrt(max(float(dx * dx + dy * dy), 1.0));
            w *= exp2(exponent);
            sum += w * c;
            spread += w * w * tap.a;
            weights += w;
        }
    }
    // The centre tap always counts (weight 9/64), so weights > 0.
    write_output(p, vec4(sum / weights * albedo, spread / (weights * weights)));
}
