#version 460
// After the plan pass: turns each eye's work-list and fill-list lengths into the trace's and
// the fill's workgroup counts (one workgroup per eye). x stays within the guaranteed limit;
// the rest goes to y, and trace.comp and lattice_fill.comp skip the threads past their
// list's end.
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH none
#define NO_PUSH
#include "bindings.glsl"

layout(local_size_x = 1) in;

// The workgroup counts of the dispatch whose block (x, y, z, list length) starts at STATS[at].
void size_dispatch(uint at) {
    uint groups = (stats[at + STAT_WORK_COUNT] + TRACE_WORKGROUP_SIZE - 1u) / TRACE_WORKGROUP_SIZE;
    uint x = min(groups, uint(MAX_GROUPS_X));
    stats[at] = x;
    stats[at + 1u] = x == 0u ? 1u : (groups + x - 1u) / x;
    stats[at + 2u] = 1u;
}

void main() {
    size_dispatch(STAT_DISPATCH + gl_WorkGroupID.x * 4u);
    size_dispatch(STAT_FILL_DISPATCH + gl_WorkGroupID.x * 4u);
}
