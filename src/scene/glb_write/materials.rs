//! Materials as glTF materials: the factors, alpha and faces, emission (with
//! KHR_materials_emissive_strength past 1), and the texture slots (with KHR_texture_transform
//! where a slot's transform is not the identity).

use serde_json::{json, Value};

use super::super::gltf_from_thesis::metallic_roughness_from_thesis;
use super::super::{AlphaMode, Material, TextureRef};

/// A glTF material object, and the extensions it uses.
pub(super) fn material_json(
    index: usize,
    m: &Material,
) -> Result<(Value, Vec<&'static str>), String> {
    let m = match m {
        Material::Thesis(m) => metallic_roughness_from_thesis(m),
        Material::MetallicRoughness(m) => *m,
    };
    let (base, metallic, roughness) = (m.base_color, m.metallic, m.roughness);
    let values = [
        base.x,
        base.y,
        base.z,
        metallic,
        roughness,
        m.coverage.alpha,
    ];
    if !m.emission.is_finite()
        || m.emission.min_element() < 0.0
        || values.iter().any(|v| !v.is_finite() || *v < 0.0)
    {
        return Err("has a negative or non-finite value".into());
    }
    let coverage = m.coverage;
    let mut value = json!({
        "name": format!("material {index}"),
        "pbrMetallicRoughness": {
            "baseColorFactor": [base.x, base.y, base.z, coverage.alpha],
            "metallicFactor": metallic,
            "roughnessFactor": roughness,
        },
        "doubleSided": coverage.double_sided,
    });
    let object = value
        .as_object_mut()
        .ok_or("internal: material is not an object")?;
    match coverage.mode {
        AlphaMode::Opaque => {}
        AlphaMode::Mask { cutoff } => {
            object.insert("alphaMode".into(), json!("MASK"));
            object.insert("alphaCutoff".into(), json!(cutoff));
        }
        AlphaMode::Blend => {
            object.insert("alphaMode".into(), json!("BLEND"));
        }
    }
    let mut extensions = Vec::new();
    let t = &m.textures;
    let slots = [
        ("baseColorTexture", t.base_color, true),
        ("metallicRoughnessTexture", t.metallic_roughness, true),
        ("emissiveTexture", t.emissive, false),
        ("normalTexture", t.normal, false),
    ];
    for (name, slot, in_pbr) in slots {
        let Some(r) = slot else { continue };
        let mut info = texture_info(&r)?;
        if info.get("extensions").is_some() {
            extensions.push(TEXTURE_TRANSFORM);
        }
        if name == "normalTexture" {
            info["scale"] = json!(t.normal_scale);
        }
        match in_pbr {
            true => object["pbrMetallicRoughness"][name] = info,
            false => {
                object.insert(name.into(), info);
            }
        }
    }
    let peak = m.emission.max_element();
    if peak > 1.0 {
        let unit = m.emission / peak;
        object.insert("emissiveFactor".into(), json!(unit.to_array().to_vec()));
        object.insert(
            "extensions".into(),
            json!({ "KHR_materials_emissive_strength": { "emissiveStrength": peak } }),
        );
        extensions.push("KHR_materials_emissive_strength");
    } else if peak > 0.0 {
        let emission = m.emission.to_array().to_vec();
        object.insert("emissiveFactor".into(), json!(emission));
    }
    Ok((value, extensions))
}

const TEXTURE_TRANSFORM: &str = "KHR_texture_transform";

/// A textureInfo: the texture (the scene's texture index is the glTF texture's), its
/// TEXCOORD set, and KHR_texture_transform unless the transform is the identity.
fn texture_info(r: &TextureRef) -> Result<Value, String> {
    let mut info = json!({ "index": r.texture, "texCoord": r.texcoord });
    if r.transform != TextureRef::IDENTITY {
        let (offset, rotation, scale) = transform_parts(r.transform)?;
        info["extensions"] = json!({ TEXTURE_TRANSFORM: {
            "offset": offset, "rotation": rotation, "scale": scale,
        }});
    }
    Ok(info)
}

/// KHR_texture_transform's offset, rotation and scale of a transform made of them (the
/// loader's `uv_transform` inverted); a transform with shear has none.
fn transform_parts(m: [[f32; 3]; 2]) -> Result<([f32; 2], f32, [f32; 2]), String> {
    let scale_u = m[0][0].hypot(m[1][0]);
    let rotation = (-m[1][0]).atan2(m[0][0]);
    let (sin, cos) = rotation.sin_cos();
    let scale_v = m[0][1] * sin + m[1][1] * cos;
    let offset = [m[0][2], m[1][2]];
    let rebuilt = [
        [cos * scale_u, sin * scale_v, offset[0]],
        [-sin * scale_u, cos * scale_v, offset[1]],
    ];
    let close = (rebuilt.iter().flatten().zip(m.iter().flatten()))
        .all(|(a, b)| (a - b).abs() <= 1e-5 * (1.0 + b.abs()));
    match close && scale_u.is_finite() && scale_v.is_finite() {
        true => Ok((offset, rotation, [scale_u, scale_v])),
        false => Err(format!(
            "its texture transform {m:?} is not offset · rotation · scale (KHR_texture_transform)"
        )),
    }
}
