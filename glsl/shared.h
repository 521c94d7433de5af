// The one source of truth for everything the host and the shaders share: binding numbers,
// specialization-constant ids, push constants and buffer struct layouts (std430).
// src/shader_layout.rs mirrors these structs; tests/shared_layout.rs parses this file and checks
// every Rust mirror's size and field offsets against the std430 rules, so the two cannot drift.
// Keep struct members to 4-byte scalars, vec4/uvec4 and arrays of them (the test's parser knows
// only those), one member per line.
#ifndef FOVEA_SHARED_H
#define FOVEA_SHARED_H

// ---- descriptor set 0 bindings -------------------------------------------------------------
#define BINDING_NODES 0        // uvec4[5] per CWBVH node (80 bytes, obvhs layout): every mesh's
                               // BLAS, then the TLAS over objects (at GpuSceneInfo.tlas_root);
                               // this and the next four are uniform texel buffers (bindings.glsl)
#define BINDING_TRIANGLES 1    // GpuTriangle[], in BLAS leaf order, object space
#define BINDING_OBJECTS 2      // GpuObject[], in TLAS leaf order
#define BINDING_MATERIALS 3    // GpuMaterial[]
#define BINDING_EMITTERS 4     // GpuEmitter[]
#define BINDING_SCENE_INFO 5   // GpuSceneInfo
#define BINDING_STATS 6        // uint counters, STAT_*
#define BINDING_OUTPUT 7       // rgba32f storage image: the frame, eyes side by side (PIXELS copied)
#define BINDING_PROBE_RAYS 8   // GpuProbeRay[] (raycast.comp only)
#define BINDING_PROBE_HITS 9   // GpuProbeHit[] (raycast.comp only)
#define BINDING_LAYER_IMAGES 10 // rgba32f 2D array image (accumulate.comp's running means)
#define BINDING_LATTICE 11     // vec4[]: traced lattice values; per eye, one entry per lattice
                               // point of the ray buffer (GpuLayer.first, .cols locate a point)
#define BINDING_WORK 12        // uint[]: the plan pass's work lists, eye e's at e * PushEye
                               // .work_stride: lattice index | layer << WORK_LAYER_SHIFT
#define BINDING_LAYERS 13      // GpuLayer[]: this frame's layers, eye-major
#define BINDING_VISIBILITY 14  // uint[]: [0] words per plane (0: no mask), then per eye 1 + layers
                               // planes of one bit per pixel (row-major, low bit first): the pixels
                               // the lens shows, then per layer the pixels whose lattice points are
                               // needed (the shown ones dilated by the layer's Catmull-Rom reach)
#define BINDING_LATTICE_TEXELS 15 // LATTICE's buffer as RGBA32UI texels: what resolve reads; an
                                  // array of EYE_TEXEL_VIEWS views, each eye's starting at its first
                                  // entry (EyePush.lattice_base)
#define BINDING_PIXELS 16      // vec4[]: the resolved frame, eye after eye, rows of pc.width; copied
                               // into OUTPUT only for what needs an image (presenting, accumulating)
// Temporal history (render/history.rs, glsl/temporal.comp); no pass declares them while
// history is off, so nothing binds them then.
#define BINDING_LATTICE_SURFACE 17 // uvec4[] per LATTICE entry, written by trace while history is
                                   // on: the surface its first sample's camera ray hit
                                   // (SURFACE_*)
#define BINDING_HISTORY 18     // vec4[]: the history plane this frame writes (History keeps two:
                               // frames take turns reading one and writing the other, and
                               // PushEye.history says which): per eye and pixel, rgb the mean of
                               // the pixel's own traced samples, w their count; at
                               // (eye * height + y) * width + x. Two buffers, not one of two
                               // planes: maxStorageBufferRange is 128 MiB on lavapipe
#define BINDING_HISTORY_SURFACE 19 // uvec4[] in HISTORY's layout: the surface a pixel's history
                                   // belongs to (SURFACE_*), the plane this frame writes
#define BINDING_HISTORY_VIEWS 20 // GpuHistoryView[]: per frame slot and eye (slot * STAT_EYES + eye)
#define BINDING_DENOISE 21    // vec4[]: the denoiser's other buffer (it ping-pongs with PIXELS), in
                              // PIXELS' layout; what a denoise iteration writes (this buffer or
                              // PIXELS, in turn)
#define BINDING_HISTORY_TEXELS 22 // the history plane the frame before wrote, which temporal reads,
                                  // as RGBA32UI texels (uniform texel buffers, like LATTICE_TEXELS)
#define BINDING_SURFACE_TEXELS 23 // a HISTORY_SURFACE plane as RGBA32UI texels: the frame before's
                                  // (temporal reads it) or this frame's (the denoiser)
#define BINDING_SHADING 24   // GpuTriangleShading[] in TRIANGLES' order (a uniform texel buffer):
                             // what shading interpolates across a triangle; empty (and never
                             // read, SPEC_HAS_SHADING off) when no mesh has such attributes
#define BINDING_BRDF_QUERIES 25 // GpuBrdfQuery[] (brdf_probe.comp only)
#define BINDING_BRDF_ANSWERS 26 // GpuBrdfAnswer[] (brdf_probe.comp only)
#define BINDING_TEXTURES 27 // sampler2D[MAX_TEXTURES] (combined image samplers, partially bound):
                            // the scene's textures in Scene::textures' order, mip chains in
                            // RGBA8 (sRGB or UNORM as their use), each with its glTF sampler
#define BINDING_ENVIRONMENT 28 // the HDR environment (a uniform texel buffer, environment.glsl):
                               // per texel of GpuSceneInfo.env_width x env_height, rows from
                               // the top, two RGBA32UI texels: (r, g, b, pmf) as float bits,
                               // then (alias, keep bits, 0, 0) (scene/env_sampling.rs); one
                               // empty element (never read, SPEC_HAS_ENV_MAP off) without one
#define BINDING_DISPLAY 29 // rgba32f storage image: OUTPUT through the display transform
                           // (display.comp), what a window or headset shows of it
#define BINDING_LATTICE_FILTERED 30 // vec4[] in LATTICE's layout: lattice_filter.comp's values (rgb)
                                   // and how many points each is worth (a), which resolve then
                                   // reads (as its LATTICE_TEXELS) in place of LATTICE
#define BINDING_LATTICE_ALBEDO 31 // uint[] per LATTICE entry, written by trace while a layer
                                 // denoises: the mean albedo of what the point's samples' camera
                                 // rays hit (pack_albedo; 1 for the sky and for emitters), which
                                 // temporal adds to the pixels' HISTORY_ALBEDO
#define BINDING_DENOISE_INPUT 32 // the denoiser's input this iteration (PIXELS or DENOISE) as
                                 // RGBA32UI texels (a uniform texel buffer, like LATTICE_TEXELS)
#define BINDING_LATTICE_SURFACE_TEXELS 33 // LATTICE_SURFACE as RGBA32UI texels: what temporal and
                                          // the lattice filter read; per eye, like LATTICE_TEXELS
#define BINDING_HISTORY_ALBEDO 34 // HistoryGuide[] (bindings.glsl) in HISTORY's layout, written by
                                  // temporal while albedos are kept (EyePush.albedo): the mean
                                  // albedo of the pixel's history's samples (pack_albedo) and the
                                  // first two moments of their illumination's luminance, the
                                  // plane this frame writes; History keeps two, as of HISTORY
#define BINDING_ALBEDO_BEFORE 35 // a HISTORY_ALBEDO plane, read: the frame before's (temporal
                                 // carries it) or this frame's (the denoiser multiplies it back)
#define BINDING_COUNT 36
// Views in the per-eye arrays of texel views (LATTICE_TEXELS, LATTICE_SURFACE_TEXELS): one per
// eye, so that maxTexelBufferElements bounds one eye's lattice, not both; mono binds its one
// view in every element.
#define EYE_TEXEL_VIEWS 2
// Only in the layouts of devices with VK_KHR_ray_query, after the others: the TLAS that
// the ray-query shaders (ray_query.glsl) trace.
#define BINDING_TLAS 36
// Textures a scene may have: BINDING_TEXTURES' descriptor count. Sponza has 69, Bistro ~400.
#define MAX_TEXTURES 1024

// 16-byte RGBA32UI texels per element of the texel-buffer arrays (bindings.glsl's load_*;
// src/shader_layout.rs checks them against the structs' sizes).
#define TEXELS_PER_NODE 5
#define TEXELS_PER_TRIANGLE 3
#define TEXELS_PER_OBJECT 10
#define TEXELS_PER_MATERIAL 17
#define TEXELS_PER_EMITTER 6
#define TEXELS_PER_TRIANGLE_SHADING 5

// ---- specialization constants: what a scene does not need is compiled away ------------------
#define SPEC_HAS_TRIANGLES 0
#define SPEC_HAS_BOXES 1
#define SPEC_HAS_SPHERES 2
#define SPEC_HAS_SPECULAR 3
#define SPEC_HAS_EMITTERS 4
#define SPEC_MAX_BOUNCES 5
#define SPEC_INTEGRATOR 6
#define SPEC_PROFILE 7 // trace.comp counts its traversal work (STAT_PROFILE); off: compiled away
#define SPEC_HAS_SHADING 8 // some mesh has shading normals or texture coordinates (SHADING)
#define SPEC_HAS_METALLIC_ROUGHNESS 9 // some material is MODEL_METALLIC_ROUGHNESS
#define SPEC_HAS_TEXTURES 10 // some material samples a texture (BINDING_TEXTURES)
#define SPEC_HAS_CUTOUTS 11 // some mesh instance is OBJECT_ALPHA_MASK or OBJECT_ALPHA_BLEND
#define SPEC_HAS_SINGLE_SIDED 12 // some mesh instance is OBJECT_SINGLE_SIDED
#define SPEC_HAS_ENV_MAP 13 // the sky is an HDR environment (BINDING_ENVIRONMENT), a light
#define SPEC_SAMPLER 14 // where a path's random numbers come from (sampler.glsl)
#define SPEC_TRACE_SHARES 15 // some layer has several trace lanes per point (GpuLayer.lanes)

#define INTEGRATOR_PT 0
#define INTEGRATOR_SEED 1

#define SAMPLER_INDEPENDENT 0
#define SAMPLER_ZSOBOL 1

// ---- object kinds (GpuObject.kind) and emitter kinds (GpuEmitter.kind) ----------------------
#define KIND_INSTANCE 0
#define KIND_BOX 1
#define KIND_SPHERE 2
#define KIND_TRIANGLE 3 // emitters only: one world-space triangle of an emissive instance
#define KIND_POINT_LIGHT 4       // emitters only: KHR_lights_punctual's point light
#define KIND_SPOT_LIGHT 5        // emitters only: its spot light
#define KIND_DIRECTIONAL_LIGHT 6 // emitters only: its directional light
#define KIND_ENVIRONMENT 7 // emitters only: the HDR environment (BINDING_ENVIRONMENT)

#define NO_EMITTER 0xffffffffu  // an object without emitters, a hit on no emitter
#define NO_OBJECT 0xffffffffu   // a ray that hit nothing (Hit.object, GpuProbeHit.object, SURFACE)
#define NO_PRIMITIVE 0xffffffffu // a hit on no triangle (an analytic shape or nothing)
#define NO_MATERIAL 0xffffffffu // a surface without material (nothing was hit)
#define NO_LAYER 0xffffffffu    // no layer chosen yet
#define NO_TEXTURE 0xffffffffu  // a material's texture slot that holds none

// ---- stats counters (BINDING_STATS), reported after every frame ----------------------------
#define STAT_NONFINITE 0       // samples that came out NaN/inf and were dropped (counted as black)
#define STAT_STACK_OVERFLOW 1  // BVH traversals whose stack overflowed
#define STAT_PATHS 2           // camera paths traced
#define STAT_RAYS 3            // all rays traced (camera, bounce and shadow)
#define STAT_COUNT 4
#define STAT_EYES 2            // one block of STAT_COUNT counters per eye: stats[eye * STAT_COUNT + STAT_*]
#define MAX_LAYERS 8           // src/foveation/config.rs's limit
// The plan pass's results, in the same host-visible buffer (reset by the host every frame):
// lattice points traced per eye and layer, then per eye the trace dispatch's
// VkDispatchIndirectCommand (x, y, z) and the length of the eye's work list: one slot per
// thread, GpuLayer.lanes of them per traced point, and WORK_EMPTY ones that pad.
#define STAT_LAYER_POINTS 8    // STAT_EYES * STAT_COUNT; + eye * MAX_LAYERS + layer
#define STAT_DISPATCH 24       // STAT_LAYER_POINTS + STAT_EYES * MAX_LAYERS; + eye * 4
#define STAT_WORK_COUNT 3      // within an eye's STAT_DISPATCH block, after x, y, z
// Per eye the fill dispatch's VkDispatchIndirectCommand (x, y, z) and the length of the eye's
// fill list: the lattice points a fractional layer skips this frame but needs (plan.comp writes
// them from the top of the eye's WORK segment down, lattice_fill.comp fills them).
#define STAT_FILL_DISPATCH 32  // STAT_DISPATCH + STAT_EYES * 4; + eye * 4 (count: STAT_WORK_COUNT)
// With SPEC_PROFILE, per eye PROFILE_COUNTERS 64-bit counters (low word, then high word) of
// the traversal's work: PROFILE_* below.
#define STAT_PROFILE 40        // STAT_FILL_DISPATCH + STAT_EYES * 4; + (eye * PROFILE_COUNTERS + counter) * 2
#define PROFILE_COUNTERS 8
#define PROFILE_TLAS_NODES 0        // TLAS nodes intersected (8 children each)
#define PROFILE_BLAS_NODES 1        // BLAS nodes intersected
#define PROFILE_TRIANGLES 2         // ray-triangle tests
#define PROFILE_PRIMITIVES 3        // ray-box and ray-sphere tests
#define PROFILE_TLAS_LANE_STEPS 4   // iterations of the TLAS loop, summed over invocations
#define PROFILE_TLAS_GROUP_STEPS 5  // the same loop's iterations per subgroup (one per step of any lane)
#define PROFILE_BLAS_LANE_STEPS 6   // iterations of the BLAS loop, summed over invocations
#define PROFILE_BLAS_GROUP_STEPS 7  // the same per subgroup
#define STAT_WORDS 72          // STAT_PROFILE + STAT_EYES * PROFILE_COUNTERS * 2
#define WORK_LAYER_SHIFT 28    // work items: lattice index in the low 28 bits, layer above

// ---- debug views (PushEye.debug) -------------------------------------------------------
#define DEBUG_NONE 0
#define DEBUG_LAYERS 1 // tint each pixel by the layer it comes from; blend bands darkened

// Angles in GpuLayer that are "no limit" (the background's radius, the fovea's inner edge).
#define NO_LIMIT 1.0e9

// Traversal stack depth, both BVH levels together (32 each, as when each had its own; the
// size does not change lavapipe's speed). CWBVH trees are shallow (8-wide); an overflow is
// counted in STAT_STACK_OVERFLOW, never silently ignored.
#define TRAVERSAL_STACK_SIZE 64
#define WORKGROUP_SIZE_X 8
#define WORKGROUP_SIZE_Y 8
#define PROBE_WORKGROUP_SIZE 64
// Resolve: each invocation does a run of this many consecutive pixels of one row, so a
// workgroup covers 128x8 pixels and a run reuses the Catmull-Rom columns its pixels share.
// Lavapipe also pays a fixed cost per invocation that was as large as a pixel's work.
#define PIXELS_PER_INVOCATION 16
// Plan: each invocation tests a run of this many lattice points of one row of one layer's
// box (consecutive lattice entries) and reserves their work-list slots with one atomic.
#define PLAN_RUN 16
#define TRACE_WORKGROUP_SIZE 64 // trace.comp is 1D over the eye's work list
#define MAX_TRACE_LANES 64 // GpuLayer.lanes' largest: one point's lanes share a workgroup
#define WORK_EMPTY 0xFFFFFFFFu // a work-list slot that pads a run's reservation (no point)
#define PLAN_WORKGROUP_SIZE 64  // plan.comp is 1D over the eye's layers' runs
#define MAX_GROUPS_X 65535 // the guaranteed maxComputeWorkGroupCount[0]; larger dispatches use y

struct GpuTriangle {
    vec4 v0;
    vec4 v1;
    vec4 v2;
};

// What shading interpolates across one triangle of a mesh with vertex attributes, by the hit's
// barycentrics: the corners' shading normals (object space, octahedral as two snorm16,
// surface.glsl's encoding) and their two sets of texture coordinates (0 where absent).
#define SHADING_NORMALS 1u // GpuTriangleShading.normals.w: the corners have shading normals
                           // (else, no normals in the mesh or an unusable one: shaded flat)
#define SHADING_TANGENTS 8u // GpuTriangleShading.tangents.w: the corners have tangents (normal maps)
struct GpuTriangleShading {
    uvec4 normals; // x, y, z: corners 0, 1, 2; w: SHADING_* flags
    vec4 uv0_01;   // TEXCOORD_0 of corner 0 (xy) and corner 1 (zw)
    vec4 uv0_2_uv1_0; // TEXCOORD_0 of corner 2 (xy), TEXCOORD_1 of corner 0 (zw)
    vec4 uv1_12;   // TEXCOORD_1 of corner 1 (xy) and corner 2 (zw)
    uvec4 tangents; // x, y, z: corners 0, 1, 2's tangents (octahedral as the normals); w:
                    // bit k the sign of corner k's bitangent (1: negative), SHADING_TANGENTS
};

// GpuObject.surface: a mesh instance's coverage (glTF's doubleSided and alphaMode), which both
// traversals apply to every ray. Alpha is the base colour's (factor x texture at level 0).
#define OBJECT_SINGLE_SIDED 1u // back faces (clockwise from the ray, in object space) are not there
#define OBJECT_ALPHA_MASK 2u   // present where alpha >= alpha_cutoff
#define OBJECT_ALPHA_BLEND 4u  // present with probability alpha (stochastic transparency)
#define OBJECT_CUTOUT 6u       // either alpha mode

// An instance of a mesh, an axis-aligned box or a sphere: the TLAS leaves.
struct GpuObject {
    vec4 world_to_object0; // rows of the 3x4 affine world->object matrix (instances)
    vec4 world_to_object1;
    vec4 world_to_object2;
    vec4 object_to_world0; // rows of the 3x4 affine object->world matrix (instances)
    vec4 object_to_world1;
    vec4 object_to_world2;
    vec4 a; // box: min; sphere: centre xyz, radius w
    vec4 b; // box: max
    uint kind;
    uint material;
    uint blas_root; // index of the mesh's root node in BLAS_NODES
    uint triangle_base; // index of the mesh's first triangle in TRIANGLES
    uint emitter; // index into EMITTERS of this object's first emitter, or NO_EMITTER
    uint triangle_count; // the mesh's triangles (instances)
    uint surface; // OBJECT_* flags: which of its triangles' points rays meet (instances)
    float alpha_cutoff; // OBJECT_ALPHA_MASK: present where alpha >= this
};

// A material's use of a texture (MODEL_METALLIC_ROUGHNESS): which, through which texture
// coordinates, moved by KHR_texture_transform. The lookup is at (dot(u_row.xyz, (u, v, 1)),
// dot(v_row.xyz, (u, v, 1))).
struct GpuTextureSlot {
    vec4 u_row;
    vec4 v_row;
    uint texture; // index into TEXTURES, or NO_TEXTURE
    uint texcoord; // 0: TEXCOORD_0, 1: TEXCOORD_1
    uint pad0;
    uint pad1;
};

// A material of either model (GpuMaterial.model); each reads only its own fields.
#define MODEL_THESIS 0u             // the thesis' Lambert + Phong (brdf.glsl): kd, ks
#define MODEL_METALLIC_ROUGHNESS 1u // glTF 2.0's (gltf_brdf.glsl): base_color, metallic, roughness
struct GpuMaterial {
    vec4 kd; // MODEL_THESIS: xyz = k_d, w = Phong exponent alpha (+inf: perfect mirror)
    vec4 ks; // MODEL_THESIS: xyz = k_s, w = p_S, the thesis' specular selection probability (eq. 3.11)
    vec4 emission; // xyz = radiance (both models)
    vec4 base_color; // MODEL_METALLIC_ROUGHNESS: rgb = linear base colour factor, a = alpha factor
    float metallic; // MODEL_METALLIC_ROUGHNESS
    float roughness; // MODEL_METALLIC_ROUGHNESS: perceptual; the GGX width is its square
    uint model; // MODEL_*
    float normal_scale; // MODEL_METALLIC_ROUGHNESS: normal_texture's x and y scale
    GpuTextureSlot base_color_texture; // rgb x base_color (sRGB texels)
    GpuTextureSlot metallic_roughness_texture; // b x metallic, g x roughness (linear)
    GpuTextureSlot emissive_texture; // rgb x emission (sRGB texels)
    GpuTextureSlot normal_texture; // tangent-space normal (linear texels)
};

// A light for next-event estimation: a world-space triangle, a box or a sphere (area
// lights), or a punctual light (KHR_lights_punctual). Next-event estimation picks one in
// proportion to its estimated power (scene/light_selection.rs) through an alias table kept
// in the emitters themselves: bucket i (chosen uniformly) is emitter i with probability
// `keep`, else emitter `alias`.
struct GpuEmitter {
    vec4 p0; // triangle: v0; box: min; sphere: centre xyz, radius w; point, spot: position
    vec4 p1; // triangle: v1; box: max; spot, directional: the unit direction light travels
    vec4 p2; // triangle: v2
    vec4 emission; // xyz = radiance (area lights) or radiant intensity (point, spot: candela
                   // as fovea's radiance x m^2) or irradiance (directional: lux); w = area
    uint kind;
    uint object;
    uint alias; // the alias table's other emitter for bucket i
    float keep; // the probability that bucket i gives emitter i itself
    float pmf; // the probability that next-event estimation picks this emitter
    float range; // point, spot: KHR_lights_punctual's range (0: unlimited)
    float spot_scale; // spot: the extension's angular falloff, saturate(cos * scale + offset)^2
    float spot_offset;
};

struct GpuSceneInfo {
    vec4 sky_zenith;
    vec4 sky_horizon;
    vec4 sky_ground;
    uint emitter_count;
    uint object_count;
    uint tlas_node_count;
    uint tlas_root; // node index of the TLAS's root in NODES (after every BLAS)
    uint env_width; // BINDING_ENVIRONMENT's texels per row (0: no environment map)
    uint env_height;
    float env_rotate_cos; // the environment's turn about +Y (a direction d reads the map at
    float env_rotate_sin; // d turned back by it)
    float env_pmf; // the probability that next-event estimation picks the environment
    uint pad0;
    uint pad1;
    uint pad2;
};

// Push constants: every pass's struct is at most 128 bytes (the guaranteed push-constant
// size) and names each of its fields for that pass alone. A shader says which struct it takes
// by defining PASS_PUSH before its includes (bindings.glsl declares `pc` from it).

// The eye's camera, as every pass of a frame sees it.
struct PushCamera {
    vec4 position;
    vec4 right;
    vec4 up;
    vec4 forward;
    vec4 tan; // tan of the view's left, right, up, down half-angles (OpenXR convention)
};

// The eye's image and its part of the frame's buffers.
struct PushEye {
    uint width;
    uint height;
    uint index; // 0 left (or mono), 1 right: output column offset index * width, seed stream
    uint seed;
    uint layer_base; // the frame slot's first entry of LAYERS (frames in flight: one set each)
    uint layer_count; // layers per eye; this eye's are LAYERS[layer_base + index*layer_count ..]
    uint work_stride; // plan, trace: this eye's work list starts at WORK[index * work_stride]
    uint history; // 0: no history; else HISTORY_ON | read plane << 1 | frame slot << 2
    uint debug; // DEBUG_*
};

// plan, trace, resolve and temporal: one eye of the frame.
struct EyePush {
    PushCamera cam;
    PushEye eye;
    uint albedo; // ALBEDO_ON: trace writes LATTICE_ALBEDO, temporal keeps HISTORY_ALBEDO (its
                 // clamp within a surface); | ALBEDO_DIVIDED while a layer denoises: temporal
                 // shows the frame divided by it, denoise.comp's last iteration multiplies it
                 // back; | ALBEDO_MOMENTS_CARRIED when both this frame and the one before
                 // divide (temporal keeps the illumination's moments only then); | ALBEDO_CARRIED
                 // when the frame before wrote HISTORY_ALBEDO too (else
                 // temporal starts it afresh)
    uint lattice_base; // this eye's first LATTICE entry, where its per-eye texel views start
                       // (GpuLayer.first already counts it)
    uint pad2;
};

// denoise.comp: one iteration over one eye.
struct DenoisePush {
    PushCamera cam;
    PushEye eye;
    uint iteration; // taps 2^iteration pixels apart
    uint pad0; // (which buffer an iteration reads and writes is in its bindings)
    uint last; // 1: the last iteration, which multiplies the albedo back (EyePush.albedo)
};

// accumulate.comp: one eye's pixels added to a running mean.
struct AccumulatePush {
    PushCamera cam;
    PushEye eye;
    uint mean_layer; // the running mean's layer of LAYER_IMAGES
    uint frames_before; // frames already in that mean (0 starts a new one)
    uint pad0;
};

// display.comp: OUTPUT (scene-referred) into DISPLAY (display-referred linear, 0..1), as
// src/render/display.rs's DisplayTransform::apply: x 2^exposure, then the tone mapper.
#define TONEMAP_CLAMP 0
#define TONEMAP_PBR_NEUTRAL 1
struct DisplayPush {
    uint width; // the images' width (eyes side by side) and height
    uint height;
    float scale; // 2^exposure
    uint tonemap; // TONEMAP_*
};

// raycast.comp: a batch of probe rays.
struct RaycastPush {
    uint probe_count;
};

// brdf_probe.comp: a batch of BRDF queries.
struct BrdfProbePush {
    uint query_count;
};

// One layer of one eye for this frame: the O(layers) numbers the CPU writes per frame, from
// which plan.comp decides which lattice points are traced and resolve.comp composes the image.
// Angles are radians from the gaze direction; directions are in the eye's view space.
struct GpuLayer {
    vec4 gaze; // xyz: the unit gaze direction, w: the blend band
    // Cosines of the angle limits, so per-point tests are one dot product (a point is within
    // a limit when dot(direction, centre) > cos). -2: no limit; 2: nothing is within.
    vec4 plan_cos; // traced region, margins included: x occlusion (from the axis), y outer, z inner
    vec4 resolve_cos; // x: outer, y: outer - band, z: occlusion
    vec4 pixel_tan; // xy: tangent-space point of pixel (0, 0)'s centre; zw: its step per pixel
    int anchor_x; // pixel of lattice point (0, 0): the gaze pixel, or 0,0 for the background
    int anchor_y;
    int spacing;
    uint spp;
    int box_i0; // lattice points on the image and in the buffer: i in box_i0 + [0, box_cols)
    int box_j0;
    uint box_cols;
    uint box_rows;
    int col_min; // the ray buffer's extent: point (i, j) is LATTICE[first + (j - row_min) *
    int row_min; //   cols + (i - col_min)]
    uint cols;
    uint first;
    uint box_prefix; // plan.comp's first thread (run) of this layer's box
    uint mask_plane; // VISIBILITY plane of the points this layer needs (any value without a mask)
    float outer; // radius: shown where angle < outer (NO_LIMIT: background); blends inside it
    uint plan_runs; // plan.comp's threads for this eye (its layers' boxes' runs together), the
                    // same in each of its layers: the gaze decides it, so it is written with
                    // the gaze, right before the frame is submitted (not a push constant)
    uint denoise; // denoise.comp's iterations over the pixels shown from this layer
    // lattice_filter.comp's Gaussian width: filter_mar times the eye's minimum angle of
    // resolution at the point's eccentricity, and at least filter_px pixels (both 0: none)
    float filter_mar;
    float filter_px;
    // denoise.comp's width limit: an iteration runs at a pixel only while the filter's width
    // stays within denoise_mar minimum angles of resolution at its eccentricity (0: no limit)
    float denoise_mar;
    // Fractional sampling (foveation/fraction.rs): the layer traces 1 in `fraction` (1, 2 or 4)
    // of its lattice points this frame, those of pattern `fraction_phase`; plan.comp lists the
    // others it needs in the fill list and lattice_fill.comp fills them from their traced
    // neighbours. The phase turns with the history, so every point is traced in turn.
    uint fraction;
    uint fraction_phase;
    // The trace's threads for each of this layer's points (a power of two, at most
    // MAX_TRACE_LANES): lane p traces samples p, p + lanes, ... (renderer.rs, trace_lanes).
    uint lanes;
    // The largest `lanes` of the eye's layers, the same in each: plan.comp reserves work-list
    // slots in multiples of it, so a point's lanes are aligned and share a workgroup.
    uint lane_unit;
    // denoise.comp's luminance edge-stop, in standard deviations of the local noise
    float denoise_sigma;
    uint pad0; // (std430 rounds the struct to 16 bytes)
    uint pad1;
    uint pad2;
};

// ---- temporal history (glsl/temporal.comp) ----------------------------------------------------
#define HISTORY_ON 1
#define ALBEDO_ON 1 // EyePush.albedo's bits
#define ALBEDO_CARRIED 2
#define ALBEDO_DIVIDED 4
#define ALBEDO_MOMENTS_CARRIED 8 // the frame before divided too: HISTORY_ALBEDO has its moments
// A surface (LATTICE_SURFACE, HISTORY_SURFACE) is a uvec4: x the distance from the camera along
// the camera ray of the point's first sample (float bits; SURFACE_NONE: the ray left the
// scene), y the unit normal
// facing the camera (octahedral, packSnorm2x16), z the object (TLAS index), w its material
// (z NO_OBJECT and w NO_MATERIAL: none).
#define SURFACE_NONE 0xbf800000u // -1.0f
#define SURFACE_HIDDEN 0xfffffffeu // material of a pixel the lens or the occlusion mask hides

// One eye's view of the frame before, for reprojecting its history into this frame.
struct GpuHistoryView {
    vec4 position; // the earlier frame's camera (PushCamera of that frame)
    vec4 right;
    vec4 up;
    vec4 forward;
    vec4 tan;
    uint valid; // 0: no usable history (first frame, reset, another image size): start afresh
    uint moved; // 1: the camera moved since that frame (history is resampled and capped)
    uint cap; // in motion, a pixel's history counts at most this many samples (exponential beyond)
    uint pad0;
};

struct GpuProbeRay {
    vec4 origin; // w = t_min
    vec4 direction; // w = t_max
};

struct GpuProbeHit {
    float t; // +inf when nothing was hit
    uint object; // TLAS object index (after BVH reordering) or NO_OBJECT
    uint primitive; // triangle index within TRIANGLES, or NO_PRIMITIVE
    uint overflow; // 1 when the traversal stack overflowed
};

// The BRDF probe (brdf_probe.comp): glTF's BRDF as the integrators sample and evaluate it, in
// the frame where the surface normal is +z, for the sampling and reciprocity checks.
struct GpuBrdfQuery {
    vec4 wo; // xyz: the unit direction toward the viewer
    vec4 wi; // xyz: a unit direction to evaluate f and the density at
    vec4 u; // x: the lobe choice, yz: the direction's two uniform numbers (one sample)
    uint material; // index into MATERIALS (MODEL_METALLIC_ROUGHNESS)
    uint pad0;
    uint pad1;
    uint pad2;
};

struct GpuBrdfAnswer {
    vec4 sampled; // xyz: the direction sampled with u, w: its density (0: below the surface)
    vec4 weight; // rgb: f cos / density of that sample (what a path's throughput is multiplied by)
    vec4 value; // rgb: f(wo, wi) at the query's wi, w: the density of sampling wi
};

// ---- progressive accumulation and the viewer's debug views (accumulate.comp) ----------------
// accumulate.comp adds OUTPUT (a just-rendered frame) to a running mean kept in LAYER_IMAGES
// layer AccumulatePush.mean_layer, AccumulatePush.frames_before frames having been added before
// (0 starts a new mean), then writes what PushEye.debug asks for back into OUTPUT.
#define ACCUM_LAYER_MAIN 0    // the mean of the frames the viewer shows
#define ACCUM_LAYER_REGULAR 1 // the mean of regular frames at the same seeds (difference view)
#define ACCUM_LAYERS 2
#define ACCUM_SHOW_MEAN 0     // the running mean
#define ACCUM_SHOW_NOTHING 1  // accumulate only; OUTPUT keeps the frame
#define ACCUM_SHOW_DIFF 2     // |main mean - regular mean| x ACCUM_DIFF_GAIN
#define ACCUM_SHOW_HEAT 3     // camera samples per pixel so far, log2 on a colour ramp
// Differences are mostly a few percent of the image: x4 makes them visible on a display.
#define ACCUM_DIFF_GAIN 4
// The heat map's range, log2 samples per pixel: 1/64 (blue) to 1024 (dark red).
#define ACCUM_HEAT_LOG2_MIN -6 // src/shader_layout.rs mirrors it (build.rs skips negatives)
#define ACCUM_HEAT_LOG2_MAX 10

#endif
