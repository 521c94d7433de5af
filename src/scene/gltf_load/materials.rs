//! glTF materials as the thesis' Lambert + Phong BRDF (see [`material_from_metallic_roughness`]).

use glam::Vec3;

use super::origin::Warnings;
use crate::scene::Material;

/// Normal-incidence Fresnel reflectance of dielectrics assumed by glTF's metallic-roughness model.
pub const DIELECTRIC_F0: f32 = 0.04;
/// Largest finite Phong exponent the mapping produces; sharper lobes are mirrors in practice.
pub const MAX_PHONG_ALPHA: f32 = 1e6;
/// Roughness floor of the α mapping (`2/r⁴` overflows the useful range below it).
const MIN_ROUGHNESS: f32 = 1e-3;

/// The material given to primitives that have none: diffuse grey 0.8.
pub fn default_material() -> Material {
    Material::diffuse(Vec3::splat(0.8))
}

/// Phong exponent for a glTF (perceptual) roughness: `α = 2/r⁴ − 2` with `r = max(roughness,
/// 10⁻³)`, clamped to `[0, 10⁶]`. GGX uses `α_g = r²` and Walter et al. (2007) relate Beckmann
/// (≈ GGX) and Blinn-Phong lobes by `α_p = 2/α_g² − 2`.
pub fn phong_alpha_from_roughness(roughness: f32) -> f32 {
    let r = roughness.clamp(MIN_ROUGHNESS, 1.0);
    (2.0 / r.powi(4) - 2.0).clamp(0.0, MAX_PHONG_ALPHA)
}

/// The inverse of [`phong_alpha_from_roughness`] (`∞` → 0); exact up to rounding for
/// α ≤ [`MAX_PHONG_ALPHA`].
pub fn roughness_from_phong_alpha(alpha: f32) -> f32 {
    if alpha == f32::INFINITY {
        return 0.0;
    }
    (2.0 / (alpha.max(0.0) + 2.0)).powf(0.25).clamp(0.0, 1.0)
}

/// The loader's material mapping from glTF metallic-roughness factors to the thesis' BRDF:
/// `k_s = mix(0.04, base, metallic)`, `k_d = base·(1−metallic)·(1−0.04)`,
/// `α =` [`phong_alpha_from_roughness`]`(roughness)`, except roughness 0 with metallic 1, which
/// is a perfect mirror (`α = ∞`). Inputs are clamped to `[0, 1]` (NaN counts as 0);
/// `k_d + k_s ≤ 1` holds per channel. `emission` is passed through.
pub fn material_from_metallic_roughness(
    base_color: Vec3,
    metallic: f32,
    roughness: f32,
    emission: Vec3,
) -> Material {
    let unit = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let base = Vec3::new(unit(base_color.x), unit(base_color.y), unit(base_color.z));
    let metallic = unit(metallic);
    let roughness = unit(roughness);
    let ks = Vec3::splat(DIELECTRIC_F0).lerp(base, metallic);
    let kd = base * (1.0 - metallic) * (1.0 - DIELECTRIC_F0);
    // Holds analytically for base ≤ 1; guard the rounding so the BRDF never creates energy.
    let kd = kd.min((Vec3::ONE - ks).max(Vec3::ZERO));
    let alpha = if roughness == 0.0 && metallic == 1.0 {
        f32::INFINITY
    } else {
        phong_alpha_from_roughness(roughness)
    };
    Material {
        kd,
        ks,
        alpha,
        emission,
    }
}

/// Converts a glTF material's factors with [`material_from_metallic_roughness`].
pub(super) fn convert_material(
    material: &gltf::Material,
    warnings: &mut Warnings,
) -> Result<Material, String> {
    let label = match (material.name(), material.index()) {
        (Some(name), Some(i)) => format!("material '{name}' (#{i})"),
        (_, i) => format!("material #{}", i.unwrap_or(0)),
    };
    let pbr = material.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let metallic = pbr.metallic_factor();
    let roughness = pbr.roughness_factor();
    let strength = material.emissive_strength().unwrap_or(1.0);
    let emissive = Vec3::from(material.emissive_factor());
    let values = [r, g, b, a, metallic, roughness, strength];
    if !values
        .iter()
        .chain(emissive.as_ref())
        .all(|x| x.is_finite() && *x >= 0.0)
    {
        return Err(format!(
            "{label} has a negative or non-finite factor (NaN or ±∞); fix the material"
        ));
    }
    if a < 1.0 && material.alpha_mode() != gltf::material::AlphaMode::Opaque {
        warnings.add("transparency (alpha; materials are opaque)");
    }
    let emission = emissive * strength;
    if !emission.is_finite() {
        return Err(format!(
            "{label}: its emission (emissiveFactor up to {:e} × emissiveStrength {strength:e}) \
             overflows to infinity; use a finite light intensity",
            emissive.max_element()
        ));
    }
    Ok(material_from_metallic_roughness(
        Vec3::new(r, g, b),
        metallic,
        roughness,
        emission,
    ))
}
