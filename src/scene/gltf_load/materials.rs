//! glTF materials as glTF's own metallic-roughness model ([`MetallicRoughness`]): the factors,
//! checked; the shaders evaluate the specification's BRDF (glsl/gltf_brdf.glsl).

use glam::Vec3;

use super::origin::Warnings;
use crate::scene::{Material, MetallicRoughness};

/// The material of primitives that have none: glTF's default material (white, metallic 1,
/// roughness 1: every property at the specification's default).
pub fn default_material() -> Material {
    Material::MetallicRoughness(MetallicRoughness::GLTF_DEFAULT)
}

/// A glTF material's factors as a [`MetallicRoughness`]; a negative, non-finite or
/// overflowing factor is an error naming the material.
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
    // The schema bounds the factors by 1; exporters round past it by an ulp or so.
    let unit = |x: f32| x.min(1.0);
    Ok(Material::MetallicRoughness(MetallicRoughness {
        base_color: Vec3::new(unit(r), unit(g), unit(b)),
        metallic: unit(metallic),
        roughness: unit(roughness),
        emission,
    }))
}
