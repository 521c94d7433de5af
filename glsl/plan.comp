#version 460
// The plan pass: one thread per lattice point of every layer's box (the layer's lattice
// points on the image) of one eye. Each thread decides whether its point is traced this
// frame (plan.glsl) and the traced ones are compacted into the eye's dense work list, which
// trace.comp walks through an indirect dispatch. A workgroup reserves its slots with one
// atomic, so the list keeps the boxes' row order within a workgroup (neighbouring rays stay
// neighbours: coherent traversals). The per-layer counts are the frame's traced samples.
//
// Compaction, not "dispatch every box and exit early in the trace": on lavapipe a
// workgroup's invocations run as 8-wide SIMD, so early exits in a ring layer's box (its
// inner disc is empty) leave lanes idle through the whole path; a dense list keeps every
// lane busy, for a pass that costs a few percent of the trace (measured: see the README).
#extension GL_GOOGLE_include_directive : require
#include "plan.glsl"

layout(local_size_x = PLAN_WORKGROUP_SIZE) in;

shared uint group_count;
shared uint group_base;
shared uint group_layer_points[MAX_LAYERS];

void main() {
    uint t = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * PLAN_WORKGROUP_SIZE)
           + gl_GlobalInvocationID.x;
    uint local = gl_LocalInvocationIndex;
    if (local == 0u) group_count = 0u;
    if (local < MAX_LAYERS) group_layer_points[local] = 0u;
    barrier();

    uint base = pc.eye * pc.layer_count;
    uint k;
    ivec2 ij;
    bool traced = plan_point(t, k, ij) && traced_point(k, lattice_pixel(k, ij));
    uint slot = 0u;
    if (traced) {
        slot = atomicAdd(group_count, 1u);
        atomicAdd(group_layer_points[k - base], 1u);
    }
    barrier();

    uint dispatch = STAT_DISPATCH + pc.eye * 4u;
    if (local == 0u && group_count > 0u) {
        group_base = atomicAdd(stats[dispatch + STAT_WORK_COUNT], group_count);
    }
    if (local < pc.layer_count && group_layer_points[local] > 0u) {
        atomicAdd(stats[STAT_LAYER_POINTS + pc.eye * MAX_LAYERS + local], group_layer_points[local]);
    }
    barrier();
    if (traced) {
        work[pc.eye * pc.work_stride + group_base + slot] =
            lattice_index(k, ij) | ((k - base) << WORK_LAYER_SHIFT);
    }
}
