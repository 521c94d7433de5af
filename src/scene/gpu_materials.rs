//! Materials as the shaders read them (shared.h's GpuMaterial): either model's fields, and a
//! glTF material's texture slots.

use super::{AlphaMode, Material, TextureRef};
use crate::shader_layout::*;
use glam::Vec3;

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// Phong selection probability p_S = a_s / (a_s + a_d) (thesis eqs. 3.9–3.11).
fn specular_probability(kd: Vec3, ks: Vec3) -> f32 {
    let a_s = ks.element_sum() / 3.0;
    let a_d = kd.element_sum() / 3.0;
    if a_s + a_d > 0.0 {
        a_s / (a_s + a_d)
    } else {
        0.0
    }
}

/// A material as the shaders read it (shared.h's GpuMaterial): the fields of its model, the
/// others zero.
pub(super) fn gpu_material(m: &Material) -> GpuMaterial {
    match m {
        Material::Thesis(m) => GpuMaterial {
            kd: v4(m.kd, m.alpha),
            ks: v4(m.ks, specular_probability(m.kd, m.ks)),
            emission: v4(m.emission, 0.0),
            model: MODEL_THESIS,
            ..Default::default()
        },
        Material::MetallicRoughness(m) => GpuMaterial {
            emission: v4(m.emission, 0.0),
            base_color: v4(m.base_color, m.coverage.alpha),
            metallic: m.metallic,
            roughness: m.roughness,
            model: MODEL_METALLIC_ROUGHNESS,
            base_color_texture: texture_slot(m.textures.base_color),
            metallic_roughness_texture: texture_slot(m.textures.metallic_roughness),
            emissive_texture: texture_slot(m.textures.emissive),
            normal_texture: texture_slot(m.textures.normal),
            normal_scale: m.textures.normal_scale,
            ..Default::default()
        },
    }
}

/// A mesh instance's GpuObject.surface flags and alpha cutoff, from its material's coverage
/// (thesis materials are opaque from both sides: no flags).
pub(super) fn surface_flags(m: &Material) -> (u32, f32) {
    let Material::MetallicRoughness(m) = m else {
        return (0, 0.0);
    };
    let sides = if m.coverage.double_sided {
        0
    } else {
        OBJECT_SINGLE_SIDED
    };
    match m.coverage.mode {
        AlphaMode::Opaque => (sides, 0.0),
        AlphaMode::Mask { cutoff } => (sides | OBJECT_ALPHA_MASK, cutoff),
        AlphaMode::Blend => (sides | OBJECT_ALPHA_BLEND, 0.0),
    }
}

fn texture_slot(r: Option<TextureRef>) -> GpuTextureSlot {
    let Some(r) = r else {
        return GpuTextureSlot::default();
    };
    let [u, v] = r.transform;
    GpuTextureSlot {
        u_row: [u[0], u[1], u[2], 0.0],
        v_row: [v[0], v[1], v[2], 0.0],
        texture: r.texture,
        texcoord: r.texcoord,
        ..Default::default()
    }
}
