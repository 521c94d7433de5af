// The HDR environment (BINDING_ENVIRONMENT, src/scene/env_map.rs): its radiance by direction,
// bilinear between texels, and next-event estimation's choice of directions from it: a texel
// in proportion to luminance x sin theta, and a uniform point in it, by inverting the rows'
// and each row's cumulative distribution with the two numbers of one 2-D sample.
// Directions map to the image as Blender's Environment Texture does for a glTF scene:
// column u = 0.5 + atan2(z, x) / 2pi, row t = acos(y) / pi from the top.
#ifndef FOVEA_ENVIRONMENT_GLSL
#define FOVEA_ENVIRONMENT_GLSL
#include "bindings.glsl"
#include "geometry.glsl"

// d turned back by the environment's rotation about +Y: the direction in the map's frame.
vec3 env_frame(vec3 d) {
    float c = scene_info.env_rotate_cos, s = scene_info.env_rotate_sin;
    return vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

// The map's (u, t) of world direction d.
vec2 env_uv(vec3 d) {
    vec3 m = normalize(env_frame(d));
    float u = 0.5 + atan(m.z, m.x) * (0.5 / PI);
    return vec2(fract(u), acos(clamp(m.y, -1.0, 1.0)) * (1.0 / PI));
}

// The world direction at the map's (u, t): the inverse of env_uv.
vec3 env_direction(vec2 ut) {
    float phi = (ut.x - 0.5) * 2.0 * PI, theta = ut.y * PI;
    vec3 m = vec3(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
    float c = scene_info.env_rotate_cos, s = scene_info.env_rotate_sin;
    return vec3(c * m.x + s * m.z, m.y, -s * m.x + c * m.z);
}

// Texel (col, row)'s radiance (xyz) and probability of being chosen (w).
vec4 env_texel(int col, int row) {
    return fetch_vec4(environment_texels, 2 * (row * int(scene_info.env_width) + col));
}

// The radiance at the map's (u, t): bilinear between texel centres.
vec3 env_radiance(vec2 ut) {
    int w = int(scene_info.env_width), h = int(scene_info.env_height);
    vec2 at = ut * vec2(w, h) - 0.5;
    vec2 f = fract(at);
    ivec2 c0 = ivec2(floor(at));
    // Columns wrap around the sphere; rows stop at the poles.
    int x0 = (c0.x % w + w) % w, x1 = (x0 + 1) % w;
    int y0 = clamp(c0.y, 0, h - 1), y1 = clamp(c0.y + 1, 0, h - 1);
    vec3 top = mix(env_texel(x0, y0).xyz, env_texel(x1, y0).xyz, f.x);
    vec3 bottom = mix(env_texel(x0, y1).xyz, env_texel(x1, y1).xyz, f.x);
    return mix(top, bottom, f.y);
}

// Solid-angle density of a direction in the texel of probability pmf at row position t:
// the texel's (u, t) area 1/(w h) covers 2 pi^2 sin(theta) / (w h) steradians.
float env_density(float pmf, float t) {
    float sin_theta = sin(t * PI);
    float texels = float(scene_info.env_width * scene_info.env_height);
    return sin_theta > 0.0 ? pmf * texels / (2.0 * PI * PI * sin_theta) : 0.0;
}

// The density with which env_sample picks the direction at the map's (u, t).
float env_pdf(vec2 ut) {
    int col = min(int(ut.x * float(scene_info.env_width)), int(scene_info.env_width) - 1);
    int row = min(int(ut.y * float(scene_info.env_height)), int(scene_info.env_height) - 1);
    return env_density(env_texel(col, row).w, ut.y);
}

// Where texel (col, row) starts in its row's cumulative distribution (x) and where its row
// starts in the map's (y) (src/scene/env_sampling.rs).
vec2 env_starts(int col, int row) {
    return uintBitsToFloat(texelFetch(environment_texels, 2 * (row * int(scene_info.env_width) + col) + 1).xy);
}

// A direction toward the environment from one 2-D sample: the row whose interval of the
// map's cumulative distribution holds u.y, the column whose interval of that row's holds
// u.x (binary searches), each coordinate's place inside its interval the place inside the
// texel; at the map's `ut`. `pdf` is its solid-angle density.
vec3 env_sample(vec2 u, out vec2 ut, out float pdf) {
    int w = int(scene_info.env_width), h = int(scene_info.env_height);
    // The last row starting at or before u.y (row 0 starts at 0).
    int lo = 0, hi = h;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (env_starts(0, mid).y <= u.y) lo = mid; else hi = mid;
    }
    int row = lo;
    float r0 = env_starts(0, row).y, r1 = row + 1 < h ? env_starts(0, row + 1).y : 1.0;
    lo = 0;
    hi = w;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (env_starts(mid, row).x <= u.x) lo = mid; else hi = mid;
    }
    int col = lo;
    float c0 = env_starts(col, row).x, c1 = col + 1 < w ? env_starts(col + 1, row).x : 1.0;
    // Inside the texel: the remainders (an interval of zero width, which rounding alone can
    // reach, gives its texel's centre).
    vec2 inside = vec2(c1 > c0 ? (u.x - c0) / (c1 - c0) : 0.5, r1 > r0 ? (u.y - r0) / (r1 - r0) : 0.5);
    inside = clamp(inside, 0.0, 0.99999994);
    ut = (vec2(col, row) + inside) / vec2(w, h);
    pdf = env_density(env_texel(col, row).w, ut.y);
    return env_direction(ut);
}

#endif
