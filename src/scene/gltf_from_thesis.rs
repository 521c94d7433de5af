//! The nearest glTF metallic-roughness material to a thesis material, for writing built-in
//! scenes as `.glb` files (`glb_write`).
//!
//! The mapping inverts `k_s = 0.04(1−m) + m·base`, `k_d = 0.96(1−m)·base`, Phong
//! `α = 2/r⁴ − 2` (Walter et al. 2007 relate Beckmann ≈ GGX and Blinn-Phong lobes by
//! `α_p = 2/α_g² − 2`, with GGX `α_g = r²`). `m` is solved from the channel means: with
//! `U = mean(k_d)/0.96` and `K = mean(k_s)`, `K = 0.04(1−m) + U·m/(1−m)` has exactly one root
//! in `(0, 1)` when `K > 0.04` (the right side is convex and 0.04 at `m = 0`), found by
//! bisection; then `base = k_d / (0.96(1−m))`. `K ≤ 0.04` gives a dielectric (`m = 0`),
//! `k_d = 0` a metal (`m = 1`, `base = k_s`); a mirror (`α = ∞`) gets roughness 0.
//!
//! The two models differ (Phong is not GGX, and glTF's dielectric has a Fresnel-weighted
//! specular layer that the thesis' Lambert has not), so a written built-in scene renders close
//! to, not exactly like, the original.

use glam::Vec3;

use super::{Coverage, MetallicRoughness, ThesisMaterial};

/// Normal-incidence Fresnel reflectance of glTF's dielectrics.
pub const DIELECTRIC_F0: f32 = 0.04;

/// Roughness for a Phong exponent: the inverse of `α = 2/r⁴ − 2` (`∞` → 0).
pub fn roughness_from_phong_alpha(alpha: f32) -> f32 {
    if alpha == f32::INFINITY {
        return 0.0;
    }
    (2.0 / (alpha.max(0.0) + 2.0)).powf(0.25).clamp(0.0, 1.0)
}

/// The metallic-roughness material nearest to `m` (see the module docs).
pub fn metallic_roughness_from_thesis(m: &ThesisMaterial) -> MetallicRoughness {
    let one_minus_f0 = 1.0 - DIELECTRIC_F0;
    let u = m.kd.element_sum() / 3.0 / one_minus_f0;
    let k = m.ks.element_sum() / 3.0;
    let metallic = if k <= DIELECTRIC_F0 + 1e-6 {
        0.0
    } else if u <= 1e-7 {
        1.0
    } else {
        metalness_root(u, k)
    };
    let base = if metallic >= 1.0 {
        m.ks
    } else {
        m.kd / (one_minus_f0 * (1.0 - metallic))
    }
    .clamp(Vec3::ZERO, Vec3::ONE);
    MetallicRoughness {
        base_color: base,
        metallic,
        roughness: roughness_from_phong_alpha(m.alpha),
        emission: m.emission,
        textures: Default::default(),
        // The thesis' surfaces are there from both sides.
        coverage: Coverage::SOLID,
    }
}

/// The root in (0, 1) of f(m) = F0(1−m) + U·m/(1−m) − K, by bisection: f is convex with
/// f(0) < 0 and f → ∞ as m → 1.
fn metalness_root(u: f32, k: f32) -> f32 {
    let f = |m: f64| DIELECTRIC_F0 as f64 * (1.0 - m) + u as f64 * m / (1.0 - m) - k as f64;
    let (mut lo, mut hi) = (0.0f64, 1.0 - 1e-9);
    if f(hi) <= 0.0 {
        lo = hi;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (0.5 * (lo + hi)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The forward mapping the inverse undoes (what the loader did before glTF materials
    /// became glTF's own BRDF).
    fn thesis_from(base: Vec3, metallic: f32, roughness: f32) -> ThesisMaterial {
        let r = roughness.max(1e-3);
        ThesisMaterial {
            kd: base * (1.0 - metallic) * (1.0 - DIELECTRIC_F0),
            ks: Vec3::splat(DIELECTRIC_F0).lerp(base, metallic),
            alpha: if roughness == 0.0 && metallic == 1.0 {
                f32::INFINITY
            } else {
                2.0 / r.powi(4) - 2.0
            },
            emission: Vec3::ZERO,
        }
    }

    #[test]
    fn the_mapping_inverts_the_forward_one() {
        for (base, metallic, roughness) in [
            (Vec3::new(0.8, 0.3, 0.2), 0.0, 0.5),
            (Vec3::new(0.9, 0.8, 0.5), 1.0, 0.0),
            (Vec3::splat(0.5), 0.3, 1.0),
            (Vec3::new(0.2, 0.6, 0.9), 0.7, 0.25),
        ] {
            let back = metallic_roughness_from_thesis(&thesis_from(base, metallic, roughness));
            assert!((back.metallic - metallic).abs() < 1e-4, "{back:?}");
            assert!((back.roughness - roughness).abs() < 1e-4, "{back:?}");
            assert!(back.base_color.abs_diff_eq(base, 1e-4), "{back:?}");
        }
    }

    #[test]
    fn a_lambertian_is_a_dielectric_and_a_mirror_is_smooth() {
        let lambert = metallic_roughness_from_thesis(&ThesisMaterial {
            kd: Vec3::splat(0.6),
            ks: Vec3::ZERO,
            alpha: 1.0,
            emission: Vec3::ONE,
        });
        assert_eq!(lambert.metallic, 0.0);
        assert_eq!(lambert.emission, Vec3::ONE);
        let mirror = metallic_roughness_from_thesis(&ThesisMaterial {
            kd: Vec3::ZERO,
            ks: Vec3::splat(0.9),
            alpha: f32::INFINITY,
            emission: Vec3::ZERO,
        });
        assert_eq!((mirror.metallic, mirror.roughness), (1.0, 0.0));
        assert_eq!(mirror.base_color, Vec3::splat(0.9));
    }
}
