#version 460
// glTF's BRDF for the sampling checks (src/check/gltf_brdf.rs): per query, one sample drawn
// as the integrators draw it, and f and the density at a given direction, all through
// gltf_brdf.glsl's functions, in the frame where the surface normal is +z.
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH BrdfProbePush
#include "gltf_brdf.glsl"

layout(local_size_x = PROBE_WORKGROUP_SIZE) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.query_count) return;
    GpuBrdfQuery q = brdf_queries[i];
    GpuMaterial m = load_material(q.material);
    const vec3 n = vec3(0.0, 0.0, 1.0);
    vec3 wo = q.wo.xyz;
    GpuBrdfAnswer a;
    vec3 wi;
    float pdf;
    if (gltf_sample(m, wo, n, q.u.x, q.u.yz, wi, pdf)) {
        a.sampled = vec4(wi, pdf);
        a.weight = vec4(gltf_eval(m, wo, wi, n) * dot(wi, n) / pdf, 0.0);
    } else {
        a.sampled = vec4(wi, 0.0);
        a.weight = vec4(0.0);
    }
    a.value = vec4(gltf_eval(m, wo, q.wi.xyz, n), gltf_pdf(m, wo, q.wi.xyz, n));
    brdf_answers[i] = a;
}
