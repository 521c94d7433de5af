//! glTF materials as glTF's own metallic-roughness model ([`MetallicRoughness`]): the factors,
//! checked, and the textures that multiply them; the shaders evaluate the specification's
//! BRDF (glsl/gltf_brdf.glsl).

use glam::Vec3;

use super::origin::{Origin, Warnings};
use super::textures::TextureLoader;
use crate::scene::{
    AlphaMode, Coverage, Material, MaterialTextures, MetallicRoughness, SceneError, TexelEncoding,
    TextureRef,
};

/// The material of primitives that have none: glTF's default material (white, metallic 1,
/// roughness 1: every property at the specification's default).
pub fn default_material() -> Material {
    Material::MetallicRoughness(MetallicRoughness::GLTF_DEFAULT)
}

/// A glTF material as a [`MetallicRoughness`], its textures loaded through `textures`.
pub(super) fn convert_material(
    material: &gltf::Material,
    textures: &mut TextureLoader,
    origin: &Origin,
    warnings: &mut Warnings,
) -> Result<Material, SceneError> {
    let factors = convert_factors(material).map_err(|p| origin.invalid(p))?;
    let pbr = material.pbr_metallic_roughness();
    let mut slot =
        |info: Option<gltf::texture::Info>, encoding| -> Result<Option<TextureRef>, SceneError> {
            info.map(|i| textures.reference(&i, encoding, origin))
                .transpose()
        };
    let base_color = slot(pbr.base_color_texture(), TexelEncoding::Srgb)?;
    let metallic_roughness = slot(pbr.metallic_roughness_texture(), TexelEncoding::Linear)?;
    let emissive = slot(material.emissive_texture(), TexelEncoding::Srgb)?;
    let normal_texture = material.normal_texture();
    let normal_scale = normal_texture.as_ref().map_or(1.0, |n| n.scale());
    if !normal_scale.is_finite() {
        return Err(origin.invalid(format!(
            "a material's normalTexture.scale is {normal_scale}; it must be a finite number"
        )));
    }
    let textures = MaterialTextures {
        base_color,
        metallic_roughness,
        emissive,
        normal: (normal_texture.as_ref())
            .map(|n| textures.normal_reference(n, origin))
            .transpose()?,
        normal_scale,
    };
    // A path tracer computes occlusion by tracing: glTF's baked ambient occlusion would count
    // it twice (the specification leaves its use to the renderer).
    if material.occlusion_texture().is_some() {
        warnings.add("occlusion textures (a path tracer traces occlusion itself)");
    }
    Ok(Material::MetallicRoughness(MetallicRoughness {
        textures,
        ..factors
    }))
}

/// A glTF material's factors and coverage; a negative, non-finite or overflowing factor is an error naming
/// the material.
fn convert_factors(material: &gltf::Material) -> Result<MetallicRoughness, String> {
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
    Ok(MetallicRoughness {
        coverage: coverage(material, unit(a), &label)?,
        ..MetallicRoughness::factors(
            Vec3::new(unit(r), unit(g), unit(b)),
            unit(metallic),
            unit(roughness),
            emission,
        )
    })
}

/// glTF's alphaMode, alphaCutoff (0.5 unless given) and doubleSided.
fn coverage(material: &gltf::Material, alpha: f32, label: &str) -> Result<Coverage, String> {
    use gltf::material::AlphaMode as Mode;
    let mode = match material.alpha_mode() {
        Mode::Opaque => AlphaMode::Opaque,
        Mode::Blend => AlphaMode::Blend,
        Mode::Mask => {
            let cutoff = material.alpha_cutoff().unwrap_or(0.5);
            if !(cutoff.is_finite() && cutoff >= 0.0) {
                return Err(format!(
                    "{label} has alphaCutoff {cutoff}; it must be a number ≥ 0 (0.5 if absent)"
                ));
            }
            AlphaMode::Mask { cutoff }
        }
    };
    Ok(Coverage {
        alpha,
        mode,
        double_sided: material.double_sided(),
    })
}
