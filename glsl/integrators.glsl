// The two estimators of L along a camera ray. Both count bounces the same way: the camera
// ray's hit is vertex 0, and emission is gathered at vertices 0..MAX_BOUNCES.
#ifndef FOVEA_INTEGRATORS_GLSL
#define FOVEA_INTEGRATORS_GLSL
#include "brdf.glsl"
#include "lights.glsl"

// The sky gradient: ground below the horizon, horizon -> zenith above it.
vec3 environment(vec3 d) {
    float y = d.y / max(length(d), 1e-30);
    if (y >= 0.0) return mix(scene_info.sky_horizon.xyz, scene_info.sky_zenith.xyz, y);
    return mix(scene_info.sky_horizon.xyz, scene_info.sky_ground.xyz, min(1.0, -8.0 * y));
}

struct SurfaceHit {
    vec3 p;
    vec3 ng;     // geometric normal, faced toward the incoming ray
    bool front;  // the ray arrived on the side the geometric normal points to
    GpuMaterial m;
    uint emitter; // this point's emitter index, or NO_EMITTER
};

SurfaceHit surface(Hit h, vec3 o, vec3 d) {
    SurfaceHit s;
    s.p = o + h.t * d;
    vec3 n = hit_normal(h, s.p);
    s.front = dot(n, d) < 0.0;
    s.ng = s.front ? n : -n;
    GpuObject ob = objects[h.object];
    s.m = materials[ob.material];
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
    bool triangle = objects[h.object].kind == KIND_INSTANCE;
    return (s.front || !triangle) ? s.m.emission.xyz : vec3(0.0);
}

// ---- seed: the thesis' estimator (eqs. 3.4-3.16) -------------------------------------------
// Uniform hemisphere sampling (p = 1/2pi, eq. 3.5); the BRDF picked by comparing R with p_S
// (eq. 3.11); the weight 2*k_d*cos (Lambert) or k_s(alpha+2)cos^alpha theta_r*cos (Phong) of eq. 3.13, divided
// by the probability of the pick (the p^-1 of eq. 3.15); 8 bounces or until the energy is zero.
// eq. 3.15's clamp f_c(n*w_i)^((alpha+2)/(alpha+1)) belongs to lobe-sampled directions; with the uniform
// directions eq. 3.5 states it would bias the image, so the eq. 3.13 weight is used instead.
vec3 trace_seed(vec3 o, vec3 d, inout Rng rng, inout uint rays, inout bool overflow) {
    vec3 L = vec3(0.0);
    vec3 energy = vec3(1.0);
    for (uint bounce = 0u; bounce <= MAX_BOUNCES; ++bounce) {
        Hit h = trace_scene(o, d, 0.0, INF, false);
        rays++;
        overflow = overflow || h.overflow;
        if (h.t == INF) {
            L += energy * environment(d);
            break;
        }
        SurfaceHit s = surface(h, o, d);
        L += energy * emitted(s, h);
        if (bounce == MAX_BOUNCES) break;
        float p_s = HAS_SPECULAR ? s.m.ks.w : 0.0;
        vec3 wo = -d;
        if (rng_next(rng) < p_s) {
            if (is_mirror(s.m)) {
                d = reflect(d, s.ng);
                energy *= s.m.ks.xyz / p_s;
            } else {
                d = sample_power_cosine(rng_next2(rng), s.ng, 0.0);
                vec3 r = reflect(-wo, s.ng);
                float alpha = s.m.kd.w;
                energy *= s.m.ks.xyz * (alpha + 2.0) * phong_lobe(d, r, alpha) * dot(s.ng, d) / p_s;
            }
        } else {
            d = sample_power_cosine(rng_next2(rng), s.ng, 0.0);
            energy *= 2.0 * s.m.kd.xyz * dot(s.ng, d) / (1.0 - p_s);
        }
        if (all(equal(energy, vec3(0.0)))) break;
        o = offset_ray_origin(s.p, s.ng, o);
    }
    return L;
}

// ---- pt: importance sampling, next-event estimation with MIS, Russian roulette ---------------
float power_heuristic(float a, float b) {
    float a2 = a * a;
    return a2 / (a2 + b * b);
}

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

vec3 trace_pt(vec3 o, vec3 d, inout Rng rng, inout uint rays, inout bool overflow) {
    vec3 L = vec3(0.0);
    vec3 throughput = vec3(1.0);
    float prev_pdf = 0.0;   // solid-angle density of the last brdf sample
    bool prev_delta = true; // camera rays and mirror bounces cannot be found by NEE
    vec3 prev_p = o;
    for (uint bounce = 0u; bounce <= MAX_BOUNCES; ++bounce) {
        Hit h = trace_scene(o, d, 0.0, INF, false);
        rays++;
        overflow = overflow || h.overflow;
        if (h.t == INF) {
            L += throughput * environment(d);
            break;
        }
        SurfaceHit s = surface(h, o, d);
        vec3 le = emitted(s, h);
        if (HAS_EMITTERS && any(greaterThan(le, vec3(0.0)))) {
            float w = 1.0;
            if (!prev_delta && s.emitter != NO_EMITTER) {
                w = power_heuristic(prev_pdf, emitter_pdf_solid_angle(s.emitter, prev_p, s.p, s.ng));
            }
            L += throughput * le * w;
        }
        if (bounce == MAX_BOUNCES) break;
        vec3 wo = -d;
        vec3 n = s.ng;
        vec3 origin = offset_ray_origin(s.p, n, o);
        float p_s = HAS_SPECULAR ? s.m.ks.w : 0.0;
        bool mirror = HAS_SPECULAR && is_mirror(s.m);

        // Next-event estimation for the non-delta lobes.
        if (HAS_EMITTERS && scene_info.emitter_count > 0u && (!mirror || p_s < 1.0)) {
            uint count = scene_info.emitter_count;
            uint index = min(uint(rng_next(rng) * float(count)), count - 1u);
            vec3 u = vec3(rng_next2(rng), rng_next(rng));
            LightSample ls = sample_emitter(index, u);
            vec3 to_light = ls.p - s.p;
            float dist2 = dot(to_light, to_light);
            vec3 wi = to_light * inversesqrt(max(dist2, 1e-30));
            float cos_x = dot(wi, n);
            GpuEmitter e = emitters[index];
            float cos_l = e.kind == KIND_TRIANGLE ? -dot(ls.n, wi) : abs(dot(ls.n, wi));
            if (cos_x > 0.0 && cos_l > 0.0 && dist2 > 0.0) {
                float light_pdf = ls.area_pdf * dist2 / cos_l;
                vec3 f = brdf_eval(s.m, wo, wi, n);
                float bpdf = brdf_pdf(s.m, wo, wi, n);
                // Shadow ray to just short of the light's surface.
                vec3 target = offset_ray_origin(ls.p, -wi * sign(cos_l), ls.p);
                vec3 seg = target - origin;
                rays++;
                if (unoccluded(origin, seg, 1.0, overflow)) {
                    L += throughput * f * cos_x * e.emission.xyz * (power_heuristic(light_pdf, bpdf) / light_pdf);
                }
            }
        }

        // Sample the brdf: choose a lobe with p_S, then importance-sample it.
        vec3 wi;
        bool spec_pick = rng_next(rng) < p_s;
        vec2 u = rng_next2(rng);
        if (spec_pick && mirror) {
            wi = reflect(d, n);
            throughput *= s.m.ks.xyz / p_s;
            prev_delta = true;
        } else {
            if (spec_pick) {
                // alpha = 0 is the constant lobe (cos^0 = 1 even where theta_r > 90 deg):
                // sample it over the hemisphere around n, which is where it is non-zero.
                float alpha = s.m.kd.w;
                wi = sample_power_cosine(u, alpha == 0.0 ? n : reflect(d, n), alpha);
            } else {
                wi = sample_power_cosine(u, n, 1.0);
            }
            float cos_i = dot(wi, n);
            if (cos_i <= 0.0) break; // the Phong lobe dipped below the surface: absorbed
            // brdf_eval and brdf_pdf cover only the non-delta lobes, so a mirror's diffuse
            // part needs no special case here.
            vec3 f = brdf_eval(s.m, wo, wi, n);
            float pdf = brdf_pdf(s.m, wo, wi, n);
            if (!(pdf > 0.0)) break;
            throughput *= f * cos_i / pdf;
            prev_pdf = pdf;
            prev_delta = false;
        }
        // Russian roulette after 3 bounces: continue with probability max(throughput).
        if (bounce >= 3u) {
            float q = min(max(max(throughput.x, throughput.y), throughput.z), 0.95);
            if (!(rng_next(rng) < q)) break;
            throughput /= q;
        }
        prev_p = s.p;
        o = origin;
        d = wi;
    }
    return L;
}

#endif
