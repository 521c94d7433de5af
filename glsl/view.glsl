// The eye's image as geometry, exactly as src/foveation/view.rs computes it: continuous pixel
// coordinates to tangent space (ty up) and angles between directions.
#ifndef FOVEA_VIEW_GLSL
#define FOVEA_VIEW_GLSL
#include "bindings.glsl"

// Tangent-space point of a continuous pixel position (pixel centres at +0.5).
vec2 pixel_tan(vec2 p) {
    vec2 uv = p / vec2(pc.eye.width, pc.eye.height);
    return vec2(mix(pc.cam.tan.x, pc.cam.tan.y, uv.x), mix(pc.cam.tan.z, pc.cam.tan.w, uv.y));
}

// Unit direction of a tangent-space point.
vec3 tan_direction(vec2 t) {
    return normalize(vec3(t, 1.0));
}

// Angle in radians between two unit directions (atan2 form, accurate for small angles).
float angle_of(vec3 u, vec3 v) {
    return atan(length(cross(u, v)), dot(u, v));
}

// Is the angle between unit directions u and v below the limit whose cosine is `cos_limit`?
// cos is decreasing on [0, pi], so one dot product answers it (GpuLayer's *_cos fields).
bool within_angle(vec3 u, vec3 v, float cos_limit) {
    return dot(u, v) > cos_limit;
}

// Index of this eye's pixel p in PIXELS (and every per-pixel buffer laid out like it): the
// eyes one after the other, rows of the eye's width.
uint eye_pixel_index(ivec2 p) {
    return (pc.eye.index * pc.eye.height + uint(p.y)) * pc.eye.width + uint(p.x);
}

// This eye's first layer in LAYERS, in the frame slot's set.
uint eye_layer_base() { return pc.eye.layer_base + pc.eye.index * pc.eye.layer_count; }

// Floor division for lattice coordinates that may be negative.
ivec2 floor_div(ivec2 a, int d) {
    return ivec2(floor(vec2(a) / float(d)));
}

#endif
