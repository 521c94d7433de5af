// The two estimators of L along a camera ray. Both count bounces the same way: the camera
// ray's hit is vertex 0, and emission is gathered at vertices 0..MAX_BOUNCES.
#ifndef FOVEA_INTEGRATORS_GLSL
#define FOVEA_INTEGRATORS_GLSL
#include "brdf.glsl"
#include "environment.glsl"
#include "gltf_brdf.glsl"
#include "lights.glsl"
#include "sampler.glsl"
#include "shading.glsl"
#include "textures.glsl"

// The power heuristic (beta 2) of MIS: the weight of a sample of density a against b.
float power_heuristic(float a, float b) {
    float a2 = a * a;
    return a2 / (a2 + b * b);
}

// The gradient sky of a scene without an HDR environment: ground below the horizon,
// horizon -> zenith above it.
vec3 gradient_sky(vec3 d) {
    float y = d.y / max(length(d), 1e-30);
    if (y >= 0.0) return mix(scene_info.sky_horizon.xyz, scene_info.sky_zenith.xyz, y);
    return mix(scene_info.sky_horizon.xyz, scene_info.sky_ground.xyz, min(1.0, -8.0 * y));
}

struct SurfaceHit {
    vec3 p;
    vec3 ng;     // geometric normal, faced toward the incoming ray
    vec3 ns;     // shading normal (valid_shading_normal), on ng's side; ng without attributes
    vec4 uv;     // TEXCOORD_0 (xy) and TEXCOORD_1 (zw) at the hit; 0 without attributes
    vec2 uv_per_area; // per TEXCOORD set, the triangle's uv area over its world area (textures)
    vec3 n_smooth; // the interpolated normal facing the viewer (ng without normals), unbent
    vec4 tangent;  // world-space tangent, w the bitangent's sign; 0 without tangents
    bool front;  // the ray arrived on the side the geometric normal points to
    GpuMaterial m;
    uint emitter; // this point's emitter index, or NO_EMITTER
};

// The hit's vertex attributes, where its mesh has them: texture coordinates, and the
// shading normal (faced like ng, then made valid for the view direction -d).
void interpolate_attributes(inout SurfaceHit s, Hit h, GpuObject ob, vec3 d) {
    GpuTriangle T = load_triangle(h.primitive);
    vec3 p = affine(ob.world_to_object0, ob.world_to_object1, ob.world_to_object2, s.p);
    vec2 b = triangle_barycentrics(T, p);
    GpuTriangleShading S = load_triangle_shading(h.primitive);
    s.uv = interpolated_uv(S, b);
    if (HAS_TEXTURES) {
        s.uv_per_area = uv_per_world_area(T, S, ob);
        s.tangent = world_tangent(S, b, ob);
    }
    vec3 n = interpolated_normal(S, b);
    if (n == vec3(0.0)) return;
    // Normals transform by the inverse transpose: the columns of world->object.
    vec3 nw = ob.world_to_object0.xyz * n.x + ob.world_to_object1.xyz * n.y + ob.world_to_object2.xyz * n.z;
    float len = length(nw);
    if (!(len > 0.0)) return;
    nw /= len;
    s.n_smooth = s.front ? nw : -nw;
    s.ns = valid_shading_normal(s.n_smooth, s.ng, -d);
}

// The surface a ray (o, d) hits; `cone_width` is its ray cone's width there (textures' level
// of detail).
SurfaceHit surface(Hit h, vec3 o, vec3 d, float cone_width) {
    SurfaceHit s;
    s.p = o + h.t * d;
    vec3 n = hit_normal(h, s.p);
    s.front = dot(n, d) < 0.0;
    s.ng = s.front ? n : -n;
    s.ns = s.ng;
    s.uv = vec4(0.0);
    s.uv_per_area = vec2(0.0);
    s.n_smooth = s.ng;
    s.tangent = vec4(0.0);
    GpuObject ob = load_object(h.object);
    if (HAS_SHADING && ob.kind == KIND_INSTANCE) interpolate_attributes(s, h, ob, d);
    s.m = load_material(ob.material);
    if (HAS_TEXTURES && is_metallic_roughness(s.m)) {
        Footprint f;
        f.uv_per_area = s.uv_per_area;
        f.width = cone_width / max(abs(dot(s.ng, d)), 1e-3);
        s.m = textured(s.m, s.uv, f);
        // A normal map bends the interpolated normal in its tangent frame; the result is made
        // valid for the view like any shading normal (valid_shading_normal).
        if (s.m.normal_texture.texture != NO_TEXTURE && s.tangent.w != 0.0) {
            vec3 mapped = mapped_normal(s.m, s.uv, f, s.n_smooth, s.tangent);
            s.ns = valid_shading_normal(mapped, s.ng, -d);
        }
    }
    s.emitter = NO_EMITTER;
    if (ob.emitter != NO_EMITTER) {
        s.emitter = ob.kind == KIND_INSTANCE ? ob.emitter + (h.primitive - ob.triangle_base) : ob.emitter;
    }
    return s;
}

// Emission leaving the surface toward the ray: one-sided (front) on triangles, two-sided on
// analytic shapes.
vec3 emitted(SurfaceHit s, Hit h) {
    if (!HAS_EMITTERS) return vec3(0.0);
    bool triangle = load_object_kind(h.object) == KIND_INSTANCE;
    return (s.front || !triangle) ? s.m.emission.xyz : vec3(0.0);
}

// One camera path, advanced one bounce per *_step call. trace.comp keeps one per invocation
// and starts the next sample as soon as a path ends, so the SIMD lanes of lavapipe (and the
// threads of a GPU's warp) stay busy until all of an invocation's samples are done instead of
// waiting, sample after sample, for the longest path among their neighbours.
struct Path {
    vec3 o;
    vec3 d;
    vec3 L;
    vec3 throughput; // the seed estimator's "energy"
    vec3 prev_p;     // pt: the previous vertex, for MIS weights of hits on emitters
    float prev_pdf;  // pt: solid-angle density of the last brdf sample
    bool prev_delta; // pt: camera rays and mirror bounces cannot be found by NEE
    uint bounce;     // the vertex this step's ray finds: 0 for the camera ray's hit
    bool done;
    // The ray cone (textures' level of detail): its width at o and its spread angle, which
    // the camera sets from the pixel's (and a layer's lattice spacing) and each bounce widens.
    float cone_width;
    float cone_spread;
};

Path path_start(vec3 o, vec3 d) {
    Path p;
    p.o = o;
    p.d = d;
    p.L = vec3(0.0);
    p.throughput = vec3(1.0);
    p.prev_p = o;
    p.prev_pdf = 0.0;
    p.prev_delta = true;
    p.bounce = 0u;
    p.done = false;
    p.cone_width = 0.0;
    p.cone_spread = 0.0;
    return p;
}

// A bounce off a glTF material widens the cone by its lobe: 2 alpha, a lobe's angular width
// (Akenine-Moller et al. 2021 widen by surface curvature; a rough lobe spreads the reflected
// rays far more than curvature does).
void widen_cone(inout Path p, GpuMaterial m) {
    if (HAS_TEXTURES && is_metallic_roughness(m)) p.cone_spread += 2.0 * ggx_alpha(m);
}

#ifdef CAMERA_VERTEX_HOOK
// The includer's hooks on every camera ray's outcome (bounce 0): its hit and surface, or a
// miss. trace.comp keeps a point's first sample's as the surface the temporal history needs,
// instead of tracing one more ray for it (except while a layer denoises: see trace.comp).
void camera_vertex(Hit h, SurfaceHit s);
void camera_missed();
#endif

// Traces the path's next ray: on a miss adds the sky and ends the path (false), on a hit
// gives the hit and its surface (true). Both integrators start a bounce with it.
bool next_vertex(inout Path p, out Hit h, out SurfaceHit s, inout uint rays, inout bool overflow) {
    h = trace_scene(p.o, p.d, 0.0, INF, false);
    rays++;
    overflow = overflow || h.overflow;
    if (h.t == INF) {
#ifdef CAMERA_VERTEX_HOOK
        if (p.bounce == 0u) camera_missed();
#endif
        // An environment map is also a light for next-event estimation (pt): a BRDF sample
        // that finds it takes its MIS weight. Camera rays and mirror bounces (prev_delta,
        // and every seed path) take it whole.
        vec3 sky;
        if (HAS_ENV_MAP) {
            vec2 ut = env_uv(p.d);
            sky = env_radiance(ut);
            if (!p.prev_delta) sky *= power_heuristic(p.prev_pdf, scene_info.env_pmf * env_pdf(ut));
        } else {
            sky = gradient_sky(p.d);
        }
        p.L += p.throughput * sky;
        p.done = true;
        return false;
    }
    if (HAS_TEXTURES) p.cone_width += p.cone_spread * h.t;
    s = surface(h, p.o, p.d, p.cone_width);
#ifdef CAMERA_VERTEX_HOOK
    if (p.bounce == 0u) camera_vertex(h, s);
#endif
    return true;
}

// ---- seed: the thesis' estimator (eqs. 3.4-3.16) -------------------------------------------
// Uniform hemisphere sampling (p = 1/2pi, eq. 3.5); the BRDF picked by comparing R with p_S
// (eq. 3.11); the weight 2*k_d*cos (Lambert) or k_s(alpha+2)cos^alpha theta_r*cos (Phong) of eq. 3.13, divided
// by the probability of the pick (the p^-1 of eq. 3.15); 8 bounces or until the energy is zero.
// One call is one bounce of the path (see Path).
// eq. 3.15's clamp f_c(n*w_i)^((alpha+2)/(alpha+1)) belongs to lobe-sampled directions; with the uniform
// directions eq. 3.5 states it would bias the image, so the eq. 3.13 weight is used instead.
void seed_step(inout Path p, inout Sampler smp, inout uint rays, inout bool overflow) {
    Hit h;
    SurfaceHit s;
    if (!next_vertex(p, h, s, rays, overflow)) return;
    p.L += p.throughput * emitted(s, h);
    if (p.bounce == MAX_BOUNCES) {
        p.done = true;
        return;
    }
    float p_s = HAS_SPECULAR ? s.m.ks.w : 0.0;
    vec3 wo = -p.d;
    vec3 d;
    if (is_metallic_roughness(s.m)) {
        // glTF's BRDF, estimated the seed way: a uniform hemisphere direction, f cos / (1/2pi).
        d = sample_power_cosine(sample_2d(smp), s.ns, 0.0);
        p.throughput *= gltf_eval(s.m, wo, d, s.ns) * dot(s.ns, d) * (2.0 * PI);
        widen_cone(p, s.m);
    } else if (sample_1d(smp) < p_s) {
        if (is_mirror(s.m)) {
            d = reflect(p.d, s.ns);
            p.throughput *= s.m.ks.xyz / p_s;
        } else {
            d = sample_power_cosine(sample_2d(smp), s.ns, 0.0);
            vec3 r = reflect(-wo, s.ns);
            float alpha = s.m.kd.w;
            p.throughput *= s.m.ks.xyz * (alpha + 2.0) * phong_lobe(d, r, alpha) * dot(s.ns, d) / p_s;
        }
    } else {
        d = sample_power_cosine(sample_2d(smp), s.ns, 0.0);
        p.throughput *= 2.0 * s.m.kd.xyz * dot(s.ns, d) / (1.0 - p_s);
    }
    p.d = d;
    p.done = all(equal(p.throughput, vec3(0.0)));
    // A direction around the shading normal may point into the geometry: absorbed there,
    // never taken through it.
    if (HAS_SHADING && dot(d, s.ng) <= 0.0) p.done = true;
    p.o = offset_ray_origin(s.p, s.ng, p.o);
    p.bounce++;
}

// ---- pt: importance sampling, next-event estimation with MIS, Russian roulette ---------------

// Density of brdf sampling for the non-delta lobes (diffuse chosen with 1 - p_S).
float brdf_pdf(GpuMaterial m, vec3 wo, vec3 wi, vec3 n) {
    float cos_i = dot(wi, n);
    if (cos_i <= 0.0) return 0.0;
    float p_s = HAS_SPECULAR ? m.ks.w : 0.0;
    float pdf = (1.0 - p_s) * cos_i / PI;
    if (HAS_SPECULAR && !is_mirror(m) && p_s > 0.0) {
        float alpha = m.kd.w;
        pdf += p_s * (alpha + 1.0) / (2.0 * PI) * phong_lobe(wi, reflect(-wo, n), alpha);
    }
    return pdf;
}

// f and the sampling density of either material model (delta lobes excluded).
vec3 material_eval(GpuMaterial m, vec3 wo, vec3 wi, vec3 n) {
    return is_metallic_roughness(m) ? gltf_eval(m, wo, wi, n) : brdf_eval(m, wo, wi, n);
}

float material_pdf(GpuMaterial m, vec3 wo, vec3 wi, vec3 n) {
    return is_metallic_roughness(m) ? gltf_pdf(m, wo, wi, n) : brdf_pdf(m, wo, wi, n);
}

// The light x = s.p receives toward wo by one next-event sample (before the path's
// throughput): an emitter chosen by power, then a point on it (MIS-weighted against BRDF
// sampling) or a punctual light's direction (a delta: weight 1). `origin` is x lifted off the
// surface for the shadow ray.
vec3 next_event(SurfaceHit s, vec3 wo, vec3 origin, inout Sampler smp, inout uint rays, inout bool overflow) {
    vec3 n = s.ns;
    vec2 u_pick = sample_2d(smp); // the alias table's bucket, and whether to keep it
    float u_bucket = u_pick.x;
    float u_keep = u_pick.y;
    GpuEmitter e = load_emitter(choose_emitter(u_bucket, u_keep));
    // The point on the light or the environment's direction (xy: one stratified pair), and a
    // box's face (z).
    vec3 u = vec3(sample_2d(smp), sample_1d(smp));
    vec3 wi;
    vec3 arriving; // irradiance (punctual) or MIS-weighted radiance over the solid-angle pdf
    vec3 shadow_seg;
    if (HAS_ENV_MAP && e.kind == KIND_ENVIRONMENT) {
        float env_density;
        vec2 ut;
        wi = env_sample(u.xy, ut, env_density);
        float light_pdf = e.pmf * env_density;
        if (!(light_pdf > 0.0)) return vec3(0.0);
        float bpdf = material_pdf(s.m, wo, wi, n);
        arriving = env_radiance(ut) * (power_heuristic(light_pdf, bpdf) / light_pdf);
    } else if (is_punctual(e.kind)) {
        PunctualArrival a = punctual_arrival(e, s.p);
        wi = a.wi;
        arriving = a.irradiance / e.pmf;
        shadow_seg = e.p0.xyz - origin;
    } else {
        LightSample ls = sample_emitter(e, u);
        vec3 to_light = ls.p - s.p;
        float dist2 = dot(to_light, to_light);
        wi = to_light * inversesqrt(max(dist2, 1e-30));
        float cos_l = e.kind == KIND_TRIANGLE ? -dot(ls.n, wi) : abs(dot(ls.n, wi));
        if (!(cos_l > 0.0 && dist2 > 0.0)) return vec3(0.0);
        float light_pdf = ls.area_pdf * dist2 / cos_l;
        float bpdf = material_pdf(s.m, wo, wi, n);
        arriving = e.emission.xyz * (power_heuristic(light_pdf, bpdf) / light_pdf);
        // The shadow ray stops just short of the light's surface.
        shadow_seg = offset_ray_origin(ls.p, -wi * sign(cos_l), ls.p) - origin;
    }
    float cos_x = dot(wi, n);
    // A light below the geometric surface is hidden by it, whatever the shading normal.
    if (HAS_SHADING && dot(wi, s.ng) <= 0.0) cos_x = 0.0;
    if (!(cos_x > 0.0) || all(equal(arriving, vec3(0.0)))) return vec3(0.0);
    rays++;
    // A directional light's and the environment's shadow rays run to infinity (t_max INF
    // along the unit wi).
    bool directional = e.kind == KIND_DIRECTIONAL_LIGHT || e.kind == KIND_ENVIRONMENT;
    if (!unoccluded(origin, directional ? wi : shadow_seg, directional ? INF : 1.0, overflow)) return vec3(0.0);
    return material_eval(s.m, wo, wi, n) * cos_x * arriving;
}

void pt_step(inout Path p, inout Sampler smp, inout uint rays, inout bool overflow) {
    Hit h;
    SurfaceHit s;
    if (!next_vertex(p, h, s, rays, overflow)) return;
    vec3 le = emitted(s, h);
    if (HAS_EMITTERS && any(greaterThan(le, vec3(0.0)))) {
        float w = 1.0;
        if (!p.prev_delta && s.emitter != NO_EMITTER) {
            w = power_heuristic(p.prev_pdf, emitter_pdf_solid_angle(s.emitter, p.prev_p, s.p, s.ng));
        }
        p.L += p.throughput * le * w;
    }
    if (p.bounce == MAX_BOUNCES) {
        p.done = true;
        return;
    }
    vec3 wo = -p.d;
    vec3 n = s.ns; // the BRDF's frame; ng decides what is above the surface
    vec3 origin = offset_ray_origin(s.p, s.ng, p.o);
    bool gltf = is_metallic_roughness(s.m);
    float p_s = HAS_SPECULAR && !gltf ? s.m.ks.w : 0.0;
    bool mirror = HAS_SPECULAR && !gltf && is_mirror(s.m);

    // Next-event estimation for the non-delta lobes.
    if (HAS_EMITTERS && scene_info.emitter_count > 0u && (!mirror || p_s < 1.0)) {
        p.L += p.throughput * next_event(s, wo, origin, smp, rays, overflow);
    }

    // Sample the brdf: glTF's mixture, or (thesis) a lobe chosen with p_S, then importance-sampled.
    vec3 wi;
    float u_lobe = sample_1d(smp);
    bool spec_pick = u_lobe < p_s;
    vec2 u = sample_2d(smp);
    if (gltf) {
        float pdf;
        // Below the shading or the geometric surface: absorbed.
        if (!gltf_sample(s.m, wo, n, u_lobe, u, wi, pdf) || (HAS_SHADING && dot(wi, s.ng) <= 0.0)) {
            p.done = true;
            return;
        }
        p.throughput *= gltf_eval(s.m, wo, wi, n) * dot(wi, n) / pdf;
        p.prev_pdf = pdf;
        p.prev_delta = false;
        widen_cone(p, s.m);
    } else if (spec_pick && mirror) {
        wi = reflect(p.d, n);
        if (HAS_SHADING && dot(wi, s.ng) <= 0.0) { // valid_shading_normal prevents it, up to rounding
            p.done = true;
            return;
        }
        p.throughput *= s.m.ks.xyz / p_s;
        p.prev_delta = true;
    } else {
        if (spec_pick) {
            // alpha = 0 is the constant lobe (cos^0 = 1 even where theta_r > 90 deg):
            // sample it over the hemisphere around n, which is where it is non-zero.
            float alpha = s.m.kd.w;
            wi = sample_power_cosine(u, alpha == 0.0 ? n : reflect(p.d, n), alpha);
        } else {
            wi = sample_power_cosine(u, n, 1.0);
        }
        float cos_i = dot(wi, n);
        // The lobe dipped below the surface, shading or geometric: absorbed.
        if (cos_i <= 0.0 || (HAS_SHADING && dot(wi, s.ng) <= 0.0)) {
            p.done = true;
            return;
        }
        // brdf_eval and brdf_pdf cover only the non-delta lobes, so a mirror's diffuse
        // part needs no special case here.
        vec3 f = brdf_eval(s.m, wo, wi, n);
        float pdf = brdf_pdf(s.m, wo, wi, n);
        if (!(pdf > 0.0)) {
            p.done = true;
            return;
        }
        p.throughput *= f * cos_i / pdf;
        p.prev_pdf = pdf;
        p.prev_delta = false;
    }
    // Russian roulette after 3 bounces: continue with probability max(throughput).
    if (p.bounce >= 3u) {
        float q = min(max(max(p.throughput.x, p.throughput.y), p.throughput.z), 0.95);
        if (!(sample_1d(smp) < q)) {
            p.done = true;
            return;
        }
        p.throughput /= q;
    }
    p.prev_p = s.p;
    p.o = origin;
    p.d = wi;
    p.bounce++;
}

#endif
