#version 460
// The fill pass (fractional layers, fraction.glsl): after trace, one thread per point of the
// eye's fill list, the points a layer skipped this frame but needs. A point becomes the mean
// of the traced points of its layer among its 3x3 neighbours: its left and right ones, or
// upper and lower ones, in a checkerboard (fraction 2), and the two or four of its 2x2 cell's
// pattern around it for fraction 4, which is bilinear interpolation on the coarser pattern.
// Its owner is always among them (the plan pass skipped it only then). Its alpha is 0 where a
// traced point's is 1: the temporal pass adds to a pixel's history only samples traced there.
// With history (KEEPS_SURFACES) it takes its owner's surface and albedo, as a sparse layer's
// pixel takes its nearest lattice point's.
//
// Its cost follows the lattice: a few loads and a region test per neighbour of a skipped
// point, a small part of tracing one path.
#extension GL_GOOGLE_include_directive : require
#define FILLS_LATTICE
#define PASS_PUSH EyePush
#include "plan.glsl"
#include "fraction.glsl"

layout(local_size_x = TRACE_WORKGROUP_SIZE) in;

void main() {
    uint thread = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * TRACE_WORKGROUP_SIZE)
                + gl_GlobalInvocationID.x;
    if (thread >= stats[STAT_FILL_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT]) return;
    uint item = work[(pc.eye.index + 1u) * pc.eye.work_stride - 1u - thread];
    uint k;
    uint entry;
    work_item(item, k, entry);
    ivec2 ij = lattice_point(k, entry);
    TracedRegion region = traced_region(k, visibility[0]);

    vec3 sum = vec3(0.0);
    float count = 0.0;
    for (int i = 0; i < 9; ++i) {
        ivec2 q = ij + ivec2(i % 3 - 1, i / 3 - 1);
        if (i == 4 || !in_box(k, q)) continue;
        if (!fraction_traces(k, q) || !traced_in(region, lattice_pixel(k, q))) continue;
        sum += lattice[lattice_index(k, q)].rgb;
        count += 1.0;
    }
    // count >= 1: the owner is traced (plan.comp).
    lattice[entry] = vec4(sum / max(count, 1.0), 0.0);
#ifdef KEEPS_SURFACES
    uint owner = lattice_index(k, fraction_owner(k, ij));
    lattice_surface[entry] = lattice_surface[owner];
    if (pc.albedo != 0u) lattice_albedo[entry] = lattice_albedo[owner];
#endif
}
