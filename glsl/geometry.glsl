// Ray/primitive intersection: watertight triangles (Woop, Benthin, Wald 2013), slab boxes,
// numerically robust spheres (Haines et al., Ray Tracing Gems ch. 7), and ray-origin offsets
// that escape the surface without a scene-scale epsilon (Wachter & Binder, RTG ch. 6).
#ifndef FOVEA_GEOMETRY_GLSL
#define FOVEA_GEOMETRY_GLSL

#define INF uintBitsToFloat(0x7f800000u)
const float PI = 3.14159265358979;

// Moves p off the surface with geometric normal n by a few ulps of p's integer representation,
// so the offset scales with the magnitude of the coordinates (no acne far from the origin).
// `from` is the origin of the ray whose hit p is: p = from + t d carries rounding of a few
// ulps of |from| too, which dominates when a surface near the world origin is seen from far
// away (a camera 200 units above a ground plane through y = 0), so the offset also covers
// 64 ulps of from's largest coordinate.
vec3 offset_ray_origin(vec3 p, vec3 n, vec3 from) {
    const float origin = 1.0 / 32.0;
    const float float_scale = 1.0 / 65536.0;
    const float int_scale = 256.0;
    const float from_scale = 64.0 / 8388608.0;
    ivec3 of_i = ivec3(int_scale * n);
    vec3 p_i = vec3(
        intBitsToFloat(floatBitsToInt(p.x) + ((p.x < 0.0) ? -of_i.x : of_i.x)),
        intBitsToFloat(floatBitsToInt(p.y) + ((p.y < 0.0) ? -of_i.y : of_i.y)),
        intBitsToFloat(floatBitsToInt(p.z) + ((p.z < 0.0) ? -of_i.z : of_i.z)));
    vec3 moved = vec3(
        abs(p.x) < origin ? p.x + float_scale * n.x : p_i.x,
        abs(p.y) < origin ? p.y + float_scale * n.y : p_i.y,
        abs(p.z) < origin ? p.z + float_scale * n.z : p_i.z);
    vec3 a = abs(from);
    return moved + (from_scale * max(max(a.x, a.y), a.z)) * n;
}

// Replaces zero direction components by a tiny signed value so 1/d is finite and the slab
// tests never compute 0 * inf = NaN.
vec3 safe_direction(vec3 d) {
    const float tiny = 1e-20;
    return vec3(abs(d.x) < tiny ? (d.x < 0.0 ? -tiny : tiny) : d.x,
                abs(d.y) < tiny ? (d.y < 0.0 ? -tiny : tiny) : d.y,
                abs(d.z) < tiny ? (d.z < 0.0 ? -tiny : tiny) : d.z);
}

// Per-ray constants of the watertight test: the axis permutation and shear.
struct WatertightRay {
    ivec3 k; // kx, ky, kz
    vec3 s;  // Sx, Sy, Sz
};

WatertightRay watertight_setup(vec3 d) {
    vec3 a = abs(d);
    int kz = (a.x > a.y) ? ((a.x > a.z) ? 0 : 2) : ((a.y > a.z) ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    if (d[kz] < 0.0) {
        int tmp = kx;
        kx = ky;
        ky = tmp;
    }
    WatertightRay w;
    w.k = ivec3(kx, ky, kz);
    w.s = vec3(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    return w;
}

// Returns the hit distance in (t_min, t_max), or INF. Edges shared by two triangles are never
// missed by both: the sign tests on the scaled barycentrics U, V, W are exact on the sheared
// 2D projection.
float intersect_triangle(vec3 o, WatertightRay w, vec3 v0, vec3 v1, vec3 v2, float t_min, float t_max) {
    vec3 A = v0 - o;
    vec3 B = v1 - o;
    vec3 C = v2 - o;
    float Ax = A[w.k.x] - w.s.x * A[w.k.z];
    float Ay = A[w.k.y] - w.s.y * A[w.k.z];
    float Bx = B[w.k.x] - w.s.x * B[w.k.z];
    float By = B[w.k.y] - w.s.y * B[w.k.z];
    float Cx = C[w.k.x] - w.s.x * C[w.k.z];
    float Cy = C[w.k.y] - w.s.y * C[w.k.z];
    float U = Cx * By - Cy * Bx;
    float V = Ax * Cy - Ay * Cx;
    float W = Bx * Ay - By * Ax;
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return INF;
    float det = U + V + W;
    if (det == 0.0) return INF;
    float T = U * (w.s.z * A[w.k.z]) + V * (w.s.z * B[w.k.z]) + W * (w.s.z * C[w.k.z]);
    float t = T / det;
    return (t > t_min && t < t_max) ? t : INF;
}

// Slab test; returns the entry distance, or the exit distance when the origin is inside.
float intersect_box(vec3 o, vec3 inv_d, vec3 bmin, vec3 bmax, float t_min, float t_max) {
    vec3 t0 = (bmin - o) * inv_d;
    vec3 t1 = (bmax - o) * inv_d;
    vec3 tn = min(t0, t1);
    vec3 tf = max(t0, t1);
    float t_near = max(max(tn.x, tn.y), tn.z);
    float t_far = min(min(tf.x, tf.y), tf.z);
    if (t_near > t_far) return INF;
    if (t_near > t_min && t_near < t_max) return t_near;
    if (t_far > t_min && t_far < t_max) return t_far;
    return INF;
}

// Outward normal of the box face containing p: the axis where p is relatively closest to a face.
vec3 box_normal(vec3 p, vec3 bmin, vec3 bmax) {
    vec3 c = 0.5 * (bmin + bmax);
    vec3 h = max(0.5 * (bmax - bmin), vec3(1e-30));
    vec3 q = (p - c) / h;
    vec3 a = abs(q);
    if (a.x >= a.y && a.x >= a.z) return vec3(sign(q.x), 0.0, 0.0);
    if (a.y >= a.z) return vec3(0.0, sign(q.y), 0.0);
    return vec3(0.0, 0.0, sign(q.z));
}

// Robust quadratic: the discriminant from the perpendicular distance (no catastrophic
// cancellation for distant spheres) and the smaller root from Vieta's formula.
float intersect_sphere(vec3 o, vec3 d, vec3 centre, float radius, float t_min, float t_max) {
    vec3 f = o - centre;
    float a = dot(d, d);
    float b = -dot(f, d);
    vec3 l = f + (b / a) * d;
    float disc = a * (radius * radius - dot(l, l));
    if (disc < 0.0) return INF;
    float sq = sqrt(disc);
    float q = b + (b >= 0.0 ? sq : -sq);
    float c = dot(f, f) - radius * radius;
    float t0 = c / q;
    float t1 = q / a;
    float tn = min(t0, t1);
    float tf = max(t0, t1);
    if (tn > t_min && tn < t_max) return tn;
    if (tf > t_min && tf < t_max) return tf;
    return INF;
}

#endif
