#version 460
// The display transform (src/render/display.rs, DisplayTransform::apply) on the GPU: OUTPUT's
// scene-referred radiance x 2^exposure, then clipped or Khronos PBR Neutral, into DISPLAY,
// which a window or a headset's swapchain shows (their blit encodes sRGB). A NaN or infinite
// pixel shows as black, as the PNG writer has it.
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH DisplayPush
#include "bindings.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;
layout(set = 0, binding = BINDING_DISPLAY, rgba32f) uniform writeonly image2D display_image;

// Khronos PBR Neutral (2024), as display.rs's pbr_neutral.
vec3 pbr_neutral(vec3 c) {
    const float F90 = 0.04;
    const float START = 0.8 - F90;
    const float DESATURATION = 0.15;
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 2.0 * F90 ? x - x * x / (4.0 * F90) : F90;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < START) return c;
    float d = 1.0 - START;
    float new_peak = 1.0 - d * d / (peak + d - START);
    float g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    return mix(c * (new_peak / peak), vec3(new_peak), g);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    vec3 c = imageLoad(out_image, p).rgb;
    bool finite = !any(isnan(c)) && !any(isinf(c));
    c = finite ? max(c * pc.scale, vec3(0.0)) : vec3(0.0);
    c = pc.tonemap == TONEMAP_PBR_NEUTRAL ? clamp(pbr_neutral(c), 0.0, 1.0) : min(c, vec3(1.0));
    imageStore(display_image, p, vec4(c, 1.0));
}
