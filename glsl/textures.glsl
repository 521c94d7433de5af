// The scene's textures (BINDING_TEXTURES) as glTF materials read them: a slot's texture
// coordinates moved by its KHR_texture_transform, the mip level chosen by the ray cone's
// footprint (Akenine-Moller et al. 2021, "Improved Shader and Texture Level of Detail Using
// Ray Cones", eq. 34: lambda = 0.5 log2(texels per unit of world area) + log2(cone width /
// |n.d|)).
#ifndef FOVEA_TEXTURES_GLSL
#define FOVEA_TEXTURES_GLSL
#extension GL_EXT_nonuniform_qualifier : require
#include "bindings.glsl"

layout(set = 0, binding = BINDING_TEXTURES) uniform sampler2D textures[MAX_TEXTURES];

// What a hit's texture lookups need of its triangle and of the ray cone that found it.
struct Footprint {
    vec2 uv_per_area; // per TEXCOORD set: the triangle's uv area over its world-space area
    float width; // the cone's width at the hit over |cos| of its incidence (world units)
};

vec2 slot_uv(GpuTextureSlot s, vec4 uv) {
    vec3 t = vec3(s.texcoord == 0u ? uv.xy : uv.zw, 1.0);
    return vec2(dot(s.u_row.xyz, t), dot(s.v_row.xyz, t));
}

// The slot's texel at the hit, filtered at the footprint's level of detail. A footprint of
// width 0 (no cone: the probe, a test) reads the finest level.
vec4 sample_slot(GpuTextureSlot s, vec4 uv, Footprint f) {
    uint i = s.texture;
    vec2 size = vec2(textureSize(textures[nonuniformEXT(i)], 0));
    // The transform scales uv areas by |det| of its 2x2 part.
    float det = abs(s.u_row.x * s.v_row.y - s.u_row.y * s.v_row.x);
    float texel_area = size.x * size.y * det * (s.texcoord == 0u ? f.uv_per_area.x : f.uv_per_area.y);
    float lod = 0.5 * log2(max(texel_area, 1e-30)) + log2(max(f.width, 1e-30));
    return textureLod(textures[nonuniformEXT(i)], slot_uv(s, uv), max(lod, 0.0));
}

// The material with its textures applied: each multiplies its factor (glTF 2.0, 3.9.2).
GpuMaterial textured(GpuMaterial m, vec4 uv, Footprint f) {
    if (m.base_color_texture.texture != NO_TEXTURE) {
        m.base_color.rgb *= sample_slot(m.base_color_texture, uv, f).rgb;
    }
    if (m.metallic_roughness_texture.texture != NO_TEXTURE) {
        vec4 mr = sample_slot(m.metallic_roughness_texture, uv, f);
        m.metallic *= mr.b;
        m.roughness *= mr.g;
    }
    if (m.emissive_texture.texture != NO_TEXTURE) {
        m.emission.rgb *= sample_slot(m.emissive_texture, uv, f).rgb;
    }
    return m;
}

// The normal a normal map gives at the hit: its texel (2 rgb - 1, x and y times the scale)
// in the frame of the tangent t (w: the bitangent's sign) and the smooth normal n, with the
// bitangent w (n x t) pointing up the image (glTF 2.0, 3.9.3: +Y is up).
vec3 mapped_normal(GpuMaterial m, vec4 uv, Footprint f, vec3 n, vec4 t) {
    vec3 c = sample_slot(m.normal_texture, uv, f).xyz * 2.0 - 1.0;
    c.xy *= m.normal_scale;
    vec3 T = t.xyz - n * dot(n, t.xyz);
    float len = length(T);
    if (!(len > 1e-6)) return n;
    T /= len;
    vec3 B = t.w * cross(n, T);
    vec3 mapped = c.x * T + c.y * B + c.z * n;
    float l = length(mapped);
    return l > 0.0 ? mapped / l : n;
}

#endif
