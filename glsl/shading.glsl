// Shading a hit on a mesh with vertex attributes (shared.h's GpuTriangleShading): the hit's
// barycentrics, the interpolated shading normal, and the guard that keeps it usable.
#ifndef FOVEA_SHADING_GLSL
#define FOVEA_SHADING_GLSL
#include "bindings.glsl"
#include "surface.glsl"

// The barycentrics (of corners 1 and 2) of object-space point p on triangle T, from the
// point itself: the traversals (software and ray query) return only the distance, and the
// few extra dot products here are paid only by hits that are shaded.
vec2 triangle_barycentrics(GpuTriangle T, vec3 p) {
    vec3 e1 = T.v1.xyz - T.v0.xyz;
    vec3 e2 = T.v2.xyz - T.v0.xyz;
    vec3 q = p - T.v0.xyz;
    float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
    float q1 = dot(q, e1), q2 = dot(q, e2);
    float det = d11 * d22 - d12 * d12;
    vec2 b = det > 0.0 ? vec2(d22 * q1 - d12 * q2, d11 * q2 - d12 * q1) / det : vec2(0.0);
    // p lies on the triangle up to rounding: keep the weights inside it.
    b = clamp(b, 0.0, 1.0);
    return b / max(1.0, b.x + b.y);
}

// TEXCOORD_0 (xy) and TEXCOORD_1 (zw) at barycentrics b.
vec4 interpolated_uv(GpuTriangleShading S, vec2 b) {
    float b0 = 1.0 - b.x - b.y;
    return vec4(b0 * S.uv0_01.xy + b.x * S.uv0_01.zw + b.y * S.uv0_2_uv1_0.xy,
                b0 * S.uv0_2_uv1_0.zw + b.x * S.uv1_12.xy + b.y * S.uv1_12.zw);
}

// Per TEXCOORD set, the triangle's area in uv space over its world-space area (instance `ob`
// maps it to the world): how many texture-space units a unit of surface holds, for the
// textures' level of detail. 0 for a degenerate triangle.
vec2 uv_per_world_area(GpuTriangle T, GpuTriangleShading S, GpuObject ob) {
    mat3 to_world = transpose(mat3(ob.object_to_world0.xyz, ob.object_to_world1.xyz, ob.object_to_world2.xyz));
    float world = length(cross(to_world * (T.v1.xyz - T.v0.xyz), to_world * (T.v2.xyz - T.v0.xyz)));
    vec2 a0 = S.uv0_01.zw - S.uv0_01.xy, b0 = S.uv0_2_uv1_0.xy - S.uv0_01.xy;
    vec2 a1 = S.uv1_12.xy - S.uv0_2_uv1_0.zw, b1 = S.uv1_12.zw - S.uv0_2_uv1_0.zw;
    vec2 uv = vec2(abs(a0.x * b0.y - a0.y * b0.x), abs(a1.x * b1.y - a1.y * b1.x));
    return world > 0.0 ? uv / world : vec2(0.0);
}

// The world-space tangent at barycentrics b (unnormalised; w the bitangent's sign), or
// vec4(0) when the triangle has none. Tangents transform with the object (they lie in the
// surface), not by the inverse transpose as normals do.
vec4 world_tangent(GpuTriangleShading S, vec2 b, GpuObject ob) {
    if ((S.tangents.w & SHADING_TANGENTS) == 0u) return vec4(0.0);
    vec3 t0 = from_octahedral(unpackSnorm2x16(S.tangents.x));
    vec3 t1 = from_octahedral(unpackSnorm2x16(S.tangents.y));
    vec3 t2 = from_octahedral(unpackSnorm2x16(S.tangents.z));
    vec3 t = (1.0 - b.x - b.y) * t0 + b.x * t1 + b.y * t2;
    mat3 to_world = transpose(mat3(ob.object_to_world0.xyz, ob.object_to_world1.xyz, ob.object_to_world2.xyz));
    // The sign of the corner nearest to the hit (the signs agree except across a mirror seam).
    uint corner = b.x > b.y ? (b.x > 1.0 - b.x - b.y ? 1u : 0u) : (b.y > 1.0 - b.x - b.y ? 2u : 0u);
    float sign = (S.tangents.w & (1u << corner)) != 0u ? -1.0 : 1.0;
    return vec4(to_world * t, sign);
}

// The object-space shading normal of a triangle's attributes at barycentrics b (unnormalised),
// or vec3(0) when the triangle has none.
vec3 interpolated_normal(GpuTriangleShading S, vec2 b) {
    if ((S.normals.w & SHADING_NORMALS) == 0u) return vec3(0.0);
    vec3 n0 = from_octahedral(unpackSnorm2x16(S.normals.x));
    vec3 n1 = from_octahedral(unpackSnorm2x16(S.normals.y));
    vec3 n2 = from_octahedral(unpackSnorm2x16(S.normals.z));
    return (1.0 - b.x - b.y) * n0 + b.x * n1 + b.y * n2;
}

// The shading normal ns (on the side of the geometric normal ng, which faces the viewer wo)
// bent toward ng just enough that the mirror reflection of wo about it stays above the
// geometric surface. Interpolated normals disagree with the geometry near silhouettes and on
// coarse meshes; unbent, a reflection there points into the surface and the path goes black
// at grazing angles. The remedy is Cycles' (ensure_valid_specular_reflection, after Keller et
// al. 2017, "Towards consistent normal mapping"): replace the reflection by the nearest one
// just above the surface and take the half vector of wo and it as the normal. Light is never
// taken through the geometry: the integrators still require every sampled or light direction
// to be above ng, and shadow rays start on ng's side.
vec3 valid_shading_normal(vec3 ns, vec3 ng, vec3 wo) {
    if (dot(ns, ng) <= 0.0) return ng; // a normal facing away from its own surface: unusable
    vec3 r = reflect(-wo, ns);
    float threshold = min(0.9 * dot(ng, wo), 0.01);
    if (dot(r, ng) >= threshold) return ns;
    vec3 tangential = r - dot(r, ng) * ng;
    float len = length(tangential);
    if (len < 1e-6) return ng;
    vec3 r_valid = tangential / len * sqrt(1.0 - threshold * threshold) + threshold * ng;
    return normalize(wo + r_valid);
}

#endif
