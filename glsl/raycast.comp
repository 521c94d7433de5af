#version 460
// Closest-hit queries for tests: one probe ray per invocation through the same traversal the
// integrators use, so GPU hit distances can be compared with a CPU reference.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#define PASS_PUSH RaycastPush
#include "bvh.glsl"

layout(local_size_x = PROBE_WORKGROUP_SIZE) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.probe_count) return;
    GpuProbeRay r = probe_rays[i];
    Hit h = trace_scene(r.origin.xyz, r.direction.xyz, r.origin.w, r.direction.w, false);
    GpuProbeHit out_hit;
    out_hit.t = h.t;
    out_hit.object = h.object;
    out_hit.primitive = h.primitive;
    out_hit.overflow = h.overflow ? 1u : 0u;
    probe_hits[i] = out_hit;
    if (h.overflow) atomicAdd(stats[STAT_STACK_OVERFLOW], 1u);
}
