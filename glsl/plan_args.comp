#version 460
// After the plan pass (one workgroup per eye): turns the eye's work-list and fill-list lengths
// into the workgroup counts of the lattice filter, the trace (TRACE_SPLIT threads per point)
// and the fill. x stays within the guaranteed limit; the rest goes to y, and the three passes
// skip the threads past their list's end.
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH none
#define NO_PUSH
#include "bindings.glsl"

layout(local_size_x = 1) in;

// Writes at STATS[at] the workgroup counts (x, y, z) of a dispatch of `lanes` threads per
// entry of the list whose length is STATS[list + STAT_WORK_COUNT].
void size_dispatch(uint list, uint at, uint lanes) {
    uint threads = stats[list + STAT_WORK_COUNT] * lanes;
    uint groups = (threads + TRACE_WORKGROUP_SIZE - 1u) / TRACE_WORKGROUP_SIZE;
    uint x = min(groups, uint(MAX_GROUPS_X));
    stats[at] = x;
    stats[at + 1u] = x == 0u ? 1u : (groups + x - 1u) / x;
    stats[at + 2u] = 1u;
}

void main() {
    uint eye = gl_WorkGroupID.x * 4u;
    size_dispatch(STAT_DISPATCH + eye, STAT_DISPATCH + eye, 1u); // the lattice filter's
    size_dispatch(STAT_DISPATCH + eye, STAT_TRACE_DISPATCH + eye, TRACE_SPLIT);
    size_dispatch(STAT_FILL_DISPATCH + eye, STAT_FILL_DISPATCH + eye, 1u);
}
