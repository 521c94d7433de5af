#version 460
// After the plan pass: turns each eye's work-list length into the trace dispatch's
// workgroup counts (one workgroup per eye). x stays within the guaranteed limit; the rest
// goes to y, and trace.comp skips the threads past the list's end.
#extension GL_GOOGLE_include_directive : require
#define PASS_PUSH none
#define NO_PUSH
#include "bindings.glsl"

layout(local_size_x = 1) in;

void main() {
    uint dispatch = STAT_DISPATCH + gl_WorkGroupID.x * 4u;
    uint groups = (stats[dispatch + STAT_WORK_COUNT] + TRACE_WORKGROUP_SIZE - 1u) / TRACE_WORKGROUP_SIZE;
    uint x = min(groups, uint(MAX_GROUPS_X));
    stats[dispatch] = x;
    stats[dispatch + 1u] = x == 0u ? 1u : (groups + x - 1u) / x;
    stats[dispatch + 2u] = 1u;
}
