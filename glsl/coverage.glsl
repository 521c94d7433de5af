// Which points of a mesh instance's triangles rays meet (shared.h's OBJECT_* flags, from
// glTF's doubleSided, alphaMode and alphaCutoff). Both traversals ask `meets` of every
// candidate triangle hit of such an instance, for camera, bounce and shadow rays alike, so a
// cut-out casts a cut-out shadow and a single-sided wall is invisible from behind to light
// too. Scenes without such instances compile this away (SPEC_HAS_CUTOUTS,
// SPEC_HAS_SINGLE_SIDED).
#ifndef FOVEA_COVERAGE_GLSL
#define FOVEA_COVERAGE_GLSL
#include "rng.glsl"
#include "shading.glsl"
#include "textures.glsl"

// A ray's key for stochastic transparency: a hash of its origin and direction. Each ray
// draws one number per triangle from it, so testing a triangle twice answers the same, and
// the next sample's or bounce's ray (another origin or direction) draws anew.
uint coverage_key(vec3 o, vec3 d) {
    uvec3 a = floatBitsToUint(o), b = floatBitsToUint(d);
    return pcg_hash(a.x ^ pcg_hash(a.y ^ pcg_hash(a.z ^ pcg_hash(b.x ^ pcg_hash(b.y ^ pcg_hash(b.z))))));
}

// The base colour's alpha at barycentrics b of triangle `tri`: the factor times the
// texture's alpha at its finest level (a traversal has no ray cone; the finest level keeps
// thin cut-outs such as leaves and fences from dissolving with distance).
float coverage_alpha(uint material, uint tri, vec2 b) {
    GpuMaterial m = load_material(material);
    float alpha = m.base_color.a;
    GpuTextureSlot slot = m.base_color_texture;
    if (HAS_TEXTURES && HAS_SHADING && slot.texture != NO_TEXTURE) {
        vec4 uv = interpolated_uv(load_triangle_shading(tri), b);
        alpha *= textureLod(textures[nonuniformEXT(slot.texture)], slot_uv(slot, uv), 0.0).a;
    }
    return alpha;
}

// True when the ray meets the alpha-cut surface at barycentrics b: MASK where alpha reaches
// the cutoff, BLEND with probability alpha. `surface` is load_object_surface's.
bool alpha_covers(uvec2 surface, uint material, uint tri, vec2 b, uint key) {
    float alpha = coverage_alpha(material, tri, b);
    if ((surface.x & OBJECT_ALPHA_MASK) != 0u) return alpha >= uintBitsToFloat(surface.y);
    uint h = pcg_hash(key ^ pcg_hash(tri));
    return float(h >> 8u) * (1.0 / 16777216.0) < alpha;
}

// True when a ray with object-space direction d meets the front of triangle T, or T is
// double-sided. The front is where the counter-clockwise winding's normal points (glTF); in
// object space, so that a mirroring instance transform keeps its front, as glTF's
// determinant rule wants.
bool facing_allows(uint surface, GpuTriangle T, vec3 d) {
    if ((surface & OBJECT_SINGLE_SIDED) == 0u) return true;
    return dot(cross(T.v1.xyz - T.v0.xyz, T.v2.xyz - T.v0.xyz), d) < 0.0;
}

// The software traversal's test of a triangle hit at distance t of the object-space ray
// (o, d): its face, then its alpha. `surface` and `material` are the instance's.
bool meets(uvec2 surface, uint material, uint tri, GpuTriangle T, vec3 o, vec3 d, float t, uint key) {
    if (HAS_SINGLE_SIDED && !facing_allows(surface.x, T, d)) return false;
    if (HAS_CUTOUTS && (surface.x & OBJECT_CUTOUT) != 0u) {
        return alpha_covers(surface, material, tri, triangle_barycentrics(T, o + t * d), key);
    }
    return true;
}

#endif
