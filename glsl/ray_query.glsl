// trace_scene through VK_KHR_ray_query: the driver's (or the GPU's ray-tracing hardware's)
// traversal of the acceleration structures src/gpu/accel.rs builds from the same scene
// arrays. Included by bvh.glsl when compiled with RAY_QUERY (build.rs's *_rq shaders), in
// place of the software traversal; everything else in the shaders is the same.
//
// Hits name the same object as the software traversal's:
// - a mesh instance is a TLAS instance whose custom index is its index in OBJECTS, of its
//   mesh's BLAS (triangles in TRIANGLES' leaf order): TRIANGLES index = triangle_base +
//   primitive index;
// - the boxes and spheres are one instance (identity transform) of one BLAS of an AABB per
//   object (a point for a mesh instance): the primitive index is the object's index. Its
//   candidates are tested here with the software traversal's intersect_box/_sphere.
#ifndef FOVEA_RAY_QUERY_GLSL
#define FOVEA_RAY_QUERY_GLSL
#extension GL_EXT_ray_query : require

layout(set = 0, binding = BINDING_TLAS) uniform accelerationStructureEXT tlas;

// The largest finite float: a ray query's t_max must be a number (INF is how the integrators
// say "no limit").
const float RAY_QUERY_T_LIMIT = 3.4028235e38;

Hit trace_scene(vec3 o, vec3 d, float t_min, float t_max, bool any_hit) {
    Hit hit;
    hit.t = INF;
    hit.object = NO_OBJECT;
    hit.primitive = NO_PRIMITIVE;
    hit.overflow = false; // the driver's traversal has no stack of ours to overflow
    if (!(HAS_TRIANGLES || HAS_BOXES || HAS_SPHERES) || scene_info.object_count == 0u) return hit;
    vec3 sd = safe_direction(d);
    vec3 inv_d = 1.0 / sd;
    // Opaque triangles are committed by the driver itself; box and sphere candidates, and
    // alpha-cut instances' triangles (src/gpu/accel/inputs.rs makes those non-opaque), come
    // back to the loop below. Single-sided instances' back faces are culled by the driver
    // (the others' instances disable culling). A shadow ray stops at its first hit.
    uint flags = (HAS_CUTOUTS ? 0u : gl_RayFlagsOpaqueEXT) |
                 (HAS_SINGLE_SIDED ? gl_RayFlagsCullBackFacingTrianglesEXT : 0u) |
                 (any_hit ? gl_RayFlagsTerminateOnFirstHitEXT : 0u);
    uint key = HAS_CUTOUTS ? coverage_key(o, d) : 0u;
    rayQueryEXT q;
    rayQueryInitializeEXT(q, tlas, flags, 0xffu, o, t_min, d, min(t_max, RAY_QUERY_T_LIMIT));
    while (rayQueryProceedEXT(q)) {
        uint type = rayQueryGetIntersectionTypeEXT(q, false);
        if (HAS_CUTOUTS && type == gl_RayQueryCandidateIntersectionTriangleEXT) {
            uint object = rayQueryGetIntersectionInstanceCustomIndexEXT(q, false);
            uvec4 ids = load_object_ids(object);
            uint tri = ids.w + rayQueryGetIntersectionPrimitiveIndexEXT(q, false);
            vec2 b = rayQueryGetIntersectionBarycentricsEXT(q, false);
            if (alpha_covers(load_object_surface(object), ids.y, tri, b, key)) {
                rayQueryConfirmIntersectionEXT(q);
                if (any_hit) {
                    rayQueryTerminateEXT(q);
                    break;
                }
            }
            continue;
        }
        if (type != gl_RayQueryCandidateIntersectionAABBEXT) continue;
        uint index = rayQueryGetIntersectionPrimitiveIndexEXT(q, false);
        // The closest hit so far bounds the candidate, as t_max does in the software loop.
        float bound = rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionNoneEXT
                          ? t_max : rayQueryGetIntersectionTEXT(q, true);
        GpuObject ob = load_object(index);
        float t = INF;
        if (HAS_BOXES && ob.kind == KIND_BOX) {
            t = intersect_box(o, inv_d, ob.a.xyz, ob.b.xyz, t_min, bound);
        } else if (HAS_SPHERES && ob.kind == KIND_SPHERE) {
            t = intersect_sphere(o, sd, ob.a.xyz, ob.a.w, t_min, bound);
        }
        if (t < bound) {
            rayQueryGenerateIntersectionEXT(q, t);
            if (any_hit) {
                rayQueryTerminateEXT(q);
                break;
            }
        }
    }
    uint committed = rayQueryGetIntersectionTypeEXT(q, true);
    if (committed == gl_RayQueryCommittedIntersectionNoneEXT) return hit;
    hit.t = rayQueryGetIntersectionTEXT(q, true);
    if (committed == gl_RayQueryCommittedIntersectionTriangleEXT) {
        hit.object = rayQueryGetIntersectionInstanceCustomIndexEXT(q, true);
        hit.primitive = load_object_ids(hit.object).w + rayQueryGetIntersectionPrimitiveIndexEXT(q, true);
    } else {
        hit.object = rayQueryGetIntersectionPrimitiveIndexEXT(q, true); // a box or sphere
    }
    return hit;
}

#endif
