#version 460
// The trace pass (thesis 3.2.1-3.2.2): one thread per traced lattice point of one eye, read
// from the work list the plan pass wrote (an indirect dispatch sized by the GPU). The thread
// traces the layer's spp samples at the point's pixel and writes their mean into LATTICE. A
// sample's jitter and random numbers depend only on (lattice point, spacing, spp, sample, seed,
// eye) - with the independent sampler on (pixel, sample, seed, eye) - so the same pixel traced
// by any layer config of its spacing and spp gives bit-identical values (sampler.glsl).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#define WRITES_LATTICE
#define PASS_PUSH EyePush
#ifdef KEEPS_SURFACES
#define CAMERA_VERTEX_HOOK
#endif
#include "integrators.glsl"
#include "plan.glsl"
#include "view.glsl"
#include "surface.glsl"
#include "albedo.glsl"

layout(local_size_x = TRACE_WORKGROUP_SIZE) in;

// Adds n to a 64-bit counter kept as two words (low, high) of STATS: a carry out of the low
// word's atomic add (the value it returns plus n wraps) goes to the high word.
void add_64(uint word, uint n) {
    if (n == 0u) return;
    uint before = atomicAdd(stats[word], n);
    if (before + n < before) atomicAdd(stats[word + 1u], 1u);
}

vec3 camera_ray(vec2 pixel, vec2 jitter) {
    vec2 t = pixel_tan(pixel + jitter);
    return normalize(pc.cam.forward.xyz + t.x * pc.cam.right.xyz + t.y * pc.cam.up.xyz);
}

// A camera path through `pixel` + `jitter`, its ray cone as wide as the pixel's angle times
// `spacing`: a layer that traces every d-th pixel sees textures at d times the footprint.
Path camera_path(vec2 pixel, vec2 jitter, float pixel_angle) {
    Path p = path_start(pc.cam.position.xyz, camera_ray(pixel, jitter));
    p.cone_spread = pixel_angle;
    return p;
}

// What a material reflects at most, which the denoiser filters without (albedo.glsl): the
// thesis model's k_d + k_s; glTF's diffuse part (the textured base colour of what is not
// metal) plus its specular one at normal incidence (gltf_f0: 0.04 for a dielectric, so a
// black plastic's reflection is not divided by the albedo floor); 1 for an emitter, whose
// radiance is not reflected light.
vec3 material_albedo(GpuMaterial m) {
    if (any(greaterThan(m.emission.xyz, vec3(0.0)))) return vec3(1.0);
    if (is_metallic_roughness(m)) return min(m.base_color.rgb * (1.0 - m.metallic) + gltf_f0(m), vec3(1.0));
    return min(m.kd.xyz + m.ks.xyz, vec3(1.0));
}

#ifdef KEEPS_SURFACES
// History on: the point's surface, which temporal.comp reprojects and tests history against
// (shared.h's SURFACE_* encoding). It is the camera ray's hit of the point's first sample,
// which the point's first lane traces first: next_vertex hands it over (camera_vertex) while
// `keeps_surface` holds. A ray of its own through the pixel's centre, as before, cost the
// H200 23% of the textured room's 1-spp trace and 41% of cornell's (history on against off,
// reports/gpu-h200-panels/history-cost/). The hit lies within the pixel's jitter of the
// centre, which temporal.comp's surface tests allow for.
bool keeps_surface = false;
uvec4 point_surface = uvec4(SURFACE_NONE, 0u, NO_OBJECT, NO_MATERIAL);
// The albedo (pc.albedo) that temporal.comp's clamp bounds and a denoising layer divides out
// and multiplies back (albedo.glsl) is the mean over the point's samples of what their camera
// rays hit (textures seen at the ray's cone; 1 where it hits nothing): the same samples as
// the point's radiance, so that at a texel edge inside the pixel the two mix the same two
// texels. temporal.comp keeps its mean over the frames as it keeps the radiance's, so that
// the clamp's and the denoiser's guide holds still. This lane's sum:
vec3 lane_albedo = vec3(0.0);

void camera_vertex(Hit h, SurfaceHit s) {
    if (pc.albedo != 0u) lane_albedo += material_albedo(s.m);
    if (!keeps_surface) return;
    keeps_surface = false;
    // surface() faces ng toward the camera, as temporal.comp compares normals.
    point_surface = uvec4(floatBitsToUint(h.t), packSnorm2x16(to_octahedral(s.ng)), h.object,
                          load_object_ids(h.object).y);
}

void camera_missed() {
    if (pc.albedo != 0u) lane_albedo += vec3(1.0);
    keeps_surface = false;
}
#endif

// Each lane's share of its point: the samples it traced summed in order, and its counts.
struct LaneSum {
    vec3 sum;
    uint rays;
    uint nonfinite;
    uint overflows;
};

// The lane's samples of layer k's point at `pixel`: s = part, part + lanes, ... < spp.
// One path at a time per invocation, the next sample's started as soon as one ends (see
// Path): sample s's random numbers and camera ray are the same as in a loop over samples,
// and the samples are summed in the same order, so the image is too.
LaneSum trace_samples(uint k, ivec2 pixel, uint spp, uint part, uint lanes, float pixel_angle) {
    LaneSum r = LaneSum(vec3(0.0), 0u, 0u, 0u);
    uint pixel_index = uint(pixel.y) * pc.eye.width + uint(pixel.x);
    uint seed = pc.eye.seed + pc.eye.index * 0x9E3779B9u; // eye 0 keeps the user's seed
    // The sampler's point: the pixel in units of the spacing (floored; the offset keeps the
    // margin's negative pixels apart), so a spacing-1 layer numbers pixels as a regular frame.
    uint spacing = uint(layers[k].spacing);
    ivec2 point = ivec2(uvec2(pixel + 4096 * layers[k].spacing) / spacing);
    SamplerPoint sampled = sampler_point(point, spacing, pixel_index, spp, seed);
    // `s < spp` also ends at once a layer whose spp reads 0 (a corrupt layer buffer), and a
    // lane with no sample of its point's: the loop must not depend on a path ending to end.
    uint s = part;
    if (s >= spp) return r;
    Sampler smp = sampler_start(sampled, s);
    Path path = camera_path(vec2(pixel), sample_2d(smp), pixel_angle);
    bool overflow = false;
    while (s < spp) {
        if (INTEGRATOR == INTEGRATOR_SEED) {
            seed_step(path, smp, r.rays, overflow);
        } else {
            pt_step(path, smp, r.rays, overflow);
        }
        if (!path.done) continue;
        if (overflow) r.overflows++;
        // A non-finite sample is dropped (counted as black) and reported, never written.
        if (any(isnan(path.L)) || any(isinf(path.L))) {
            r.nonfinite++;
        } else {
            r.sum += path.L;
        }
        s += lanes;
        if (s >= spp) break;
        smp = sampler_start(sampled, s);
        path = camera_path(vec2(pixel), sample_2d(smp), pixel_angle);
        overflow = false;
    }
    return r;
}

// While some layer has several lanes per point, each lane's sum, which the point's first
// lane adds up in lane order (and, while a layer denoises, each lane's sum of albedos).
shared vec3 lane_sums[TRACE_WORKGROUP_SIZE];
#ifdef KEEPS_SURFACES
shared vec3 lane_albedos[TRACE_WORKGROUP_SIZE];
#endif

void main() {
    uint thread = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * TRACE_WORKGROUP_SIZE)
                + gl_GlobalInvocationID.x;
    uint block = pc.eye.index * STAT_COUNT; // each eye counts in its own block
    // One slot of the work list per thread: GpuLayer.lanes consecutive slots per point,
    // aligned, so that a point with few threads left to fill a GPU spreads its samples over
    // several (renderer.rs, trace_lanes); WORK_EMPTY slots pad.
    bool listed = thread < stats[STAT_DISPATCH + pc.eye.index * 4u + STAT_WORK_COUNT];
    uint item = listed ? work[pc.eye.index * pc.eye.work_stride + thread] : WORK_EMPTY;
    listed = item != WORK_EMPTY;
    // With one lane per point in every layer (a CPU driver's choice) no lane waits at the
    // barrier below, so the unlisted ones may leave now; else every lane must reach it. A
    // specialization constant, so that without lanes the barrier and its shared memory are
    // compiled away (on an H100 they cost mirror-room's 1-spp frame about 9% when they were
    // only skipped at run time).
    bool shares = TRACE_SHARES;
    if (!shares && !listed) return;
    if (PROFILE) {
        for (uint c = 0u; c < PROFILE_COUNTERS; ++c) profile_counts[c] = 0u;
    }
    uint k = 0u;
    uint entry = 0u; // the point's LATTICE index
    uint part = 0u;
    uint lanes = 1u;
    ivec2 pixel = ivec2(0);
    uint spp = 0u;
    float pixel_angle = 0.0;
    LaneSum r = LaneSum(vec3(0.0), 0u, 0u, 0u);
    if (listed) {
        work_item(item, k, entry);
        lanes = layers[k].lanes;
        part = thread & (lanes - 1u);
        pixel = lattice_pixel(k, lattice_point(k, entry));
        spp = layers[k].spp;
        // The pixel's angular height at the image centre, times the layer's lattice spacing.
        pixel_angle = abs(layers[k].pixel_tan.w) * float(layers[k].spacing);
#ifdef KEEPS_SURFACES
        keeps_surface = part == 0u;
#endif
        r = trace_samples(k, pixel, spp, part, lanes, pixel_angle);
    }
    vec3 sum = r.sum;
    bool first_lane = listed && part == 0u;
    if (shares) {
        uint lane = gl_LocalInvocationID.x;
        lane_sums[lane] = r.sum;
#ifdef KEEPS_SURFACES
        lane_albedos[lane] = lane_albedo;
#endif
        barrier();
        // The point's first lane, in lane order, from zero: with spp <= lanes the same
        // additions as one lane's loop (sample s is lane s's), so the same bits. Only it
        // reads: its lanes end within the workgroup, a later lane's would not.
        if (first_lane) {
            sum = vec3(0.0);
            for (uint p = 0u; p < lanes; ++p) sum += lane_sums[lane + p];
#ifdef KEEPS_SURFACES
            lane_albedo = vec3(0.0);
            for (uint p = 0u; p < lanes; ++p) lane_albedo += lane_albedos[lane + p];
#endif
        }
    }
    if (first_lane) {
        lattice[entry] = vec4(sum / float(spp), 1.0);
#ifdef KEEPS_SURFACES
        lattice_surface[entry] = point_surface;
        if (pc.albedo != 0u) lattice_albedo[entry] = pack_albedo(lane_albedo / float(spp));
#endif
        atomicAdd(stats[block + STAT_PATHS], spp);
    }
    if (r.nonfinite > 0u) atomicAdd(stats[block + STAT_NONFINITE], r.nonfinite);
    if (r.overflows > 0u) atomicAdd(stats[block + STAT_STACK_OVERFLOW], r.overflows);
    if (r.rays > 0u) atomicAdd(stats[block + STAT_RAYS], r.rays);
    if (PROFILE && listed) {
        for (uint c = 0u; c < PROFILE_COUNTERS; ++c) {
            add_64(STAT_PROFILE + (pc.eye.index * PROFILE_COUNTERS + c) * 2u, profile_counts[c]);
        }
    }
}
