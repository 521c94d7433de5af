// glTF 2.0's metallic-roughness BRDF (the specification's Appendix B, "BRDF Implementation"):
//   f = (1 - F) c_diff / pi + F D V,   c_diff = base (1 - metallic),   F0 = mix(0.04, base, metallic)
// with D the Trowbridge-Reitz (GGX) distribution of width alpha = roughness^2, V the
// height-correlated Smith visibility G2 / (4 |n.l| |n.v|), and F Schlick's Fresnel at v.h.
// Every term is symmetric in l and v, so the BRDF is reciprocal.
// Sampled as a mixture: the specular lobe by GGX's distribution of visible normals (Dupuy &
// Benyoub 2023, "Sampling Visible GGX Normals with Spherical Caps"), the diffuse one by
// cosine, picked by their estimated weights; gltf_pdf is the mixture's density, which is what
// MIS weights need.
#ifndef FOVEA_GLTF_BRDF_GLSL
#define FOVEA_GLTF_BRDF_GLSL
#include "brdf.glsl"
#include "colour.glsl"

bool is_metallic_roughness(GpuMaterial m) {
    return HAS_METALLIC_ROUGHNESS && m.model == MODEL_METALLIC_ROUGHNESS;
}

// Normal-incidence reflectance of glTF's dielectrics.
const float GLTF_DIELECTRIC_F0 = 0.04;
// The narrowest lobe traced: below alpha = 1e-3 (roughness 0.03) D's peak (1/(pi alpha^2))
// nears float's range in products, and the lobe is a mirror at any display resolution.
const float GGX_MIN_ALPHA = 1e-3;

float ggx_alpha(GpuMaterial m) {
    return max(m.roughness * m.roughness, GGX_MIN_ALPHA);
}

// D(h) for cos(n, h) = nh > 0 and a2 = alpha^2.
float ggx_d(float nh, float a2) {
    float t = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (PI * t * t);
}

// The height-correlated Smith visibility V = G2 / (4 nl nv) for nl, nv > 0 (Heitz 2014, eq. 99).
float smith_visibility(float nl, float nv, float a2) {
    float gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    float gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    return 0.5 / (gv + gl);
}

vec3 schlick(vec3 f0, float cos_theta) {
    float x = 1.0 - clamp(cos_theta, 0.0, 1.0);
    float x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

vec3 gltf_f0(GpuMaterial m) {
    return mix(vec3(GLTF_DIELECTRIC_F0), m.base_color.rgb, m.metallic);
}

// f(wo, wi) with normal n; 0 unless both directions are above it.
vec3 gltf_eval(GpuMaterial m, vec3 wo, vec3 wi, vec3 n) {
    float nl = dot(n, wi), nv = dot(n, wo);
    if (nl <= 0.0 || nv <= 0.0) return vec3(0.0);
    vec3 h = normalize(wo + wi);
    float a = ggx_alpha(m);
    float a2 = a * a;
    vec3 F = schlick(gltf_f0(m), dot(wo, h));
    vec3 c_diff = m.base_color.rgb * (1.0 - m.metallic);
    return (1.0 - F) * c_diff * (1.0 / PI) + F * (ggx_d(dot(n, h), a2) * smith_visibility(nl, nv, a2));
}

// The probability of sampling the specular lobe from wo: its share of the estimated albedo
// (Fresnel at the view angle against what the diffuse base keeps), never 0 or 1 while both
// lobes reflect something, so each stays reachable.
float gltf_specular_probability(GpuMaterial m, float nv) {
    float spec = luminance(schlick(gltf_f0(m), nv));
    float diff = luminance(m.base_color.rgb * (1.0 - m.metallic)) * (1.0 - spec);
    if (diff <= 0.0) return 1.0;
    return clamp(spec / (spec + diff), 0.1, 0.9);
}

// Density (solid angle) of reflecting wo about a visible GGX normal: D_v(h) / (4 v.h) with
// D_v = G1(v) v.h D(h) / n.v, which is D(h) / (2 (nv + sqrt(a2 + (1 - a2) nv^2))).
float ggx_vndf_pdf(float nv, float nh, float a2) {
    return ggx_d(nh, a2) / (2.0 * (nv + sqrt(a2 + (1.0 - a2) * nv * nv)));
}

// The mixture's density of wi given wo (solid angle), for MIS and for the sampler's weight.
float gltf_pdf(GpuMaterial m, vec3 wo, vec3 wi, vec3 n) {
    float nl = dot(n, wi), nv = dot(n, wo);
    if (nl <= 0.0 || nv <= 0.0) return 0.0;
    float p_spec = gltf_specular_probability(m, nv);
    float a = ggx_alpha(m);
    vec3 h = normalize(wo + wi);
    float spec = ggx_vndf_pdf(nv, max(dot(n, h), 0.0), a * a);
    return p_spec * spec + (1.0 - p_spec) * nl * (1.0 / PI);
}

// A visible normal of the GGX distribution of width a, seen from v (in the frame where the
// surface normal is +z), from two uniform numbers: Dupuy & Benyoub (2023), listing 3.
vec3 ggx_sample_vndf(vec3 v, float a, vec2 u) {
    vec3 v_std = normalize(vec3(v.xy * a, v.z));
    float phi = 2.0 * PI * u.x;
    float z = (1.0 - u.y) * (1.0 + v_std.z) - v_std.z;
    float sin_theta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    vec3 h_std = vec3(sin_theta * cos(phi), sin_theta * sin(phi), z) + v_std;
    return normalize(vec3(h_std.xy * a, h_std.z));
}

// Samples wi from wo: u_lobe picks the lobe, u the direction in it. Returns false when the
// direction falls below the surface (the path is absorbed there; the density counts that
// loss, so no weight is needed for it); else wi and its density.
bool gltf_sample(GpuMaterial m, vec3 wo, vec3 n, float u_lobe, vec2 u, out vec3 wi, out float pdf) {
    float nv = dot(n, wo);
    wi = vec3(0.0);
    pdf = 0.0;
    if (nv <= 0.0) return false;
    if (u_lobe < gltf_specular_probability(m, nv)) {
        vec3 t, b;
        basis(n, t, b);
        vec3 v = vec3(dot(wo, t), dot(wo, b), nv);
        vec3 h = ggx_sample_vndf(v, ggx_alpha(m), u);
        wi = reflect(-wo, h.x * t + h.y * b + h.z * n);
    } else {
        wi = sample_power_cosine(u, n, 1.0);
    }
    pdf = gltf_pdf(m, wo, wi, n);
    return pdf > 0.0;
}

#endif
