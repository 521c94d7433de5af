// The lattice's values and surfaces as texels (LATTICE_TEXELS, LATTICE_SURFACE_TEXELS), for the
// passes whose push is EyePush: each eye has its own view, starting at its first entry
// (pc.lattice_base), so that maxTexelBufferElements bounds one eye's lattice, not both eyes'.
// A lattice entry (GpuLayer.first counts the eye's base) is read from its eye's view at
// entry - lattice_base; the eye is the same across a dispatch, so the index is uniform.
#ifndef LATTICE_TEXELS_GLSL
#define LATTICE_TEXELS_GLSL

// Lattice entry i's value (one vector load per lane on lavapipe).
vec4 lattice_texel(uint i) {
    return uintBitsToFloat(texelFetch(lattice_texels[pc.eye.index], int(i - pc.lattice_base)));
}

// The surface at lattice entry i.
uvec4 lattice_surface_at(uint i) {
    return texelFetch(lattice_surface_texels[pc.eye.index], int(i - pc.lattice_base));
}

#endif
