// A surface as the temporal history stores it (shared.h's SURFACE_* encoding): distance,
// normal in octahedral form (packSnorm2x16), object and material. trace.comp encodes it at a
// lattice point's pixel centre; temporal.comp and denoise.comp decode it.
#ifndef FOVEA_SURFACE_GLSL
#define FOVEA_SURFACE_GLSL

// Octahedral encoding of a unit vector into [-1, 1]^2.
vec2 to_octahedral(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.xy;
    if (n.z < 0.0) e = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return e;
}

// The unit vector of an octahedral encoding.
vec3 from_octahedral(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return normalize(n);
}

#endif
