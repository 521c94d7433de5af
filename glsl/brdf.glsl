// The thesis' BRDF (eqs. 3.7-3.8): Lambert k_d/pi plus modified Phong k_s (alpha+2)/(2pi) cos^alpha theta_r,
// where theta_r is the angle between the incident direction and the mirror reflection of the
// outgoing one. alpha = +inf is a perfect mirror (a delta lobe).
#ifndef FOVEA_BRDF_GLSL
#define FOVEA_BRDF_GLSL
#include "bindings.glsl"
#include "geometry.glsl"

bool is_mirror(GpuMaterial m) {
    return isinf(m.kd.w);
}

// An orthonormal basis around n (Duff et al. 2017, "Building an orthonormal basis, revisited").
void basis(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 to_world(vec3 local, vec3 n) {
    vec3 t, b;
    basis(n, t, b);
    return local.x * t + local.y * b + local.z * n;
}

// Direction around axis with pdf (k+1)/(2pi) cos^k theta: k = 0 uniform hemisphere, k = 1 cosine.
vec3 sample_power_cosine(vec2 u, vec3 axis, float k) {
    float cos_t = pow(u.x, 1.0 / (k + 1.0));
    float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
    float phi = 2.0 * PI * u.y;
    return to_world(vec3(cos(phi) * sin_t, sin(phi) * sin_t, cos_t), axis);
}

// pow that is 0 (not NaN) for a non-positive base and finite for huge exponents.
float safe_pow(float x, float e) {
    return x > 0.0 ? pow(min(x, 1.0), e) : 0.0;
}

// Phong lobe value cos^alpha theta_r, with alpha = 0 meaning a constant lobe.
float phong_lobe(vec3 wi, vec3 r, float alpha) {
    return alpha == 0.0 ? 1.0 : safe_pow(dot(wi, r), alpha);
}

// The non-delta part of the BRDF, f(wo, wi) for a normal n (wi, n same hemisphere checked by caller).
vec3 brdf_eval(GpuMaterial m, vec3 wo, vec3 wi, vec3 n) {
    vec3 f = m.kd.xyz * (1.0 / PI);
    if (HAS_SPECULAR && !is_mirror(m)) {
        vec3 r = reflect(-wo, n);
        float alpha = m.kd.w;
        f += m.ks.xyz * ((alpha + 2.0) / (2.0 * PI)) * phong_lobe(wi, r, alpha);
    }
    return f;
}

#endif
