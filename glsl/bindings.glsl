// Declarations of every set-0 resource and specialization constant, from shared.h's numbers.
#ifndef FOVEA_BINDINGS_GLSL
#define FOVEA_BINDINGS_GLSL
// Texel buffers without samplers (utextureBuffer + texelFetch).
#extension GL_EXT_samplerless_texture_functions : require
#include "shared.h"

layout(constant_id = SPEC_HAS_TRIANGLES) const bool HAS_TRIANGLES = true;
layout(constant_id = SPEC_HAS_BOXES) const bool HAS_BOXES = true;
layout(constant_id = SPEC_HAS_SPHERES) const bool HAS_SPHERES = true;
layout(constant_id = SPEC_HAS_SPECULAR) const bool HAS_SPECULAR = true;
layout(constant_id = SPEC_HAS_EMITTERS) const bool HAS_EMITTERS = true;
layout(constant_id = SPEC_MAX_BOUNCES) const uint MAX_BOUNCES = 8;
layout(constant_id = SPEC_INTEGRATOR) const uint INTEGRATOR = INTEGRATOR_PT;
layout(constant_id = SPEC_PROFILE) const bool PROFILE = false;
layout(constant_id = SPEC_HAS_SHADING) const bool HAS_SHADING = true;
layout(constant_id = SPEC_HAS_METALLIC_ROUGHNESS) const bool HAS_METALLIC_ROUGHNESS = true;
layout(constant_id = SPEC_HAS_TEXTURES) const bool HAS_TEXTURES = true;
layout(constant_id = SPEC_HAS_CUTOUTS) const bool HAS_CUTOUTS = true;
layout(constant_id = SPEC_HAS_SINGLE_SIDED) const bool HAS_SINGLE_SIDED = true;
layout(constant_id = SPEC_HAS_ENV_MAP) const bool HAS_ENV_MAP = true;
layout(constant_id = SPEC_SAMPLER) const uint SAMPLER = SAMPLER_ZSOBOL;
layout(constant_id = SPEC_TRACE_SHARES) const bool TRACE_SHARES = false;

// The scene's arrays are uniform texel buffers of RGBA32UI texels (uvec4[5] per BVH node, a
// struct's vec4s and uint quads in order): lavapipe loads a texel per lane with one vector
// load, a storage buffer's uvec4 as four bounds-checked scalar loads per lane
// (src/gpu/memory.rs, TexelView). The load_* functions read the structs back; the compiler
// drops the fetches of fields a caller does not use.
layout(set = 0, binding = BINDING_NODES) uniform utextureBuffer bvh_nodes;
layout(set = 0, binding = BINDING_TRIANGLES) uniform utextureBuffer triangle_texels;
layout(set = 0, binding = BINDING_SHADING) uniform utextureBuffer shading_texels;
layout(set = 0, binding = BINDING_OBJECTS) uniform utextureBuffer object_texels;
layout(set = 0, binding = BINDING_MATERIALS) uniform utextureBuffer material_texels;
layout(set = 0, binding = BINDING_EMITTERS) uniform utextureBuffer emitter_texels;
layout(set = 0, binding = BINDING_ENVIRONMENT) uniform utextureBuffer environment_texels;

vec4 fetch_vec4(utextureBuffer b, int texel) {
    return uintBitsToFloat(texelFetch(b, texel));
}

GpuTriangle load_triangle(uint index) {
    int t = int(index * TEXELS_PER_TRIANGLE);
    GpuTriangle T;
    T.v0 = fetch_vec4(triangle_texels, t);
    T.v1 = fetch_vec4(triangle_texels, t + 1);
    T.v2 = fetch_vec4(triangle_texels, t + 2);
    return T;
}

GpuTriangleShading load_triangle_shading(uint index) {
    int t = int(index * TEXELS_PER_TRIANGLE_SHADING);
    GpuTriangleShading S;
    S.normals = texelFetch(shading_texels, t);
    S.uv0_01 = fetch_vec4(shading_texels, t + 1);
    S.uv0_2_uv1_0 = fetch_vec4(shading_texels, t + 2);
    S.uv1_12 = fetch_vec4(shading_texels, t + 3);
    S.tangents = texelFetch(shading_texels, t + 4);
    return S;
}

// An object's kind, material, blas_root and triangle_base: the texel the traversal reads for
// every object it meets.
uvec4 load_object_ids(uint index) {
    return texelFetch(object_texels, int(index * TEXELS_PER_OBJECT) + 8);
}

GpuObject load_object(uint index) {
    int t = int(index * TEXELS_PER_OBJECT);
    GpuObject o;
    o.world_to_object0 = fetch_vec4(object_texels, t);
    o.world_to_object1 = fetch_vec4(object_texels, t + 1);
    o.world_to_object2 = fetch_vec4(object_texels, t + 2);
    o.object_to_world0 = fetch_vec4(object_texels, t + 3);
    o.object_to_world1 = fetch_vec4(object_texels, t + 4);
    o.object_to_world2 = fetch_vec4(object_texels, t + 5);
    o.a = fetch_vec4(object_texels, t + 6);
    o.b = fetch_vec4(object_texels, t + 7);
    uvec4 ids = load_object_ids(index);
    o.kind = ids.x;
    o.material = ids.y;
    o.blas_root = ids.z;
    o.triangle_base = ids.w;
    uvec4 more = texelFetch(object_texels, t + 9);
    o.emitter = more.x;
    o.triangle_count = more.y;
    o.surface = more.z;
    o.alpha_cutoff = uintBitsToFloat(more.w);
    return o;
}

// An object's OBJECT_* flags and alpha cutoff: what a traversal reads on entering an instance,
// in a scene with single-sided or alpha-cut surfaces.
uvec2 load_object_surface(uint index) {
    return texelFetch(object_texels, int(index * TEXELS_PER_OBJECT) + 9).zw;
}

uint load_object_kind(uint index) {
    return load_object_ids(index).x;
}

GpuTextureSlot load_texture_slot(int t) {
    GpuTextureSlot s;
    s.u_row = fetch_vec4(material_texels, t);
    s.v_row = fetch_vec4(material_texels, t + 1);
    uvec4 ids = texelFetch(material_texels, t + 2);
    s.texture = ids.x;
    s.texcoord = ids.y;
    s.pad0 = ids.z;
    s.pad1 = ids.w;
    return s;
}

GpuMaterial load_material(uint index) {
    int t = int(index * TEXELS_PER_MATERIAL);
    GpuMaterial m;
    m.kd = fetch_vec4(material_texels, t);
    m.ks = fetch_vec4(material_texels, t + 1);
    m.emission = fetch_vec4(material_texels, t + 2);
    m.base_color = fetch_vec4(material_texels, t + 3);
    uvec4 more = texelFetch(material_texels, t + 4);
    m.metallic = uintBitsToFloat(more.x);
    m.roughness = uintBitsToFloat(more.y);
    m.model = more.z;
    m.normal_scale = uintBitsToFloat(more.w);
    m.base_color_texture = load_texture_slot(t + 5);
    m.metallic_roughness_texture = load_texture_slot(t + 8);
    m.emissive_texture = load_texture_slot(t + 11);
    m.normal_texture = load_texture_slot(t + 14);
    return m;
}

// Emitter `index`'s alias-table bucket: x its alias, y its keep probability's bits.
uvec2 load_emitter_bucket(uint index) {
    return texelFetch(emitter_texels, int(index * TEXELS_PER_EMITTER) + 4).zw;
}

GpuEmitter load_emitter(uint index) {
    int t = int(index * TEXELS_PER_EMITTER);
    GpuEmitter e;
    e.p0 = fetch_vec4(emitter_texels, t);
    e.p1 = fetch_vec4(emitter_texels, t + 1);
    e.p2 = fetch_vec4(emitter_texels, t + 2);
    e.emission = fetch_vec4(emitter_texels, t + 3);
    uvec4 ids = texelFetch(emitter_texels, t + 4);
    e.kind = ids.x;
    e.object = ids.y;
    e.alias = ids.z;
    e.keep = uintBitsToFloat(ids.w);
    vec4 more = fetch_vec4(emitter_texels, t + 5);
    e.pmf = more.x;
    e.range = more.y;
    e.spot_scale = more.z;
    e.spot_offset = more.w;
    return e;
}
layout(std430, set = 0, binding = BINDING_SCENE_INFO) readonly buffer SceneInfoBuf { GpuSceneInfo scene_info; };
layout(std430, set = 0, binding = BINDING_STATS) buffer Stats { uint stats[]; };
layout(set = 0, binding = BINDING_OUTPUT, rgba32f) uniform image2D out_image;
layout(std430, set = 0, binding = BINDING_PROBE_RAYS) readonly buffer ProbeRays { GpuProbeRay probe_rays[]; };
layout(std430, set = 0, binding = BINDING_PROBE_HITS) writeonly buffer ProbeHits { GpuProbeHit probe_hits[]; };
layout(std430, set = 0, binding = BINDING_BRDF_QUERIES) readonly buffer BrdfQueries { GpuBrdfQuery brdf_queries[]; };
layout(std430, set = 0, binding = BINDING_BRDF_ANSWERS) writeonly buffer BrdfAnswers { GpuBrdfAnswer brdf_answers[]; };

layout(set = 0, binding = BINDING_LAYER_IMAGES, rgba32f) uniform image2DArray layer_images;
// Only trace.comp writes LATTICE (it defines WRITES_LATTICE), and lattice_fill.comp fills the
// points it skipped from those it traced (FILLS_LATTICE); read-only everywhere else, so the
// validation layer's synchronization checks see the other passes as its readers.
#ifdef WRITES_LATTICE
layout(std430, set = 0, binding = BINDING_LATTICE) writeonly buffer LatticeBuf { vec4 lattice[]; };
#elif defined(FILLS_LATTICE)
layout(std430, set = 0, binding = BINDING_LATTICE) buffer LatticeBuf { vec4 lattice[]; };
#else
layout(std430, set = 0, binding = BINDING_LATTICE) readonly buffer LatticeBuf { vec4 lattice[]; };
#endif
// The same buffer as texels, one view per eye (lattice_texels.glsl): resolve reads its taps
// this way (one vector load per lane on lavapipe, see the scene arrays above).
layout(set = 0, binding = BINDING_LATTICE_TEXELS) uniform utextureBuffer lattice_texels[EYE_TEXEL_VIEWS];
layout(std430, set = 0, binding = BINDING_WORK) buffer WorkBuf { uint work[]; };
layout(std430, set = 0, binding = BINDING_LAYERS) readonly buffer Layers { GpuLayer layers[]; };
layout(std430, set = 0, binding = BINDING_VISIBILITY) readonly buffer Visibility { uint visibility[]; };
// Only resolve.comp writes the frame's pixels: on lavapipe a storage-buffer store costs about
// half an imageStore (which goes through a per-lane image-format routine).
// temporal.comp (which defines READS_PIXELS) reads them back and writes what it shows.
#ifdef READS_PIXELS
layout(std430, set = 0, binding = BINDING_PIXELS) buffer PixelsBuf { vec4 pixels[]; };
#else
layout(std430, set = 0, binding = BINDING_PIXELS) writeonly buffer PixelsBuf { vec4 pixels[]; };
#endif
// Temporal history (temporal.comp; trace writes the lattice points' surfaces while it is on).
#ifdef WRITES_LATTICE
layout(std430, set = 0, binding = BINDING_LATTICE_SURFACE) writeonly buffer LatticeSurfaceBuf { uvec4 lattice_surface[]; };
layout(std430, set = 0, binding = BINDING_LATTICE_ALBEDO) writeonly buffer LatticeAlbedoBuf { uint lattice_albedo[]; };
#elif defined(FILLS_LATTICE)
layout(std430, set = 0, binding = BINDING_LATTICE_SURFACE) buffer LatticeSurfaceBuf { uvec4 lattice_surface[]; };
layout(std430, set = 0, binding = BINDING_LATTICE_ALBEDO) buffer LatticeAlbedoBuf { uint lattice_albedo[]; };
#else
layout(std430, set = 0, binding = BINDING_LATTICE_SURFACE) readonly buffer LatticeSurfaceBuf { uvec4 lattice_surface[]; };
layout(std430, set = 0, binding = BINDING_LATTICE_ALBEDO) readonly buffer LatticeAlbedoBuf { uint lattice_albedo[]; };
#endif
layout(std430, set = 0, binding = BINDING_HISTORY) writeonly buffer HistoryBuf { vec4 history_out[]; };
layout(std430, set = 0, binding = BINDING_HISTORY_SURFACE) writeonly buffer HistorySurfaceBuf { uvec4 history_surface_out[]; };
// A pixel's denoising guides over its history (HISTORY_ALBEDO): its mean albedo (pack_albedo),
// and the first two moments of its frames' illumination luminance (temporal.comp), whose
// variance is the noise the denoiser's edge-stop compares with once the history is long.
struct HistoryGuide {
    uint albedo;
    float moment1;
    float moment2;
};
layout(std430, set = 0, binding = BINDING_HISTORY_ALBEDO) writeonly buffer HistoryAlbedoBuf { HistoryGuide history_albedo_out[]; };
layout(std430, set = 0, binding = BINDING_ALBEDO_BEFORE) readonly buffer AlbedoBeforeBuf { HistoryGuide albedo_before[]; };
layout(std430, set = 0, binding = BINDING_DENOISE) buffer DenoiseBuf { vec4 denoise_pixels[]; };
// What temporal and the denoiser read, through texel views: on lavapipe a texel is one vector
// load per lane, where a storage buffer's vec4 is four bounds-checked scalar loads (the
// denoiser's three iterations at 720x800, cornell: 559 ms before, 299 after).
layout(set = 0, binding = BINDING_HISTORY_TEXELS) uniform utextureBuffer history_texels;
layout(set = 0, binding = BINDING_SURFACE_TEXELS) uniform utextureBuffer surface_texels;
layout(set = 0, binding = BINDING_LATTICE_SURFACE_TEXELS) uniform utextureBuffer lattice_surface_texels[EYE_TEXEL_VIEWS];
layout(set = 0, binding = BINDING_DENOISE_INPUT) uniform utextureBuffer denoise_input;
// The frame before's history at pixel index i, and its surface (temporal); this frame's
// surface at i once temporal has written it (the denoiser).
vec4 history_before(uint i) { return uintBitsToFloat(texelFetch(history_texels, int(i))); }
uvec4 pixel_surface(uint i) { return texelFetch(surface_texels, int(i)); }
#ifdef WRITES_LATTICE_FILTERED
layout(std430, set = 0, binding = BINDING_LATTICE_FILTERED) writeonly buffer LatticeFilteredBuf { vec4 lattice_filtered[]; };
#else
layout(std430, set = 0, binding = BINDING_LATTICE_FILTERED) readonly buffer LatticeFilteredBuf { vec4 lattice_filtered[]; };
#endif
layout(std430, set = 0, binding = BINDING_HISTORY_VIEWS) readonly buffer HistoryViews { GpuHistoryView history_views[]; };

// The pass's own push constants (shared.h): each shader names its struct before its includes.
#ifndef PASS_PUSH
#error "define PASS_PUSH as the pass's push-constant struct from shared.h before any include"
#endif
#ifndef NO_PUSH
layout(push_constant) uniform Push { PASS_PUSH pc; };
#endif

#endif
