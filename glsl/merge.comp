#version 460
// The merge pass (thesis 3.2.4): each pixel takes the innermost layer whose radius contains
// it, F1, and inside that radius's blend band mixes in the next layer out, F0, by eq. 3.18:
// (1 - v) F0 + v F1 with v rising linearly from 0 at the radius to 1 one band-width inside.
// Where v is 1 the pixel is F1 exactly (no arithmetic), so the fovea of a foveated frame is
// bit-identical to a regular frame. Outside the occlusion mask, and where the headset's lens
// hides the pixel (its visibility mask: never traced), the pixel is black.
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

// Overlay colours of the layers, innermost first (thesis fig. 3.5's role).
const vec3 LAYER_COLOURS[8] = vec3[8](vec3(1.0, 0.25, 0.2), vec3(1.0, 0.7, 0.1), vec3(0.3, 0.9, 0.3),
                                      vec3(0.25, 0.5, 1.0), vec3(0.7, 0.35, 1.0), vec3(0.2, 0.9, 0.9),
                                      vec3(0.9, 0.9, 0.9), vec3(0.6, 0.6, 0.6));

vec3 layer_value(uint image_layer, ivec2 p, uint k) {
    vec3 c = imageLoad(layer_images, ivec3(p, image_layer)).rgb;
    if (pc.debug == DEBUG_LAYERS) {
        float luminance = dot(c, vec3(0.2126, 0.7152, 0.0722));
        return LAYER_COLOURS[min(k, 7u)] * (0.3 + 0.7 * clamp(luminance, 0.0, 1.0));
    }
    return c;
}

// Does the lens show pixel p of this eye? (No mask: every pixel is shown.)
bool lens_shows(ivec2 p) {
    uint words_per_eye = visibility[0];
    if (words_per_eye == 0u) return true;
    uint i = uint(p.y) * pc.width + uint(p.x);
    return ((visibility[1u + pc.eye * words_per_eye + i / 32u] >> (i % 32u)) & 1u) != 0u;
}

void merge_pixel(ivec2 p, uint base, vec3 gaze, float band, float cos_occlusion) {
    ivec2 out_pixel = ivec2(p.x + int(pc.eye * pc.width), p.y);
    vec3 u = tan_direction(pixel_tan(vec2(p) + 0.5));
    if (!within_angle(u, vec3(0.0, 0.0, 1.0), cos_occlusion) || !lens_shows(p)) {
        imageStore(out_image, out_pixel, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    // The innermost layer whose radius contains the pixel (cosine tests, no trig).
    uint k = 0u;
    while (k + 1u < pc.layer_count && !within_angle(u, gaze, layers[base + k].merge_cos.x)) k++;
    // The blend weight needs the angle itself, but only inside the band.
    float v = 1.0;
    if (band > 0.0 && !within_angle(u, gaze, layers[base + k].merge_cos.y)) {
        v = clamp((layers[base + k].outer - angle_of(u, gaze)) / band, 0.0, 1.0);
    }
    vec3 c = layer_value(layers[base + k].image_layer, p, k);
    if (v < 1.0 && k + 1u < pc.layer_count) {
        c = mix(layer_value(layers[base + k + 1u].image_layer, p, k + 1u), c, v);
    }
    if (pc.debug == DEBUG_LAYERS && v < 1.0) {
        c *= 0.35 + 0.65 * abs(2.0 * v - 1.0); // dark blend bands, as in the thesis' fig. 3.5
    }
    imageStore(out_image, out_pixel, vec4(c, 1.0));
}

void main() {
    uint base = pc.eye * pc.layer_count;
    // Per-eye values, the same for every pixel: read once per invocation.
    vec3 gaze = tan_direction(layers[base].gaze.xy);
    float band = layers[base].gaze.w;
    float cos_occlusion = layers[base].merge_cos.z;
    int y = int(gl_GlobalInvocationID.y);
    int x0 = int(gl_WorkGroupID.x * gl_WorkGroupSize.x) * PIXELS_PER_INVOCATION + int(gl_LocalInvocationID.x);
    if (y >= int(pc.height)) return;
    for (int i = 0; i < PIXELS_PER_INVOCATION; ++i) {
        int x = x0 + i * int(gl_WorkGroupSize.x);
        if (x < int(pc.width)) merge_pixel(ivec2(x, y), base, gaze, band, cos_occlusion);
    }
}
