#version 460
// The plan pass: one thread per run of PLAN_RUN lattice points of one row of one layer's box
// (the layer's lattice points on the image) of one eye. The thread decides which of its
// points are traced this frame (plan.glsl), reserves their slots in the eye's dense work list
// with one atomic and writes them in row order (neighbouring rays stay neighbours: coherent
// traversals). The per-layer counts are the frame's traced samples.
//
// Compaction rather than "dispatch every box and let each trace thread plan its own point":
// on lavapipe (8-wide SIMD per invocation batch) the early exits of a ring layer's box leave
// lanes idle through whole paths. Measured at 1440x1600, thesis layers, Vive Pro Eye fov, 2-core
// VM: the trace of the compacted list took 0.60-0.69x the time of the planning trace on
// bunny-low, bunny-high, cubes-441 and mirror-room (e.g. cubes-441 forward 297 vs 494 ms,
// mirror-room 624 vs 1146 ms) for a plan pass of a few percent of that.
//
// Runs, not one thread per point, and no shared memory: lavapipe's cost per invocation and
// per barrier was larger than a point's test (one thread per point with a workgroup-shared
// counter took 200 ms of a 1440x1600 regular frame's plan).
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH EyePush
#include "plan.glsl"

layout(local_size_x = PLAN_WORKGROUP_SIZE) in;

void main() {
    uint t = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * PLAN_WORKGROUP_SIZE)
           + gl_GlobalInvocationID.x;
    uint k;
    ivec2 ij;
    uint n;
    if (!plan_run(t, k, ij, n)) return;
    uint traced = 0u; // bit i: point ij + (i, 0) is traced
    uint mask_words = visibility[0];
    bool everything = layers[k].plan_cos.xyz == vec3(-2.0, -2.0, 2.0) && mask_words == 0u;
    if (everything) {
        traced = n == 32u ? ~0u : (1u << n) - 1u; // regular rendering: no limit, no mask
    } else {
        for (uint i = 0u; i < n; ++i) {
            if (traced_point(k, lattice_pixel(k, ij + ivec2(i, 0)), mask_words)) traced |= 1u << i;
        }
    }
    uint count = bitCount(traced);
    if (count == 0u) return;
    uint layer = k - eye_layer_base();
    uint slot = pc.eye.index * pc.eye.work_stride
              + atomicAdd(stats[STAT_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT], count);
    atomicAdd(stats[STAT_LAYER_POINTS + pc.eye.index * MAX_LAYERS + layer], count);
    // A row's points are consecutive lattice entries.
    uint first = lattice_index(k, ij) | (layer << WORK_LAYER_SHIFT);
    for (; traced != 0u; traced &= traced - 1u) {
        work[slot++] = first + uint(findLSB(traced));
    }
}
