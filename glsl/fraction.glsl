// Fractional sampling (src/foveation/fraction.rs, which decides the same with the same integer
// operations): layer k traces 1 in GpuLayer.fraction of its lattice points this frame, the
// pattern GpuLayer.fraction_phase picks: a checkerboard for 2, one point of every 2x2 block for
// 4 (the block's cell lattice_shift(phase, 2): (0,0), (1,1), (0,1), (1,0)). A skipped point
// that the layer needs is filled from its traced neighbours while its owner (the traced point
// next to it) is traced, else traced itself.
#ifndef FOVEA_FRACTION_GLSL
#define FOVEA_FRACTION_GLSL
#include "bindings.glsl"

// The 2x2 block's traced cell in phase p of a fraction-4 layer (lattice_shift(p, 2)).
ivec2 quarter_cell(uint p) {
    const ivec2 CELLS[4] = ivec2[4](ivec2(0, 0), ivec2(1, 1), ivec2(0, 1), ivec2(1, 0));
    return CELLS[p & 3u];
}

// Does layer k trace its lattice point ij this frame (were it inside its region)?
bool fraction_traces(uint k, ivec2 ij) {
    uint fraction = layers[k].fraction;
    uint p = layers[k].fraction_phase;
    if (fraction == 2u) return ((ij.x + ij.y + int(p)) & 1) == 0;
    if (fraction == 4u) return all(equal(ij & 1, quarter_cell(p)));
    return true;
}

// The traced point next to layer k's skipped point ij.
ivec2 fraction_owner(uint k, ivec2 ij) {
    uint fraction = layers[k].fraction;
    if (fraction == 2u) return ij - ivec2(1, 0);
    if (fraction == 4u) return ij - ((ij - quarter_cell(layers[k].fraction_phase)) & 1);
    return ij;
}

#endif
