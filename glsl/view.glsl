// The eye's image as geometry, exactly as src/foveation/view.rs computes it: continuous pixel
// coordinates to tangent space (ty up) and angles between directions.
#ifndef FOVEA_VIEW_GLSL
#define FOVEA_VIEW_GLSL
#include "bindings.glsl"

// Tangent-space point of a continuous pixel position (pixel centres at +0.5).
vec2 pixel_tan(vec2 p) {
    vec2 uv = p / vec2(pc.width, pc.height);
    return vec2(mix(pc.cam_tan.x, pc.cam_tan.y, uv.x), mix(pc.cam_tan.z, pc.cam_tan.w, uv.y));
}

// Angle in radians between the directions of two tangent-space points; atan2 of the cross
// and dot products stays accurate for small angles, where acos does not.
float angle_between(vec2 a, vec2 b) {
    vec3 u = normalize(vec3(a, 1.0));
    vec3 v = normalize(vec3(b, 1.0));
    return atan(length(cross(u, v)), dot(u, v));
}

// Floor division for lattice coordinates that may be negative.
ivec2 floor_div(ivec2 a, int d) {
    return ivec2(floor(vec2(a) / float(d)));
}

#endif
