#version 460
// The temporal pass: after resolve, per pixel of one eye, the pixel's history (the mean and
// count of the samples traced at this pixel in earlier frames, and the surface they belong
// to) is carried into this frame and the pixel's own new samples are added to it; what is
// shown is that history, with resolve's spatial estimate mixed in only while the pixel has
// few samples of its own.
//
// History belongs to scene points, not to layers: a pixel's samples are those traced at its
// own pixel centre by the layer shown there (the sparse layers' lattices shift every
// frame, render/history.rs, so every pixel is traced in turn), and history is carried
// between frames by reprojection: the pixel's surface (its own, or the nearest lattice
// point's of the layer shown there) gives its scene point, the point's place in the earlier
// frame's image the history taps. A tap whose surface differs (object, normal, distance) is
// disoccluded or occluded and rejected. While the camera stands still nothing is resampled
// and nothing is capped: the history is the plain mean of every sample the pixel got, which
// converges to the unbiased image. In motion taps are bilinear and the count is capped, so
// history follows (exponentially) what the pixel sees now, and a sparse layer's pixel that
// has no sample of its own this frame adds resolve's spatial estimate to its history, so
// that the periphery does not show a fresh noisy fill every frame.
// It keeps each pixel's mean albedo the same way (HISTORY_ALBEDO, with the radiance's
// weights), which within a surface is what the clamp in motion bounds (the texture; the
// illumination is left as averaged). While a layer denoises it divides what it shows by it
// and the denoiser multiplies it back; and it tells the denoiser how noisy what it shows is
// (the pixel's alpha, see shown_variance), so that the denoiser blurs only while the
// history is short. For that it keeps, beside the albedo, the first two moments of the
// illumination's luminance over the pixel's frames (see history_variance).
//
// One invocation per pixel: this pass is simple per-pixel work, not shaped for lavapipe
// like resolve.comp, except that it reads through texel views (the lattice's values and
// surfaces, the frame before's history: bindings.glsl). The host binds the plane the frame
// before wrote as HISTORY_TEXELS and SURFACE_TEXELS, the other as HISTORY and
// HISTORY_SURFACE, which this frame writes.
#extension GL_GOOGLE_include_directive : require
#define READS_PIXELS
#define PASS_PUSH EyePush
#include "plan.glsl"
#include "view.glsl"
#include "surface.glsl"
#include "albedo.glsl"
#include "colour.glsl"
#include "lattice_texels.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

// A tap is the same surface when the object and its material are the same (an emitter
// set into a wall of the same mesh is another surface), the normals within ~25 degrees
// and the distances within 5% (+ 1 mm): generous enough for the approximate surface of
// a pixel between lattice points, tight enough to see a step in depth.
const float SAME_NORMAL_COS = 0.9;
const float SAME_DISTANCE = 0.05;
// In motion, a pixel next to an edge between surfaces keeps at most this many frames' worth
// of its layer's samples (own, or spatial ones, see SPATIAL_SHARE): 4 cut flicker beyond 20°
// by half on cornell against 2 (bench --motion); 8 lags behind a camera turn more than
// tests/temporal.rs allows.
const float EDGE_CAP = 4.0;
// In motion, a frame's spatial estimate at a pixel without own samples counts as this share
// of the layer's spp in the history (see main).
const float SPATIAL_SHARE = 1.0;

struct Surface {
    float dist; // < 0: nothing (the sky)
    vec3 n;
    uint object;
    uint material;
};

Surface decode(uvec4 s) {
    Surface r;
    r.dist = uintBitsToFloat(s.x);
    r.n = from_octahedral(unpackSnorm2x16(s.y));
    r.object = s.z;
    r.material = s.w;
    return r;
}

// Whether a history tap's surface `a` may be this pixel's surface `b` seen from the earlier
// camera. `spread` is how much the distance varies across the pixel's 3x3 lattice
// neighbourhood: a surface seen at a grazing angle (a floor towards the horizon) changes
// distance by more than 5% from pixel to pixel. In a sparse layer (spacing > 1, or a
// fraction of the points traced per frame) `b` is mostly a nearby lattice point's surface,
// which changes as the lattice shifts every frame: there the tap's object and material need only be among the neighbourhood's
// (`near`), and its normal is not compared. A test as tight as the fovea's rejected nearly
// all peripheral history in motion (bench --motion: as much flicker beyond 20° with history
// as without); what the looser test lets through is bounded by the neighbourhood clamp and,
// next to edges, by EDGE_CAP.
//
// In a dense layer a distance beyond 5% passes only where the tap lies on the pixel's plane
// (`plane_gap`: how far the tap's point is from the plane through this pixel's point with its
// normal, within 5%): the grazing surface, whose points are all on it. A step in depth within
// one object (a plate before a wall of the same mesh) also makes the spread large, and there
// the tap is the other depth's, off the plane: kept, it carried the plate's radiance onto the
// wall the camera uncovered, a ghost that the clamp within a surface then kept
// (tests/temporal.rs).
bool same_surface(Surface a, Surface b, bool sparse, float spread, bool near, float plane_gap) {
    bool same_kind = a.object == b.object && a.material == b.material;
    float tolerance = max(SAME_DISTANCE * b.dist, spread) + 1e-3;
    if (sparse) {
        if (!near) return false;
        // Another surface of the neighbourhood, or the sky on one side: which one the
        // nearest lattice point hit is a coin toss along an edge (a horizon), so the tap
        // is kept, bounded by the clamp and the edge cap.
        if (!same_kind || a.dist < 0.0 || b.dist < 0.0) return true;
        return abs(a.dist - b.dist) <= tolerance;
    }
    if (!same_kind) return false;
    if (a.dist < 0.0 || b.dist < 0.0) return a.dist < 0.0 && b.dist < 0.0;
    float close = SAME_DISTANCE * b.dist + 1e-3;
    float apart = abs(a.dist - b.dist);
    bool on_plane = apart <= tolerance && plane_gap <= close;
    return dot(a.n, b.n) > SAME_NORMAL_COS && (apart <= close || on_plane);
}

uint history_index(ivec2 p) {
    return eye_pixel_index(p);
}

void history_store(uint i, vec4 v, uvec4 surface) {
    history_out[i] = v;
    history_surface_out[i] = surface;
}

// Whether this frame keeps the pixels' albedos (HISTORY_ALBEDO), whether the frame before
// did, so that there are albedos to carry, and whether a layer denoises, so that what is
// shown is divided by them.
bool keeps_albedo() {
    return (pc.albedo & ALBEDO_ON) != 0u;
}

bool divides_albedo() {
    return (pc.albedo & ALBEDO_DIVIDED) != 0u;
}

bool carries_albedo() {
    return (pc.albedo & ALBEDO_CARRIED) != 0u;
}

// Whether the frame before kept the illumination's moments (it divided too); this frame keeps
// them while it divides.
bool carries_moments() {
    return (pc.albedo & ALBEDO_MOMENTS_CARRIED) != 0u;
}

// The frame before's albedo at pixel index i (none when it kept none).
vec3 albedo_carried_from(uint i) {
    return carries_albedo() ? unpack_albedo(albedo_before[i].albedo) : vec3(0.0);
}

// The frame before's illumination moments at pixel index i (read only while carries_moments()).
vec2 moments_carried_from(uint i) {
    return vec2(albedo_before[i].moment1, albedo_before[i].moment2);
}

// The pixel's albedo now, as its radiance's mean is made: what was carried with `carried`
// samples' weight, this frame's (its lattice point's) with `added`. The denoiser's guide is
// this mean, not this frame's samples' albedo alone: a texel edge across the pixel changes
// that from frame to frame, and the history's radiance, which it divides, mixes both texels.
uint albedo_now(vec3 carried_albedo, float carried, vec3 added_albedo, float added) {
    if (!carries_albedo()) carried = 0.0;
    if (carried + added <= 0.0) return pack_albedo(added_albedo);
    return pack_albedo((carried_albedo * carried + added_albedo * added) / (carried + added));
}

// The pixel's illumination moments now, as its albedo's mean is made.
vec2 moments_now(vec2 carried_moments, float carried, vec2 added_moments, float added) {
    if (!carries_moments()) carried = 0.0;
    if (carried + added <= 0.0) return added_moments;
    return (carried_moments * carried + added_moments * added) / (carried + added);
}

// A lattice point's illumination luminance (what the denoiser filters: its radiance divided
// by its albedo) and that squared: summed over 3x3 points, the moments of moments_variance.
vec2 illumination_moments(vec3 radiance, uint albedo_bits) {
    float l = luminance(radiance / albedo_divisor(albedo_bits));
    return vec2(l, l * l);
}

// The variance of the illumination's luminance among this frame's 3x3 nearest lattice points
// of the pixel's layer, from their moments summed: one lattice point's noise, as SVGF
// estimates it spatially (with what the surface's shading changes across them, which no
// single frame can tell from noise).
float moments_variance(vec2 moments) {
    vec2 mean = moments / 9.0;
    return max(mean.y - mean.x * mean.x, 0.0);
}

// The moments of layer k's 3x3 nearest lattice points around the pixel. In motion the
// neighbourhood clamp reads the same points and sums them as it goes (main).
vec2 lattice_moments(uint k, ivec2 nearest, ivec2 box_first, ivec2 box_last) {
    vec2 moments = vec2(0.0);
    for (int i = 0; i < 9; ++i) {
        uint entry = lattice_index(k, clamp(nearest + ivec2(i % 3 - 1, i / 3 - 1), box_first, box_last));
        moments += illumination_moments(lattice_texel(entry).rgb, lattice_albedo[entry]);
    }
    return moments;
}

// A history needs this many frames' worth of samples before its own moments say how noisy it
// is; until then the 3x3 lattice points' spatial estimate does (SVGF's 4).
const float TEMPORAL_VARIANCE_FRAMES = 4.0;

// One lattice point's illumination variance from the history's own frames (the first two
// moments of their illumination's luminance, kept as its radiance is): SVGF's temporal
// variance (Schied et al. 2017), which the denoiser's edge-stop compares with once a dense
// layer's history holds TEMPORAL_VARIANCE_FRAMES frames of them; before that the 3x3 lattice
// points' (moments_variance) does. Nine points of one frame underrate a path tracer's
// heavy-tailed noise (cornell's denoised 1 spp gained 0.017 JOD in motion with the
// history's), and they count the shading's own changes across them as noise (a shadow's edge
// within a surface, which they blurred by 4% of the step and the history's frames by 0.5%:
// tests/temporal.rs). A sparse layer keeps the 3x3's: in motion its pixels add resolve's
// spatial estimate to their history between their own samples, which is smoother than a
// sample.
float history_variance(vec2 history_moments) {
    return max(history_moments.y - history_moments.x * history_moments.x, 0.0);
}

// The variance of the luminance the pixel shows (what the denoiser's edge-stop compares
// with, denoise.comp): one sample's (a lattice point's variance times its spp) over the
// samples' worth of what is shown. So a pixel with a long history shows little noise and
// the denoiser keeps what its neighbours differ by, and a fresh one (disoccluded, or
// just entered the view) is blurred as its lattice point's noise asks.
float shown_variance(float point_variance, float spp, float worth) {
    return point_variance * spp / max(worth, 1e-6);
}

// World direction of a continuous pixel position seen by a camera (basis r, u, f; tangents
// of its left, right, up and down edges), as trace.comp's camera_ray makes it.
vec3 view_dir(vec4 tan4, vec3 r, vec3 u, vec3 f, vec2 pos) {
    vec2 uv = pos / vec2(pc.eye.width, pc.eye.height);
    vec2 t = vec2(mix(tan4.x, tan4.y, uv.x), mix(tan4.z, tan4.w, uv.y));
    return normalize(f + t.x * r + t.y * u);
}

// This frame's direction through the centre of pixel q.
vec3 pixel_dir(ivec2 q) {
    return view_dir(pc.cam.tan, pc.cam.right.xyz, pc.cam.up.xyz, pc.cam.forward.xyz, vec2(q) + 0.5);
}

// The earlier frame's direction through the centre of its pixel t.
vec3 earlier_dir(GpuHistoryView v, ivec2 t) {
    return view_dir(v.tan, v.right.xyz, v.up.xyz, v.forward.xyz, vec2(t) + 0.5);
}

// Whether pixel t lies in the eye's image.
bool within_image(ivec2 t) {
    return all(greaterThanEqual(t, ivec2(0))) && t.x < int(pc.eye.width) && t.y < int(pc.eye.height);
}

// Catmull-Rom's weights of the four samples at -1, 0, 1, 2 for a point t (0..1) past sample 0.
vec4 catmull_rom(float t) {
    return vec4(t * (-0.5 + t * (1.0 - 0.5 * t)),
                1.0 + t * t * (-2.5 + 1.5 * t),
                t * (0.5 + t * (2.0 - 1.5 * t)),
                t * t * (-0.5 + 0.5 * t));
}

// The 8 pixels of the 4x4 around a bilinear footprint that are beside its 4 taps (not its
// corners), as (column, row) of the 4x4.
const ivec2 BESIDE_TAPS[8] = ivec2[8](ivec2(1, 0), ivec2(2, 0), ivec2(0, 1), ivec2(3, 1),
                                      ivec2(0, 2), ivec2(3, 2), ivec2(1, 3), ivec2(2, 3));

// Where direction d (from the camera's position) lands in that camera's image, in continuous
// pixel coordinates; false behind the camera.
bool project(GpuHistoryView v, vec3 d, out vec2 pos) {
    float z = dot(d, v.forward.xyz);
    pos = vec2(-1.0);
    if (z <= 1e-6 * length(d)) return false;
    vec2 t = vec2(dot(d, v.right.xyz), dot(d, v.up.xyz)) / z;
    vec2 uv = (t - v.tan.xz) / (v.tan.yw - v.tan.xz);
    pos = uv * vec2(pc.eye.width, pc.eye.height);
    return true;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.eye.width) || p.y >= int(pc.eye.height)) return;
    uint base = eye_layer_base();
    GpuHistoryView view = history_views[(pc.eye.history >> 2) * STAT_EYES + pc.eye.index];
    uint out_index = eye_pixel_index(p);
    uint mask_words = visibility[0];
    vec3 u = tan_direction(layers[base].pixel_tan.xy + vec2(p) * layers[base].pixel_tan.zw);
    bool shown = within_angle(u, vec3(0.0, 0.0, 1.0), layers[base].resolve_cos.z)
              && visibility_bit(mask_words, pc.eye.index * (pc.eye.layer_count + 1u), p);
    if (!shown) { // never traced, black in resolve: no history either
        history_store(history_index(p), vec4(0.0), uvec4(SURFACE_NONE, 0u, NO_OBJECT, SURFACE_HIDDEN));
        if (keeps_albedo()) history_albedo_out[history_index(p)] = HistoryGuide(pack_albedo(vec3(1.0)), 0.0, 0.0);
        if (divides_albedo()) pixels[out_index] = vec4(0.0); // black, and no noise for the denoiser
        return;
    }

    // The layer shown here (the innermost whose radius holds the pixel) and its spp.
    uint k = base + shown_depth(u, base);
    float shown_spp = float(max(layers[k].spp, 1u));
    // The pixel's own samples this frame: its shown layer's, when its lattice (shifted
    // every frame) has a point on the pixel: every shown point is traced. (Another layer may
    // trace the pixel too, in its margin; those samples are left out, which costs a little
    // noise, not bias: testing every layer per pixel cost more than it gained on lavapipe.)
    ivec2 box_first = box_lo(k);
    ivec2 box_last = box_hi(k);
    // A fractional layer's points skipped this frame were filled from their neighbours
    // (lattice_fill.comp, alpha 0): they are no samples of the pixel's own.
    bool sparse = layers[k].spacing > 1 || layers[k].fraction > 1u;
    ivec2 nearest = nearest_lattice_point(k, p);
    uint own_entry = lattice_index(k, nearest);
    // Its own point, when traced (alpha 1) this frame, not filled (alpha 0, lattice_fill.comp).
    bool own_here = lattice_pixel(k, nearest) == p && lattice_texel(own_entry).a > 0.5;
    uint own_spp = own_here ? layers[k].spp : 0u;
    // The pixel's surface now: its own, else its shown layer's nearest lattice point's.
    uint surface_entry = own_entry;
    uvec4 now_packed = lattice_surface_at(surface_entry);
    Surface now = decode(now_packed);

    // The history carried into this frame: the earlier frame's pixel at the same scene point.
    vec4 carried = vec4(0.0);
    uvec4 carried_packed = now_packed;
    vec3 carried_albedo = vec3(0.0); // while keeps_albedo(), with the radiance's weights
    vec2 carried_moments = vec2(0.0); // and the illumination's moments, the same way
    // While keeps_albedo(): the 3x3 lattice points' illumination moments, for the denoiser's
    // noise estimate, when the clamp below has read the points (in motion).
    vec2 moments = vec2(0.0);
    bool moments_summed = false;
    if (view.valid != 0u) {
        if (view.moved == 0u) {
            // Standing still: the same pixel, whole (no resampling, no test: nothing moved).
            carried = history_before(history_index(p));
            carried_packed = pixel_surface(history_index(p));
            if (keeps_albedo()) carried_albedo = albedo_carried_from(history_index(p));
            if (carries_moments()) carried_moments = moments_carried_from(history_index(p));
        } else {
            // This frame's 3x3 nearest lattice points around the pixel: the range of their
            // radiance (the clamp below), whether another surface is among them (an edge), and
            // how far the distance to this surface varies across them.
            vec3 lo = vec3(1e30);
            vec3 hi = vec3(-1e30);
            vec3 albedo_lo = vec3(1.0); // and of their albedos, while keeps_albedo()
            vec3 albedo_hi = vec3(0.0);
            bool edge = false;
            bool step = false; // in a dense layer: a neighbour of this object off this pixel's plane
            float spread = 0.0;
            uvec2 kinds[9];
            vec3 d = pixel_dir(p);
            for (int i = 0; i < 9; ++i) {
                ivec2 point = clamp(nearest + ivec2(i % 3 - 1, i / 3 - 1), box_first, box_last);
                uint entry = lattice_index(k, point);
                vec3 v = lattice_texel(entry).rgb;
                lo = min(lo, v);
                hi = max(hi, v);
                if (keeps_albedo()) {
                    uint albedo_bits = lattice_albedo[entry];
                    vec3 a = unpack_albedo(albedo_bits);
                    albedo_lo = min(albedo_lo, a);
                    albedo_hi = max(albedo_hi, a);
                    if (divides_albedo()) moments += illumination_moments(v, albedo_bits);
                }
                Surface s = decode(lattice_surface_at(entry));
                kinds[i] = uvec2(s.object, s.material);
                bool other = s.object != now.object || s.material != now.material;
                edge = edge || other;
                if ((!other || sparse) && s.dist >= 0.0 && now.dist >= 0.0) spread = max(spread, abs(s.dist - now.dist));
                if (!other && !sparse && s.dist >= 0.0 && now.dist >= 0.0) {
                    vec3 at = s.dist * pixel_dir(lattice_pixel(k, point));
                    step = step || abs(dot(at - now.dist * d, now.n)) > SAME_DISTANCE * now.dist;
                }
            }
            moments_summed = divides_albedo();
            // From the earlier camera: the point (or, for the sky, the direction).
            vec3 seen = now.dist < 0.0 ? d : pc.cam.position.xyz + now.dist * d - view.position.xyz;
            Surface expected = now;
            expected.dist = now.dist < 0.0 ? -1.0 : length(seen);
            vec2 q;
            // The history's illumination (its radiance over its albedo): carried apart from
            // the albedo from here, and the two multiplied once, after the clamp below.
            vec3 illumination = vec3(0.0);
            if (project(view, seen, q)) {
                // Bilinear taps around q, each kept only where its surface is this one.
                // Every frame the view moves they blur the history a little (a tap between
                // pixels averages them), and the history lives tens of frames; that blur also
                // smooths the illumination's noise, which FovVideoVDP rewards at 1-2 spp. The
                // texture need not blur: where all 4 taps are kept and the 8 pixels beside
                // them are this object and material too, the albedo is taken by Catmull-Rom
                // over the 4x4 but its corners (within the range of the 4 taps, so it does not
                // ring), and the radiance is the bilinear illumination times it.
                // Catmull-Rom on the radiance itself kept a shadow's edge sharp too, but lost
                // up to 0.23 JOD at 1 spp in motion to the noise it kept
                // (reports/tune-motion-window-lavapipe/sharp-albedo/); so did Catmull-Rom on the
                // illumination where its difference from bilinear stood out of the history's
                // noise, less (reports/tune-motion-window-lavapipe/sharp-illumination/).
                vec2 f = q - 0.5;
                ivec2 t0 = ivec2(floor(f));
                vec2 w1 = f - vec2(t0);
                vec4 cx = catmull_rom(w1.x);
                vec4 cy = catmull_rom(w1.y);
                float weights = 0.0;
                float best = 0.0;
                vec3 sharp_albedo = vec3(0.0); // Catmull-Rom's, while `sharp`
                vec3 taps_albedo_lo = vec3(1.0); // the 4 taps' albedos' range
                vec3 taps_albedo_hi = vec3(0.0);
                bool sharp = carries_albedo();
                for (int i = 0; i < 4; ++i) {
                    ivec2 t = t0 + ivec2(i & 1, i >> 1);
                    float w = ((i & 1) != 0 ? w1.x : 1.0 - w1.x) * ((i >> 1) != 0 ? w1.y : 1.0 - w1.y);
                    if (!within_image(t)) {
                        sharp = false;
                        continue;
                    }
                    vec4 h = history_before(history_index(t));
                    uvec4 hs = pixel_surface(history_index(t));
                    Surface tap = decode(hs);
                    bool near = false;
                    for (int j = 0; j < 9; ++j) near = near || all(equal(kinds[j], hs.zw));
                    float plane_gap = abs(dot(tap.dist * earlier_dir(view, t) - seen, now.n));
                    if (h.w <= 0.0 || !same_surface(tap, expected, sparse, spread, near, plane_gap)) {
                        sharp = false;
                        continue;
                    }
                    vec3 a = albedo_carried_from(history_index(t));
                    sharp_albedo += cx[1 + (i & 1)] * cy[1 + (i >> 1)] * a;
                    taps_albedo_lo = min(taps_albedo_lo, a);
                    taps_albedo_hi = max(taps_albedo_hi, a);
                    if (w <= 0.0) continue;
                    carried += w * h;
                    carried_albedo += w * a;
                    if (carries_moments()) carried_moments += w * moments_carried_from(history_index(t));
                    illumination += w * h.rgb / floored_albedo(a);
                    weights += w;
                    if (w > best) {
                        best = w;
                        carried_packed = hs;
                    }
                }
                carried = weights > 1e-3 ? carried / weights : vec4(0.0);
                carried_albedo = weights > 1e-3 ? carried_albedo / weights : vec3(0.0);
                carried_moments = weights > 1e-3 ? carried_moments / weights : vec2(0.0);
                illumination = weights > 1e-3 ? illumination / weights : vec3(0.0);
                // The 8 pixels beside the 4 taps (the 4x4's corners, whose weights are the
                // products of two small lobes, at most 0.006, are left out): only their
                // albedos are read, so only their object and material are compared (what they
                // might carry from another depth of it is bounded by the taps' range).
                for (int i = 0; i < 8 && sharp; ++i) {
                    ivec2 c = BESIDE_TAPS[i];
                    ivec2 t = t0 - 1 + c;
                    sharp = within_image(t) && all(equal(pixel_surface(history_index(t)).zw, uvec2(now.object, now.material)));
                    if (sharp) sharp_albedo += cx[c.x] * cy[c.y] * albedo_carried_from(history_index(t));
                }
                // The weights used: all but the corners' (Catmull-Rom's weights sum to 1).
                float sharp_weights = 1.0 - (cx.x + cx.w) * (cy.x + cy.w);
                if (sharp) {
                    carried_albedo = clamp(sharp_albedo / sharp_weights, taps_albedo_lo, taps_albedo_hi);
                } else {
                    // Elsewhere the history's radiance is bilinear (its mean as it was kept, not
                    // the bilinear illumination times the bilinear albedo).
                    illumination = carried.rgb / floored_albedo(carried_albedo);
                }
                // Distances are from this frame's camera from now on.
                carried_packed.x = now_packed.x;
            }
            carried.w = min(carried.w, float(view.cap));
            // Neighbourhood clamp: carried radiance stays within what this frame traced
            // around the pixel (its layer's 3x3 nearest lattice points). A pixel an edge
            // crossed held a mix of both sides that its centre's surface test cannot see
            // (the sky does not move when the camera steps); this frame's samples can.
            // And so is the albedo: resampled frame after frame it would blur, and the
            // texture the denoiser multiplies back with it.
            // Within one smooth surface (no other among the 3x3, no step in distance there,
            // not the sky, a dense layer) only the albedo is clamped: the texture. The
            // illumination is left as the history averaged it: at 1 spp the range of one
            // frame's 3x3 samples is their noise, mostly below the mean (a few paths find the
            // light), and clamping to it darkened a turning view's history by 5%
            // (tests/temporal.rs). Next to a step in depth within one object (an ear before
            // the body: `step`) the pixel mixes both depths, as one next to an edge does, and
            // is clamped and capped as that one is.
            bool within_surface = !edge && !step && !sparse && now.dist >= 0.0;
            if (keeps_albedo() && carries_albedo() && within_surface) {
                carried_albedo = clamp(carried_albedo, albedo_lo, albedo_hi);
                carried.rgb = illumination * floored_albedo(carried_albedo);
            } else {
                carried.rgb = clamp(illumination * floored_albedo(carried_albedo), lo, hi);
                if (keeps_albedo()) carried_albedo = clamp(carried_albedo, albedo_lo, albedo_hi);
            }
            // Near an edge between surfaces the part of the pixel each covers changes as the
            // view moves, which no surface test of its centre sees: there history counts
            // for little, and this frame's samples (which do see it) soon take over. So next
            // to a step within one object: without the cap a denoising layer's wall, which a
            // plate of the same mesh had hidden, kept the plate's light (tests/temporal.rs).
            if (edge || step) carried.w = min(carried.w, EDGE_CAP * shown_spp);
        }
    }

    // The pixel's new history: what was carried plus its own samples of this frame.
    vec3 mean = carried.rgb;
    float n = carried.w;
    uvec4 surface = n > 0.0 ? carried_packed : now_packed;
    vec3 spatial = pixels[out_index].rgb;
    float added = 0.0; // the weight this frame's samples, or its spatial estimate, got
    if (own_spp > 0u) {
        vec3 own = lattice_texel(own_entry).rgb;
        mean = (mean * n + own * float(own_spp)) / (n + float(own_spp));
        n += float(own_spp);
        added = float(own_spp);
        surface = now_packed;
    } else if (view.valid != 0u && view.moved != 0u) {
        // In motion a sparse layer's pixel gets its own samples only every spacing^2 frames,
        // and reprojection keeps history capped (exponential, so biased) anyway: there
        // resolve's spatial estimate goes into the history too, worth SPATIAL_SHARE of the
        // layer's spp. Shown fresh every frame instead, its noise would change every frame:
        // the periphery would shimmer (bench --motion measured as much flicker beyond 20°
        // with history as without). Standing still it stays out: the mean of own samples
        // converges unbiased (what motion left in the history is diluted as they come).
        float w = SPATIAL_SHARE * shown_spp;
        mean = (mean * n + spatial * w) / (n + w);
        n += w;
        added = w;
        if (carried.w <= 0.0) surface = now_packed;
    }
    history_store(history_index(p), vec4(mean, n), surface);
    uint albedo = 0u;
    vec2 history_moments = vec2(0.0);
    if (keeps_albedo()) {
        uint own_bits = lattice_albedo[own_entry];
        albedo = albedo_now(carried_albedo, carried.w, unpack_albedo(own_bits), added);
        if (divides_albedo()) {
            vec3 added_value = own_spp > 0u ? lattice_texel(own_entry).rgb : spatial;
            history_moments = moments_now(carried_moments, carried.w, illumination_moments(added_value, own_bits), added);
            history_albedo_out[history_index(p)] = HistoryGuide(albedo, history_moments.x, history_moments.y);
        } else {
            history_albedo_out[history_index(p)].albedo = albedo;
        }
    }

    // Shown: the history, and resolve's spatial estimate (biased by its interpolation) worth
    // the shown layer's spp, halving with every spp-worth of samples the pixel has. Where the
    // lattice filter smoothed the layer, the estimate is worth as many points as the nearest
    // point's filtered value averaged (lattice_filter.comp): the filter's blur shows until
    // the pixel's own samples outweigh it.
    if (pc.eye.debug == DEBUG_LAYERS) return; // the layer tints stay as resolve made them
    float worth = shown_spp;
    if (layers[k].filter_mar > 0.0 || layers[k].filter_px > 0.0) worth *= max(lattice_filtered[own_entry].a, 1.0);
    float w_spatial = worth * exp2(-n / worth);
    vec3 shows = (mean * n + spatial * w_spatial) / (n + w_spatial);
    // While a layer denoises, the denoiser filters the illumination: what is shown is divided
    // by the pixel's albedo here and multiplied back by its last iteration (albedo.glsl), and
    // the alpha carries how noisy it is.
    float noise = 1.0;
    if (divides_albedo()) {
        shows /= albedo_divisor(albedo);
        float point_variance;
        if (carries_moments() && !sparse && n >= TEMPORAL_VARIANCE_FRAMES * shown_spp) {
            point_variance = history_variance(history_moments);
        } else {
            if (!moments_summed) moments = lattice_moments(k, nearest, box_first, box_last);
            point_variance = moments_variance(moments);
        }
        noise = shown_variance(point_variance, shown_spp, n + w_spatial);
    }
    pixels[out_index] = vec4(shows, noise);
}
