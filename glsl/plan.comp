#version 460
// The plan pass: one thread per run of PLAN_RUN lattice points of one row of one layer's box
// (the layer's lattice points on the image) of one eye. The thread decides which of its
// points are traced this frame (plan.glsl), reserves their slots in the eye's dense work list
// with one atomic and writes them in row order (neighbouring rays stay neighbours: coherent
// traversals). The per-layer counts are the frame's traced samples. A fractional layer's
// points that this frame skips go to the eye's fill list instead (fraction.glsl).
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
#include "fraction.glsl"

layout(local_size_x = PLAN_WORKGROUP_SIZE) in;

// Does fractional layer k skip its point ij (inside its region) this frame? Only when its
// pattern skips it and its owner is traced too (inside the layer's box and region), so that
// every skipped point has a traced neighbour to be filled from.
bool skips(uint k, ivec2 ij, uint mask_words) {
    if (fraction_traces(k, ij)) return false;
    ivec2 owner = fraction_owner(k, ij);
    return in_box(k, owner) && traced_point(k, lattice_pixel(k, owner), mask_words);
}

void main() {
    uint t = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * PLAN_WORKGROUP_SIZE)
           + gl_GlobalInvocationID.x;
    uint k;
    ivec2 ij;
    uint n;
    if (!plan_run(t, k, ij, n)) return;
    uint traced = 0u; // bit i: point ij + (i, 0) is traced
    uint filled = 0u; // bit i: point ij + (i, 0) is skipped this frame but needed (fraction)
    uint mask_words = visibility[0];
    bool fractional = layers[k].fraction > 1u;
    bool everything = layers[k].plan_cos.xyz == vec3(-2.0, -2.0, 2.0) && mask_words == 0u;
    if (everything && !fractional) {
        traced = n == 32u ? ~0u : (1u << n) - 1u; // regular rendering: no limit, no mask
    } else {
        for (uint i = 0u; i < n; ++i) {
            ivec2 point = ij + ivec2(i, 0);
            if (!traced_point(k, lattice_pixel(k, point), mask_words)) continue;
            if (fractional && skips(k, point, mask_words)) {
                filled |= 1u << i;
            } else {
                traced |= 1u << i;
            }
        }
    }
    uint layer = k - eye_layer_base();
    // A row's points are consecutive lattice entries.
    uint first = lattice_index(k, ij) | (layer << WORK_LAYER_SHIFT);
    uint count = bitCount(traced);
    if (count > 0u) {
        // GpuLayer.lanes slots (trace threads) per point, the reservation padded with
        // WORK_EMPTY to a multiple of lane_unit: every reservation starts at a multiple of it,
        // so each point's lanes are aligned and share a workgroup (trace.comp adds them up).
        uint lanes = layers[k].lanes;
        uint unit = layers[k].lane_unit;
        uint slots = count * lanes;
        uint reserved = (slots + unit - 1u) / unit * unit;
        uint slot = pc.eye.index * pc.eye.work_stride
                  + atomicAdd(stats[STAT_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT], reserved);
        atomicAdd(stats[STAT_LAYER_POINTS + pc.eye.index * MAX_LAYERS + layer], count);
        for (; traced != 0u; traced &= traced - 1u) {
            uint item = first + uint(findLSB(traced));
            for (uint p = 0u; p < lanes; ++p) work[slot++] = item;
        }
        for (; slots < reserved; ++slots) work[slot++] = WORK_EMPTY;
    }
    uint fills = bitCount(filled);
    if (fills > 0u) {
        // The fill list grows down from the top of the eye's segment: a point is traced or
        // filled, never both, so the two lists never meet.
        uint top = (pc.eye.index + 1u) * pc.eye.work_stride - 1u
                 - atomicAdd(stats[STAT_FILL_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT], fills);
        for (; filled != 0u; filled &= filled - 1u) {
            work[top--] = first + uint(findLSB(filled));
        }
    }
}
