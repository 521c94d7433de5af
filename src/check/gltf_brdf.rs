//! glTF 2.0's metallic-roughness BRDF on the CPU, in f64, written from the specification's
//! Appendix B independently of glsl/gltf_brdf.glsl (Smith's G2 through Λ rather than the
//! folded visibility term, D through tan θ_h), so that the GPU's values can be checked
//! against it; and directional albedo by quadrature, the white furnace's expected value.

use glam::DVec3;

/// What the BRDF reads of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfBrdf {
    pub base_color: DVec3,
    pub metallic: f64,
    pub roughness: f64,
}

/// glsl/gltf_brdf.glsl's floor on the GGX width α = roughness².
pub const GGX_MIN_ALPHA: f64 = 1e-3;

impl GltfBrdf {
    pub fn alpha(&self) -> f64 {
        (self.roughness * self.roughness).max(GGX_MIN_ALPHA)
    }

    /// GGX D(h) for the half vector's angle θ_h to the normal (cos_h > 0).
    fn distribution(&self, cos_h: f64) -> f64 {
        let a2 = self.alpha().powi(2);
        let cos2 = cos_h * cos_h;
        let tan2 = (1.0 - cos2) / cos2;
        1.0 / (std::f64::consts::PI * a2 * cos2 * cos2 * (1.0 + tan2 / a2).powi(2))
    }

    /// Smith's Λ for a direction at cos θ to the normal (Heitz 2014, eq. 72).
    fn lambda(&self, cos: f64) -> f64 {
        let tan2 = (1.0 - cos * cos) / (cos * cos);
        0.5 * (-1.0 + (1.0 + self.alpha().powi(2) * tan2).sqrt())
    }

    /// f(wo, wi) in the frame where the normal is +z; zero unless both are above it.
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return DVec3::ZERO;
        }
        let h = (wo + wi).normalize();
        let f0 = DVec3::splat(0.04).lerp(self.base_color, self.metallic);
        let fresnel = f0 + (DVec3::ONE - f0) * (1.0 - wo.dot(h).clamp(0.0, 1.0)).powi(5);
        // Height-correlated masking-shadowing (Heitz 2014, eq. 99).
        let g2 = 1.0 / (1.0 + self.lambda(wo.z) + self.lambda(wi.z));
        let specular = self.distribution(h.z) * g2 / (4.0 * wo.z * wi.z);
        let diffuse = self.base_color * (1.0 - self.metallic) / std::f64::consts::PI;
        (DVec3::ONE - fresnel) * diffuse + fresnel * specular
    }

    /// Directional albedo ∫ f cos θ_i dω_i for a viewer at `cos_o` to the normal, by the
    /// midpoint rule on a `rows × 2·rows` grid over (cos θ_i, φ_i).
    pub fn albedo(&self, cos_o: f64, rows: usize) -> DVec3 {
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        let wo = DVec3::new(sin_o, 0.0, cos_o);
        let cols = 2 * rows;
        let cell = (1.0 / rows as f64) * (2.0 * std::f64::consts::PI / cols as f64);
        let mut sum = DVec3::ZERO;
        for r in 0..rows {
            let cos_i = (r as f64 + 0.5) / rows as f64;
            let sin_i = (1.0 - cos_i * cos_i).sqrt();
            for c in 0..cols {
                let phi = (c as f64 + 0.5) / cols as f64 * 2.0 * std::f64::consts::PI;
                let wi = DVec3::new(sin_i * phi.cos(), sin_i * phi.sin(), cos_i);
                sum += self.eval(wo, wi) * cos_i;
            }
        }
        sum * cell
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brdf(base: f64, metallic: f64, roughness: f64) -> GltfBrdf {
        GltfBrdf {
            base_color: DVec3::splat(base),
            metallic,
            roughness,
        }
    }

    #[test]
    fn a_white_metal_at_alpha_1_seen_head_on_reflects_1_minus_ln_2() {
        // With α = 1, D = 1/π and Λ(μ) = (1/μ − 1)/2, so seen along the normal
        // E = ∫ f μ dω = 2π ∫₀¹ μ / (2π (1 + μ)) dμ = 1 − ln 2: the half of the microfacets
        // that reflect below the horizon, and shadowing, take the rest.
        let e = brdf(1.0, 1.0, 1.0).albedo(1.0, 400).x;
        assert!((e - (1.0 - 2f64.ln())).abs() < 1e-4, "{e}");
        // A smooth metal loses almost nothing.
        let smooth = brdf(1.0, 1.0, 0.3).albedo(1.0, 1600).x;
        assert!(smooth > 0.98 && smooth <= 1.0, "{smooth}");
    }

    #[test]
    fn a_black_dielectric_reflects_fresnel_only() {
        // At normal incidence a smooth dielectric reflects about F0 = 0.04.
        let e = brdf(0.0, 0.0, 0.3).albedo(1.0, 400).x;
        assert!((0.035..0.045).contains(&e), "{e}");
    }

    #[test]
    fn the_brdf_is_reciprocal() {
        let m = brdf(0.7, 0.4, 0.5);
        let a = DVec3::new(0.3, -0.2, 0.9).normalize();
        let b = DVec3::new(-0.6, 0.1, 0.4).normalize();
        assert!(m.eval(a, b).abs_diff_eq(m.eval(b, a), 1e-12));
    }
}
