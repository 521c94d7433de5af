// Next-event estimation: an emitter chosen in proportion to its estimated power (an alias
// table, GpuEmitter), then a uniform point on its surface, or a punctual light's one
// direction. Area densities are converted to solid angle (area pdf * d^2 / cos theta_light)
// for MIS; punctual lights are deltas that no BRDF sample finds, so they take no MIS weight.
#ifndef FOVEA_LIGHTS_GLSL
#define FOVEA_LIGHTS_GLSL
#include "bvh.glsl"

struct LightSample {
    vec3 p;
    vec3 n;
    float area_pdf; // including the emitter's choice (GpuEmitter.pmf)
};

// The emitter next-event estimation uses: bucket floor(u_bucket * count), then that bucket's
// own emitter with probability keep, else its alias.
uint choose_emitter(float u_bucket, float u_keep) {
    uint count = scene_info.emitter_count;
    uint bucket = min(uint(u_bucket * float(count)), count - 1u);
    uvec2 b = load_emitter_bucket(bucket);
    return u_keep < uintBitsToFloat(b.y) ? bucket : b.x;
}

bool is_punctual(uint kind) {
    return kind >= KIND_POINT_LIGHT && kind <= KIND_DIRECTIONAL_LIGHT;
}

// Light reaching x from a punctual light: the unit direction toward it, the distance (INF for
// a directional light) and the irradiance on a surface facing it (the extension's falloffs:
// inverse square with the range window clamp(1 - (d/range)^4, 0, 1), and the spot's
// saturate(cos * scale + offset)^2).
struct PunctualArrival {
    vec3 wi;
    float dist;
    vec3 irradiance;
};

PunctualArrival punctual_arrival(GpuEmitter e, vec3 x) {
    PunctualArrival a;
    if (e.kind == KIND_DIRECTIONAL_LIGHT) {
        a.wi = -e.p1.xyz;
        a.dist = INF;
        a.irradiance = e.emission.xyz;
        return a;
    }
    vec3 to_light = e.p0.xyz - x;
    float dist2 = max(dot(to_light, to_light), 1e-30);
    a.dist = sqrt(dist2);
    a.wi = to_light / a.dist;
    float falloff = 1.0 / dist2;
    if (e.range > 0.0) {
        float r = a.dist / e.range;
        r *= r;
        falloff *= clamp(1.0 - r * r, 0.0, 1.0);
    }
    if (e.kind == KIND_SPOT_LIGHT) {
        float cone = clamp(dot(e.p1.xyz, -a.wi) * e.spot_scale + e.spot_offset, 0.0, 1.0);
        falloff *= cone * cone;
    }
    a.irradiance = e.emission.xyz * falloff;
    return a;
}

LightSample sample_emitter(GpuEmitter e, vec3 u) {
    LightSample s;
    s.area_pdf = e.pmf / e.emission.w;
    if (e.kind == KIND_TRIANGLE) {
        float su = sqrt(u.x);
        float b0 = 1.0 - su, b1 = u.y * su;
        s.p = b0 * e.p0.xyz + b1 * e.p1.xyz + (1.0 - b0 - b1) * e.p2.xyz;
        s.n = normalize(cross(e.p1.xyz - e.p0.xyz, e.p2.xyz - e.p0.xyz));
    } else if (e.kind == KIND_SPHERE) {
        float z = 1.0 - 2.0 * u.x;
        float r = sqrt(max(0.0, 1.0 - z * z));
        float phi = 2.0 * PI * u.y;
        s.n = vec3(r * cos(phi), r * sin(phi), z);
        s.p = e.p0.xyz + e.p0.w * s.n;
    } else {
        // Box: pick a face in proportion to its area, then a point on it.
        vec3 ext = e.p1.xyz - e.p0.xyz;
        vec3 face_area = vec3(ext.y * ext.z, ext.x * ext.z, ext.x * ext.y);
        float total = face_area.x + face_area.y + face_area.z;
        float pick = u.z * total;
        int axis = pick < face_area.x ? 0 : (pick < face_area.x + face_area.y ? 1 : 2);
        float lo = axis == 0 ? 0.0 : (axis == 1 ? face_area.x : face_area.x + face_area.y);
        float v = (pick - lo) / face_area[axis]; // reuse the leftover of u.z for the side
        bool upper = v >= 0.5;
        int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        vec3 p;
        p[axis] = upper ? e.p1[axis] : e.p0[axis];
        p[a1] = e.p0[a1] + u.x * ext[a1];
        p[a2] = e.p0[a2] + u.y * ext[a2];
        s.p = p;
        s.n = vec3(0.0);
        s.n[axis] = upper ? 1.0 : -1.0;
    }
    return s;
}

// Solid-angle density with which sample_emitter would have produced the point p with normal n
// seen from x, for MIS weights of BSDF-sampled hits on emitters.
float emitter_pdf_solid_angle(uint index, vec3 x, vec3 p, vec3 n) {
    GpuEmitter e = load_emitter(index);
    vec3 d = p - x;
    float dist2 = dot(d, d);
    float cos_l = abs(dot(n, normalize(d)));
    if (cos_l <= 0.0) return 0.0;
    return dist2 * e.pmf / (cos_l * e.emission.w);
}

#endif
