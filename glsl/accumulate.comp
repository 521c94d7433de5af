#version 460
// Progressive refinement and the viewer's debug views, one eye per dispatch. Each pixel of
// OUTPUT (the frame just rendered) is added to a running mean in LAYER_IMAGES layer pc.mean_layer:
// after n frames the mean is m_n = m_{n-1} + (x_n - m_{n-1}) / n, which stays in range for any
// n (a sum could overflow for the brightest emitters). Frame n is rendered with seed + n, so
// the mean of N frames of s samples is an estimate with N*s samples per pixel. Then OUTPUT is
// overwritten with what the viewer shows (pc.eye.debug, ACCUM_SHOW_*), so presenting and
// screenshots read one image.
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH AccumulatePush
#include "view.glsl"
#include "colour.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

// Turbo (Mikhailov 2019, Google's polynomial fit): a perceptually ordered rainbow, blue to
// dark red. Returns display (sRGB-encoded) values.
vec3 turbo(float x) {
    const vec4 r4 = vec4(0.13572138, 4.61539260, -42.66032258, 132.13108234);
    const vec4 g4 = vec4(0.09140261, 2.19418839, 4.84296658, -14.18503333);
    const vec4 b4 = vec4(0.10667330, 12.64194608, -60.58204836, 110.36276771);
    const vec2 r2 = vec2(-152.94239396, 59.28637943);
    const vec2 g2 = vec2(4.27729857, 2.82956604);
    const vec2 b2 = vec2(-89.90310912, 27.34824973);
    x = clamp(x, 0.0, 1.0);
    vec4 v4 = vec4(1.0, x, x * x, x * x * x);
    vec2 v2 = v4.zw * v4.z;
    return clamp(vec3(dot(v4, r4) + dot(v2, r2), dot(v4, g4) + dot(v2, g2), dot(v4, b4) + dot(v2, b2)),
                 0.0, 1.0);
}

// Camera samples that went into pixel p of this eye over `frames` frames: the samples per
// pixel of the innermost layer containing it, spp / spacing^2 (a layer traces one target
// pixel in spacing x spacing), as resolve.comp picks layers. 0 outside the occlusion mask.
float samples_per_pixel(ivec2 p, float frames) {
    uint base = eye_layer_base();
    vec3 u = tan_direction(pixel_tan(vec2(p) + 0.5));
    if (!within_angle(u, vec3(0.0, 0.0, 1.0), layers[base].resolve_cos.z)) return 0.0;
    vec3 gaze = layers[base].gaze.xyz;
    uint k = 0u;
    while (k + 1u < pc.eye.layer_count && !within_angle(u, gaze, layers[base + k].resolve_cos.x)) k++;
    float spacing = float(layers[base + k].spacing);
    return frames * float(layers[base + k].spp) / (spacing * spacing);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.eye.width) || p.y >= int(pc.eye.height)) return;
    ivec2 q = ivec2(p.x + int(pc.eye.index * pc.eye.width), p.y); // the pixel in the side-by-side images
    vec3 frame = imageLoad(out_image, q).rgb;
    uint n = pc.frames_before;
    vec3 mean = frame;
    if (n > 0u) {
        vec3 previous = imageLoad(layer_images, ivec3(q, pc.mean_layer)).rgb;
        mean = previous + (frame - previous) / float(n + 1u);
    }
    imageStore(layer_images, ivec3(q, pc.mean_layer), vec4(mean, 1.0));

    vec3 shown;
    if (pc.eye.debug == ACCUM_SHOW_NOTHING) {
        return;
    } else if (pc.eye.debug == ACCUM_SHOW_DIFF) {
        vec3 other = imageLoad(layer_images, ivec3(q, ACCUM_LAYER_MAIN + ACCUM_LAYER_REGULAR - pc.mean_layer)).rgb;
        shown = abs(mean - other) * float(ACCUM_DIFF_GAIN);
    } else if (pc.eye.debug == ACCUM_SHOW_HEAT) {
        float spp = samples_per_pixel(p, float(n + 1u));
        float range = float(ACCUM_HEAT_LOG2_MAX - ACCUM_HEAT_LOG2_MIN);
        vec3 colour = spp > 0.0 ? turbo((log2(spp) - float(ACCUM_HEAT_LOG2_MIN)) / range) : vec3(0.0);
        // The image's luminance shows through faintly, to see where in the scene a colour is.
        shown = pow(colour, vec3(2.2)) * (0.6 + 0.4 * clamp(luminance(mean), 0.0, 1.0));
    } else {
        shown = mean;
    }
    imageStore(out_image, q, vec4(shown, 1.0));
}
