// The scene's ray queries: trace_scene (closest or any hit), unoccluded, hit_normal.
//
// The software traversal: two-level CWBVH traversal (Ylitie, Karras, Laine 2017, "Efficient
// incoherent ray traversal on GPUs through compressed wide BVHs"), over obvhs' node layout: a
// TLAS over objects (mesh instances, boxes, spheres) and one BLAS per mesh, walked by one loop
// (trace_scene) with one short stack for both levels; an overflow is counted
// (STAT_STACK_OVERFLOW via Hit.overflow), never silently ignored. Compiled with RAY_QUERY
// (build.rs's *_rq shaders), trace_scene is the driver's instead (ray_query.glsl).
#ifndef FOVEA_BVH_GLSL
#define FOVEA_BVH_GLSL
#include "bindings.glsl"
#include "coverage.glsl"
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
    uint object;    // TLAS object index, or NO_OBJECT for a miss
    uint primitive; // global triangle index for instances
    bool overflow;
};

vec3 affine(vec4 r0, vec4 r1, vec4 r2, vec3 p) {
    return vec3(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}

vec3 linear(vec4 r0, vec4 r1, vec4 r2, vec3 v) {
    return vec3(dot(r0.xyz, v), dot(r1.xyz, v), dot(r2.xyz, v));
}

#ifdef RAY_QUERY
#include "ray_query.glsl"
#else
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

// The ray as the current level sees it: the world ray in the TLAS, the object-space ray in an
// instance's BLAS (its direction not renormalised, so t is the same in both spaces).
struct LevelRay {
    vec3 o;
    vec3 d;
    vec3 inv_d;
    uint oct;
};

LevelRay level_ray(vec3 o, vec3 d) {
    LevelRay r;
    r.o = o;
    r.d = safe_direction(d);
    r.inv_d = 1.0 / r.d;
    r.oct = octant_inv4(r.d);
    return r;
}

// Closest hit in the whole scene along o + t*d, t in (t_min, t_max); with any_hit, the first
// hit found (for shadow rays).
//
// One loop walks both levels: entering an instance swaps the ray for its object-space one and
// keeps the TLAS's pending node group and leaf objects aside; the BLAS's own entries go on the
// same stack above `blas_sp`, and when they are used up the TLAS resumes. A step tests the
// pending leaf primitives (triangles, or objects until one is an instance), then visits one
// node. Lavapipe runs a divergent branch for every lane and a loop until its slowest lane
// ends, so the former nested loops (a BLAS loop inside the TLAS loop's leaf loop) kept 40% of
// the lanes busy in the BLAS loop on cornell (tools/profile-trace.sh): this is that argument,
// and Aila and Laine's (2009) for a GPU warp. Measured on lavapipe (256x256, 16 spp, same
// binary, interleaved runs): against the nested loops about 20% faster on bunny-low and
// within the noise (+-10%) on cornell, mirror-room and cubes-441; a variant whose step is one
// primitive *or* one node ("if-if") was 1.2-1.6x slower, since each of its steps pays for a
// triangle, an object and a node test. The order of the tests, and so the hit, is the nested
// loops': images are bit for bit the same.
Hit trace_scene(vec3 o, vec3 d, float t_min, float t_max, bool any_hit) {
    Hit hit;
    hit.t = INF;
    hit.object = NO_OBJECT;
    hit.primitive = NO_PRIMITIVE;
    hit.overflow = false;
    if (!(HAS_TRIANGLES || HAS_BOXES || HAS_SPHERES) || scene_info.tlas_node_count == 0u) return hit;
    LevelRay world = level_ray(o, d);
    LevelRay ray = world;
    WatertightRay w; // the object-space ray's, set on entering a BLAS
    uvec2 stack[TRAVERSAL_STACK_SIZE];
    uint sp = 0u;
    // A node group: (child base, hit mask << 24 | leaf bits); a leaf group: (first, hit bits).
    uvec2 cur = uvec2(0u, 0x80000000u);
    uvec2 prim = uvec2(0u);
    uint root = scene_info.tlas_root; // node index of the current level's root
    bool in_blas = false;
    uint blas_sp = 0u;              // the stack's entries from here up are the BLAS's
    uvec2 tlas_cur = uvec2(0u);     // the TLAS's pending node group and leaves, while in a BLAS
    uvec2 tlas_prim = uvec2(0u);
    uint object = 0u;               // the instance whose BLAS is being walked
    uint tri_base = 0u;
    // The instance's coverage (coverage.glsl), in scenes with single-sided or alpha-cut ones.
    bool covers_all = true;
    uvec2 surface = uvec2(0u);
    uint material = 0u;
    uint key = HAS_CUTOUTS ? coverage_key(o, d) : 0u;
    for (;;) {
        while (prim.y != 0u) {
            uint local = uint(findMSB(prim.y));
            prim.y &= ~(1u << local);
            uint index = prim.x + local;
            if (in_blas) {
                profile_count(PROFILE_TRIANGLES, 1u);
                uint tri = tri_base + index;
                GpuTriangle T = load_triangle(tri);
                float t = intersect_triangle(ray.o, w, T.v0.xyz, T.v1.xyz, T.v2.xyz, t_min, t_max);
                if ((HAS_CUTOUTS || HAS_SINGLE_SIDED) && t < t_max && !covers_all &&
                    !meets(surface, material, tri, T, ray.o, ray.d, t, key)) {
                    t = INF;
                }
                if (t < t_max) {
                    t_max = t;
                    hit.t = t;
                    hit.object = object;
                    hit.primitive = tri;
                    if (any_hit) return hit;
                }
            } else {
                uvec4 ids = load_object_ids(index);
                uint kind = ids.x;
                if (HAS_TRIANGLES && kind == KIND_INSTANCE) {
                    GpuObject ob = load_object(index); // only its world_to_object rows
                    tlas_cur = cur;
                    tlas_prim = prim;
                    blas_sp = sp;
                    in_blas = true;
                    object = index;
                    root = ids.z;     // blas_root
                    tri_base = ids.w; // triangle_base
                    if (HAS_CUTOUTS || HAS_SINGLE_SIDED) {
                        surface = load_object_surface(index);
                        material = ids.y;
                        covers_all = surface.x == 0u;
                    }
                    ray = level_ray(affine(ob.world_to_object0, ob.world_to_object1, ob.world_to_object2, world.o),
                                    linear(ob.world_to_object0, ob.world_to_object1, ob.world_to_object2, world.d));
                    w = watertight_setup(ray.d);
                    cur = uvec2(0u, 0x80000000u);
                    prim = uvec2(0u); // ends this loop; the BLAS's root is the next node
                    break;
                }
                float t = INF;
                if (HAS_BOXES && kind == KIND_BOX) {
                    profile_count(PROFILE_PRIMITIVES, 1u);
                    GpuObject ob = load_object(index);
                    t = intersect_box(world.o, world.inv_d, ob.a.xyz, ob.b.xyz, t_min, t_max);
                } else if (HAS_SPHERES && kind == KIND_SPHERE) {
                    profile_count(PROFILE_PRIMITIVES, 1u);
                    GpuObject ob = load_object(index);
                    t = intersect_sphere(world.o, world.d, ob.a.xyz, ob.a.w, t_min, t_max);
                }
                if (t < t_max) {
                    t_max = t;
                    hit.t = t;
                    hit.object = index;
                    hit.primitive = NO_PRIMITIVE; // not a triangle (one hit before may have been)
                    if (any_hit) return hit;
                }
            }
        }
        // A step counts at the level of the node it may visit, so that each level's steps are
        // at least its node visits.
        if (in_blas) {
            profile_step(PROFILE_BLAS_LANE_STEPS, PROFILE_BLAS_GROUP_STEPS);
        } else {
            profile_step(PROFILE_TLAS_LANE_STEPS, PROFILE_TLAS_GROUP_STEPS);
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
            uint slot = (child_offset - 24u) ^ (ray.oct & 0xffu);
            uint rel = uint(bitCount(hits_imask & ~(0xffffffffu << slot)));
            int at = int((root + cur.x + rel) * TEXELS_PER_NODE);
            profile_count(in_blas ? PROFILE_BLAS_NODES : PROFILE_TLAS_NODES, 1u);
            uvec4 n0 = texelFetch(bvh_nodes, at);
            uvec4 n1 = texelFetch(bvh_nodes, at + 1);
            uint hm = intersect_node(n0, n1, texelFetch(bvh_nodes, at + 2), texelFetch(bvh_nodes, at + 3),
                                     texelFetch(bvh_nodes, at + 4), ray.o, ray.inv_d, ray.oct, t_min, t_max);
            cur = uvec2(n1.x, (hm & 0xff000000u) | (n0.w >> 24));
            prim = uvec2(n1.y, hm & 0x00ffffffu);
        } else {
            cur = uvec2(0u);
        }
        if (prim.y == 0u && (cur.y & 0xff000000u) == 0u) {
            if (sp > blas_sp) {
                cur = stack[--sp];
            } else if (in_blas) {
                // The BLAS is done: back to the TLAS's pending work, with the world ray.
                in_blas = false;
                ray = world;
                root = scene_info.tlas_root;
                cur = tlas_cur;
                prim = tlas_prim;
                blas_sp = 0u;
            } else {
                break;
            }
        }
    }
    return hit;
}
#endif

// True when nothing blocks the segment o + t*d, t in (0, t_max) - for shadow rays.
bool unoccluded(vec3 o, vec3 d, float t_max, inout bool overflow) {
    Hit h = trace_scene(o, d, 0.0, t_max, true);
    overflow = overflow || h.overflow;
    return h.t == INF;
}

// World-space geometric normal at a hit (not yet faced toward the ray).
vec3 hit_normal(Hit h, vec3 p) {
    GpuObject ob = load_object(h.object);
    if (HAS_TRIANGLES && ob.kind == KIND_INSTANCE) {
        GpuTriangle T = load_triangle(h.primitive);
        vec3 n = cross(T.v1.xyz - T.v0.xyz, T.v2.xyz - T.v0.xyz);
        // Normals transform by the inverse transpose: the columns of world->object.
        vec3 nw = ob.world_to_object0.xyz * n.x + ob.world_to_object1.xyz * n.y + ob.world_to_object2.xyz * n.z;
        return normalize(nw);
    }
    if (HAS_BOXES && ob.kind == KIND_BOX) return box_normal(p, ob.a.xyz, ob.b.xyz);
    return normalize(p - ob.a.xyz);
}

#endif
