// Declarations of every set-0 resource and specialization constant, from shared.h's numbers.
#ifndef FOVEA_BINDINGS_GLSL
#define FOVEA_BINDINGS_GLSL
#include "shared.h"

layout(constant_id = SPEC_HAS_TRIANGLES) const bool HAS_TRIANGLES = true;
layout(constant_id = SPEC_HAS_BOXES) const bool HAS_BOXES = true;
layout(constant_id = SPEC_HAS_SPHERES) const bool HAS_SPHERES = true;
layout(constant_id = SPEC_HAS_SPECULAR) const bool HAS_SPECULAR = true;
layout(constant_id = SPEC_HAS_EMITTERS) const bool HAS_EMITTERS = true;
layout(constant_id = SPEC_MAX_BOUNCES) const uint MAX_BOUNCES = 8;
layout(constant_id = SPEC_INTEGRATOR) const uint INTEGRATOR = INTEGRATOR_PT;
layout(constant_id = SPEC_PROFILE) const bool PROFILE = false;

layout(std430, set = 0, binding = BINDING_BLAS_NODES) readonly buffer BlasNodes { uvec4 blas_nodes[]; };
layout(std430, set = 0, binding = BINDING_TLAS_NODES) readonly buffer TlasNodes { uvec4 tlas_nodes[]; };
layout(std430, set = 0, binding = BINDING_TRIANGLES) readonly buffer Triangles { GpuTriangle triangles[]; };
layout(std430, set = 0, binding = BINDING_OBJECTS) readonly buffer Objects { GpuObject objects[]; };
layout(std430, set = 0, binding = BINDING_MATERIALS) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, set = 0, binding = BINDING_EMITTERS) readonly buffer Emitters { GpuEmitter emitters[]; };
layout(std430, set = 0, binding = BINDING_SCENE_INFO) readonly buffer SceneInfoBuf { GpuSceneInfo scene_info; };
layout(std430, set = 0, binding = BINDING_STATS) buffer Stats { uint stats[]; };
layout(set = 0, binding = BINDING_OUTPUT, rgba32f) uniform image2D out_image;
layout(std430, set = 0, binding = BINDING_PROBE_RAYS) readonly buffer ProbeRays { GpuProbeRay probe_rays[]; };
layout(std430, set = 0, binding = BINDING_PROBE_HITS) writeonly buffer ProbeHits { GpuProbeHit probe_hits[]; };

layout(set = 0, binding = BINDING_LAYER_IMAGES, rgba32f) uniform image2DArray layer_images;
// Only trace.comp writes LATTICE (it defines WRITES_LATTICE); read-only everywhere else, so
// the validation layer's synchronization checks see the other passes as its readers.
#ifdef WRITES_LATTICE
layout(std430, set = 0, binding = BINDING_LATTICE) writeonly buffer LatticeBuf { vec4 lattice[]; };
#else
layout(std430, set = 0, binding = BINDING_LATTICE) readonly buffer LatticeBuf { vec4 lattice[]; };
#endif
layout(std430, set = 0, binding = BINDING_WORK) buffer WorkBuf { uint work[]; };
layout(std430, set = 0, binding = BINDING_LAYERS) readonly buffer Layers { GpuLayer layers[]; };
layout(std430, set = 0, binding = BINDING_VISIBILITY) readonly buffer Visibility { uint visibility[]; };

layout(push_constant) uniform Push { PushConstants pc; };

#endif
