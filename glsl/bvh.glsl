// Two-level CWBVH traversal (Ylitie, Karras, Laine 2017, "Efficient incoherent ray traversal
// on GPUs through compressed wide BVHs"), over obvhs' node layout: a TLAS over objects
// (mesh instances, boxes, spheres) and one BLAS per mesh. Each level has its own short stack;
// an overflow is counted (STAT_STACK_OVERFLOW via Hit.overflow), never silently ignored.
#ifndef FOVEA_BVH_GLSL
#define FOVEA_BVH_GLSL
#include "bindings.glsl"
#include "geometry.glsl"

// Ize 2013: widen t_max by 2*gamma(3) so rounding in the slab test never culls a box the ray touches.
const float CONSERVATIVE_TMAX = 1.0000004;
// The quantized slab distances lo * adj_inv_d + adj_o round relative to their two terms, which
// can be far larger than the distance itself (a node origin far behind the ray origin): each
// axis' interval is also widened by 4 ulps of the larger term, absolutely. Without this, rays
// aimed exactly at an edge shared by two boxes (flat faces of a closed mesh) slip between them.
const float SLAB_ROUNDING = 4.0 / 8388608.0;

// With PROFILE, this invocation's traversal work (PROFILE_* counters; trace.comp adds them to
// STAT_PROFILE). Without it every use is compiled away.
uint profile_counts[PROFILE_COUNTERS];

void profile_count(uint counter, uint n) {
    if (PROFILE) profile_counts[counter] += n;
}

// One iteration of a traversal loop: per invocation, and once per subgroup (its elected lane):
// their ratio over the subgroup size is the loop's SIMD occupancy.
void profile_step(uint lane_counter, uint group_counter) {
    if (PROFILE) {
        profile_counts[lane_counter]++;
        if (subgroupElect()) profile_counts[group_counter]++;
    }
}

struct Hit {
    float t;
    uint object;    // TLAS object index, or NO_EMITTER for a miss
    uint primitive; // global triangle index for instances
    bool overflow;
};

// Intersects the 8 quantized children of a node (80 bytes = uvec4[5] at node_index * 5).
// Returns the hit mask: bits 24..31 internal children (in traversal-priority order),
// bits 0..23 leaf triangle slots relative to the node's primitive base.
uint intersect_node(uvec4 n0, uvec4 n1, uvec4 n2, uvec4 n3, uvec4 n4,
                    vec3 o, vec3 inv_d, uint oct_inv4, float t_min, float t_max) {
    vec3 p = uintBitsToFloat(n0.xyz);
    // e[0..2] are the exponents of the per-axis quantization scale.
    vec3 ext = vec3(uintBitsToFloat((n0.w & 0xffu) << 23),
                    uintBitsToFloat(((n0.w >> 8) & 0xffu) << 23),
                    uintBitsToFloat(((n0.w >> 16) & 0xffu) << 23));
    vec3 adj_inv_d = ext * inv_d;
    vec3 adj_o = (p - o) * inv_d;
    vec3 slack = (abs(adj_o) + 255.0 * abs(adj_inv_d)) * SLAB_ROUNDING;
    uint hitmask = 0u;
    for (uint h = 0u; h < 2u; ++h) {
        uint meta4 = h == 0u ? n1.z : n1.w;
        // Internal children have meta 0b001xxxxx with slot+24 in the low bits: bits 3 and 4 set.
        uint is_inner4 = (meta4 & (meta4 << 1)) & 0x10101010u;
        uint inner_mask4 = (is_inner4 >> 4) * 0xffu;
        uint bit_index4 = (meta4 ^ (oct_inv4 & inner_mask4)) & 0x1f1f1f1fu;
        uint child_bits4 = (meta4 >> 5) & 0x07070707u;
        uint lo_x = h == 0u ? n2.x : n2.y, hi_x = h == 0u ? n2.z : n2.w;
        uint lo_y = h == 0u ? n3.x : n3.y, hi_y = h == 0u ? n3.z : n3.w;
        uint lo_z = h == 0u ? n4.x : n4.y, hi_z = h == 0u ? n4.z : n4.w;
        for (uint j = 0u; j < 4u; ++j) {
            uint s = j * 8u;
            vec3 lo = vec3(float((lo_x >> s) & 0xffu), float((lo_y >> s) & 0xffu), float((lo_z >> s) & 0xffu));
            vec3 hi = vec3(float((hi_x >> s) & 0xffu), float((hi_y >> s) & 0xffu), float((hi_z >> s) & 0xffu));
            vec3 t0 = lo * adj_inv_d + adj_o;
            vec3 t1 = hi * adj_inv_d + adj_o;
            vec3 tn = min(t0, t1) - slack;
            vec3 tf = max(t0, t1) + slack;
            float tmin = max(max(tn.x, tn.y), max(tn.z, t_min));
            float tmax = min(min(tf.x, tf.y), min(tf.z, t_max)) * CONSERVATIVE_TMAX;
            if (tmin <= tmax) {
                hitmask |= ((child_bits4 >> s) & 0xffu) << ((bit_index4 >> s) & 0xffu);
            }
        }
    }
    return hitmask;
}

uint octant_inv4(vec3 d) {
    return (d.x < 0.0 ? 0u : 0x04040404u) | (d.y < 0.0 ? 0u : 0x02020202u) | (d.z < 0.0 ? 0u : 0x01010101u);
}

// Closest triangle of one mesh's BLAS along an object-space ray; updates t_max and hit.
// With any_hit, returns at the first hit (shadow rays need no closest one).
void traverse_blas(uint root, uint tri_base, vec3 o, vec3 d, float t_min, inout float t_max,
                   uint object, bool any_hit, inout Hit hit) {
    d = safe_direction(d);
    vec3 inv_d = 1.0 / d;
    uint oct = octant_inv4(d);
    WatertightRay w = watertight_setup(d);
    uvec2 stack[TRAVERSAL_STACK_SIZE];
    uint sp = 0u;
    uvec2 cur = uvec2(0u, 0x80000000u);
    uvec2 prim = uvec2(0u);
    for (;;) {
        profile_step(PROFILE_BLAS_LANE_STEPS, PROFILE_BLAS_GROUP_STEPS);
        while (prim.y != 0u) {
            uint local = uint(findMSB(prim.y));
            prim.y &= ~(1u << local);
            profile_count(PROFILE_TRIANGLES, 1u);
            uint tri = tri_base + prim.x + local;
            GpuTriangle T = triangles[tri];
            float t = intersect_triangle(o, w, T.v0.xyz, T.v1.xyz, T.v2.xyz, t_min, t_max);
            if (t < t_max) {
                t_max = t;
                hit.t = t;
                hit.object = object;
                hit.primitive = tri;
                if (any_hit) return;
            }
        }
        if ((cur.y & 0xff000000u) != 0u) {
            uint hits_imask = cur.y;
            uint child_offset = uint(findMSB(hits_imask));
            cur.y &= ~(1u << child_offset);
            if ((cur.y & 0xff000000u) != 0u) {
                if (sp == TRAVERSAL_STACK_SIZE) {
                    hit.overflow = true;
                    return;
                }
                stack[sp++] = cur;
            }
            uint slot = (child_offset - 24u) ^ (oct & 0xffu);
            uint rel = uint(bitCount(hits_imask & ~(0xffffffffu << slot)));
            uint node = (root + cur.x + rel) * 5u;
            profile_count(PROFILE_BLAS_NODES, 1u);
            uvec4 n1 = blas_nodes[node + 1u];
            uint hm = intersect_node(blas_nodes[node], n1, blas_nodes[node + 2u], blas_nodes[node + 3u],
                                     blas_nodes[node + 4u], o, inv_d, oct, t_min, t_max);
            cur = uvec2(n1.x, (hm & 0xff000000u) | (blas_nodes[node].w >> 24));
            prim = uvec2(n1.y, hm & 0x00ffffffu);
        } else {
            cur = uvec2(0u);
        }
        if (prim.y == 0u && (cur.y & 0xff000000u) == 0u) {
            if (sp == 0u) break;
            cur = stack[--sp];
        }
    }
}

vec3 affine(vec4 r0, vec4 r1, vec4 r2, vec3 p) {
    return vec3(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}

vec3 linear(vec4 r0, vec4 r1, vec4 r2, vec3 v) {
    return vec3(dot(r0.xyz, v), dot(r1.xyz, v), dot(r2.xyz, v));
}

void intersect_object(uint index, vec3 o, vec3 d, vec3 inv_d, float t_min, inout float t_max, bool any_hit,
                      inout Hit hit) {
    GpuObject ob = objects[index];
    if (HAS_TRIANGLES && ob.kind == KIND_INSTANCE) {
        // The object-space direction is not renormalised, so t is the same in both spaces.
        vec3 lo = affine(ob.world_to_object0, ob.world_to_object1, ob.world_to_object2, o);
        vec3 ld = linear(ob.world_to_object0, ob.world_to_object1, ob.world_to_object2, d);
        traverse_blas(ob.blas_root, ob.triangle_base, lo, ld, t_min, t_max, index, any_hit, hit);
    } else if (HAS_BOXES && ob.kind == KIND_BOX) {
        profile_count(PROFILE_PRIMITIVES, 1u);
        float t = intersect_box(o, inv_d, ob.a.xyz, ob.b.xyz, t_min, t_max);
        if (t < t_max) {
            t_max = t;
            hit.t = t;
            hit.object = index;
        }
    } else if (HAS_SPHERES && ob.kind == KIND_SPHERE) {
        profile_count(PROFILE_PRIMITIVES, 1u);
        float t = intersect_sphere(o, d, ob.a.xyz, ob.a.w, t_min, t_max);
        if (t < t_max) {
            t_max = t;
            hit.t = t;
            hit.object = index;
        }
    }
}

// Closest hit in the whole scene along o + t*d, t in (t_min, t_max); with any_hit, the first
// hit found (for shadow rays).
Hit trace_scene(vec3 o, vec3 d, float t_min, float t_max, bool any_hit) {
    Hit hit;
    hit.t = INF;
    hit.object = NO_EMITTER;
    hit.primitive = NO_EMITTER;
    hit.overflow = false;
    if (!(HAS_TRIANGLES || HAS_BOXES || HAS_SPHERES) || scene_info.tlas_node_count == 0u) return hit;
    d = safe_direction(d);
    vec3 inv_d = 1.0 / d;
    uint oct = octant_inv4(d);
    uvec2 stack[TRAVERSAL_STACK_SIZE];
    uint sp = 0u;
    uvec2 cur = uvec2(0u, 0x80000000u);
    uvec2 prim = uvec2(0u);
    for (;;) {
        profile_step(PROFILE_TLAS_LANE_STEPS, PROFILE_TLAS_GROUP_STEPS);
        while (prim.y != 0u) {
            uint local = uint(findMSB(prim.y));
            prim.y &= ~(1u << local);
            intersect_object(prim.x + local, o, d, inv_d, t_min, t_max, any_hit, hit);
            if (hit.overflow || (any_hit && hit.t != INF)) return hit;
        }
        if ((cur.y & 0xff000000u) != 0u) {
            uint hits_imask = cur.y;
            uint child_offset = uint(findMSB(hits_imask));
            cur.y &= ~(1u << child_offset);
            if ((cur.y & 0xff000000u) != 0u) {
                if (sp == TRAVERSAL_STACK_SIZE) {
                    hit.overflow = true;
                    return hit;
                }
                stack[sp++] = cur;
            }
            uint slot = (child_offset - 24u) ^ (oct & 0xffu);
            uint rel = uint(bitCount(hits_imask & ~(0xffffffffu << slot)));
            uint node = (cur.x + rel) * 5u;
            profile_count(PROFILE_TLAS_NODES, 1u);
            uvec4 n1 = tlas_nodes[node + 1u];
            uint hm = intersect_node(tlas_nodes[node], n1, tlas_nodes[node + 2u], tlas_nodes[node + 3u],
                                     tlas_nodes[node + 4u], o, inv_d, oct, t_min, t_max);
            cur = uvec2(n1.x, (hm & 0xff000000u) | (tlas_nodes[node].w >> 24));
            prim = uvec2(n1.y, hm & 0x00ffffffu);
        } else {
            cur = uvec2(0u);
        }
        if (prim.y == 0u && (cur.y & 0xff000000u) == 0u) {
            if (sp == 0u) break;
            cur = stack[--sp];
        }
    }
    return hit;
}

// True when nothing blocks the segment o + t*d, t in (0, t_max) - for shadow rays.
bool unoccluded(vec3 o, vec3 d, float t_max, inout bool overflow) {
    Hit h = trace_scene(o, d, 0.0, t_max, true);
    overflow = overflow || h.overflow;
    return h.t == INF;
}

// World-space geometric normal at a hit (not yet faced toward the ray).
vec3 hit_normal(Hit h, vec3 p) {
    GpuObject ob = objects[h.object];
    if (HAS_TRIANGLES && ob.kind == KIND_INSTANCE) {
        GpuTriangle T = triangles[h.primitive];
        vec3 n = cross(T.v1.xyz - T.v0.xyz, T.v2.xyz - T.v0.xyz);
        // Normals transform by the inverse transpose: the columns of world->object.
        vec3 nw = ob.world_to_object0.xyz * n.x + ob.world_to_object1.xyz * n.y + ob.world_to_object2.xyz * n.z;
        return normalize(nw);
    }
    if (HAS_BOXES && ob.kind == KIND_BOX) return box_normal(p, ob.a.xyz, ob.b.xyz);
    return normalize(p - ob.a.xyz);
}

#endif
