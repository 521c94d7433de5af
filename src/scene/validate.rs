//! What a scene must satisfy before it is built for the GPU, whoever made it (built-in, glTF or
//! code): finite geometry, indices in range, and materials that cannot create energy or
//! overflow 32-bit floats. The glTF loader already produces such scenes; this catches scenes
//! built in code and says what to change.

use super::{
    AlphaMode, Material, MetallicRoughness, Scene, SceneError, Texture, TextureRef, ThesisMaterial,
};
use glam::Vec3;

/// Largest finite Phong exponent accepted; sharper lobes are mirrors in practice (α = ∞).
pub const MAX_PHONG_ALPHA: f32 = 1e6;

/// Largest emitted radiance accepted. A path multiplies emission by a throughput of at most a
/// few and divides by light-sampling densities that can reach ~1e6 for small, distant lights:
/// 1e30 keeps every product well below f32's 3.4e38, so a sample never overflows to ∞.
pub const MAX_EMISSION: f32 = 1e30;

/// Checks `scene`; the error names the offending element and what to do.
pub fn validate(scene: &Scene) -> Result<(), SceneError> {
    let invalid = |problem: String| SceneError::Invalid {
        scene: scene.name.clone(),
        problem,
    };
    for (i, t) in scene.textures.iter().enumerate() {
        check_texture(t).map_err(|p| invalid(format!("texture {i} ('{}'): {p}", t.name)))?;
    }
    for (i, m) in scene.materials.iter().enumerate() {
        check_material(m).map_err(|p| invalid(format!("material {i}: {p}")))?;
        if let Material::MetallicRoughness(m) = m {
            for r in m.textures.iter() {
                check_texture_ref(r, scene.textures.len())
                    .map_err(|p| invalid(format!("material {i}: {p}")))?;
            }
        }
    }
    for (i, mesh) in scene.meshes.iter().enumerate() {
        if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return Err(invalid(format!(
                "mesh {i} ('{}') vertex {v} is {} (not finite): every coordinate must be a number",
                mesh.name, mesh.positions[v]
            )));
        }
        let n = mesh.positions.len();
        if let Some((t, tri)) = mesh
            .indices
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&k| k as usize >= n))
        {
            return Err(invalid(format!(
                "mesh {i} ('{}') triangle {t} uses vertex indices {tri:?} but the mesh has {n} vertices",
                mesh.name
            )));
        }
    }
    for (i, inst) in scene.instances.iter().enumerate() {
        if !inst.transform.is_finite() {
            return Err(invalid(format!(
                "instance {i} has a non-finite transform (NaN or ±∞)"
            )));
        }
    }
    let c = &scene.camera;
    let angles = [c.angle_left, c.angle_right, c.angle_up, c.angle_down];
    if !(c.position.is_finite() && c.forward.is_finite() && c.up.is_finite())
        || c.forward.length_squared() == 0.0
        || c.forward.cross(c.up).length_squared() == 0.0
        || angles.iter().any(|a| !a.is_finite())
    {
        return Err(invalid(format!(
            "the camera is not usable (position {}, forward {}, up {}): it needs finite values, \
             a non-zero forward and an up that is not parallel to it",
            c.position, c.forward, c.up
        )));
    }
    check_lights(scene).map_err(invalid)?;
    let e = &scene.environment;
    for (what, v) in [
        ("zenith", e.zenith),
        ("horizon", e.horizon),
        ("ground", e.ground),
    ] {
        if !(v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= MAX_EMISSION) {
            return Err(invalid(format!(
                "the sky's {what} radiance {v} must be finite, ≥ 0 and ≤ {MAX_EMISSION:e}"
            )));
        }
    }
    Ok(())
}

/// Each punctual light as the extension allows it, and no brighter than floats can carry.
fn check_lights(scene: &Scene) -> Result<(), String> {
    for (i, light) in scene.lights.iter().enumerate() {
        if let Some(problem) = light.problem() {
            return Err(format!("light {i}: {problem}"));
        }
        if light.intensity.max_element() > MAX_EMISSION {
            return Err(format!(
                "light {i}: intensity {} is above {MAX_EMISSION:e} (it would overflow 32-bit \
                 floats); scale the lights and the exposure down together",
                light.intensity
            ));
        }
    }
    Ok(())
}

/// The material rules, for either model; emission is checked the same way for both.
fn check_material(m: &Material) -> Result<(), String> {
    match m {
        Material::Thesis(m) => check_thesis(m)?,
        Material::MetallicRoughness(m) => check_metallic_roughness(m)?,
    }
    let emission = m.emission();
    if !(emission.is_finite()
        && emission.min_element() >= 0.0
        && emission.max_element() <= MAX_EMISSION)
    {
        return Err(format!(
            "emission {emission} must be finite, ≥ 0 and ≤ {MAX_EMISSION:e} (radiance beyond that \
             overflows 32-bit floats); scale the emission and the exposure down together"
        ));
    }
    Ok(())
}

/// k_d + k_s > 1 is rejected rather than clamped: the Lambert and Phong lobes would then
/// reflect more than they receive (a white furnace would glow), and a silent clamp would
/// render a different material from the one asked for.
fn check_thesis(m: &ThesisMaterial) -> Result<(), String> {
    for (what, v) in [("k_d", m.kd), ("k_s", m.ks)] {
        check_unit(what, v)?;
    }
    let sum = m.kd + m.ks;
    if sum.max_element() > 1.0 {
        return Err(format!(
            "k_d + k_s = {sum} exceeds 1, so the surface would reflect more light than it \
             receives; scale k_d and k_s down so that their sum is at most 1 in every channel"
        ));
    }
    if !(m.alpha == f32::INFINITY || (0.0..=MAX_PHONG_ALPHA).contains(&m.alpha)) {
        return Err(format!(
            "Phong exponent α = {} must be between 0 and {MAX_PHONG_ALPHA:e}, or ∞ for a \
             perfect mirror",
            m.alpha
        ));
    }
    Ok(())
}

/// glTF's factors are in [0, 1] (its schema says so); outside it the BRDF creates energy.
fn check_metallic_roughness(m: &MetallicRoughness) -> Result<(), String> {
    check_unit("base colour", m.base_color)?;
    check_unit("metallic", Vec3::splat(m.metallic))?;
    check_unit("roughness", Vec3::splat(m.roughness))?;
    check_unit("alpha", Vec3::splat(m.coverage.alpha))?;
    match m.coverage.mode {
        AlphaMode::Mask { cutoff } if !(cutoff.is_finite() && cutoff >= 0.0) => Err(format!(
            "its alpha cutoff {cutoff} must be a number ≥ 0 (glTF's default is 0.5)"
        )),
        _ => Ok(()),
    }
}

/// A texture has texels, as many as its size says.
fn check_texture(t: &Texture) -> Result<(), String> {
    let texels = t.width as u64 * t.height as u64;
    if texels == 0 || t.rgba8.len() as u64 != 4 * texels {
        return Err(format!(
            "{}×{} texels need {} bytes of RGBA, it has {}",
            t.width,
            t.height,
            4 * texels,
            t.rgba8.len()
        ));
    }
    Ok(())
}

/// A material's texture exists, is read with TEXCOORD_0 or _1, and moves by finite numbers.
fn check_texture_ref(r: &TextureRef, textures: usize) -> Result<(), String> {
    if r.texture as usize >= textures {
        return Err(format!(
            "it uses texture {} but the scene has {textures}",
            r.texture
        ));
    }
    if r.texcoord > 1 {
        return Err(format!("TEXCOORD_{} does not exist (0 or 1)", r.texcoord));
    }
    if !r.transform.iter().flatten().all(|x| x.is_finite()) {
        return Err(format!(
            "its texture transform {:?} is not finite",
            r.transform
        ));
    }
    Ok(())
}

fn check_unit(what: &str, v: Vec3) -> Result<(), String> {
    if v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0 {
        Ok(())
    } else {
        Err(format!(
            "{what} = {v} must be between 0 and 1 in every channel"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin::{builtin, BUILTIN_SCENES};
    use crate::scene::Coverage;
    use glam::Vec3;

    fn problem(m: Material) -> String {
        check_material(&m).unwrap_err()
    }

    #[test]
    fn every_builtin_scene_is_valid() {
        for (name, _) in BUILTIN_SCENES {
            validate(&builtin(name, 1.0).unwrap()).unwrap();
        }
    }

    #[test]
    fn materials_at_the_limits_are_accepted() {
        for alpha in [0.0, 1.0, 1e6, f32::INFINITY] {
            let m = Material::phong(
                Vec3::splat(0.5),
                Vec3::splat(0.5),
                alpha,
                Vec3::splat(MAX_EMISSION),
            );
            check_material(&m).unwrap();
        }
        for (base, metallic, roughness) in [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)] {
            let m = Material::MetallicRoughness(MetallicRoughness {
                base_color: Vec3::splat(base),
                metallic,
                roughness,
                emission: Vec3::splat(MAX_EMISSION),
                textures: Default::default(),
                coverage: Coverage::SOLID,
            });
            check_material(&m).unwrap();
        }
    }

    #[test]
    fn materials_that_create_energy_or_overflow_are_rejected_with_the_reason() {
        let base = ThesisMaterial {
            kd: Vec3::splat(0.5),
            ks: Vec3::ZERO,
            alpha: 1.0,
            emission: Vec3::ZERO,
        };
        let thesis = |m: ThesisMaterial| Material::Thesis(m);
        let cases = [
            (
                thesis(ThesisMaterial {
                    ks: Vec3::new(0.6, 0.1, 0.1),
                    ..base
                }),
                "exceeds 1",
            ),
            (
                Material::diffuse(Vec3::new(1.2, 0.5, 0.5)),
                "between 0 and 1",
            ),
            (
                Material::diffuse(Vec3::new(-0.1, 0.5, 0.5)),
                "between 0 and 1",
            ),
            (Material::diffuse(Vec3::new(f32::NAN, 0.5, 0.5)), "k_d"),
            (
                thesis(ThesisMaterial {
                    alpha: -1.0,
                    ..base
                }),
                "α = -1",
            ),
            (thesis(ThesisMaterial { alpha: 2e6, ..base }), "α = 2000000"),
            (
                thesis(ThesisMaterial {
                    alpha: f32::NAN,
                    ..base
                }),
                "α = NaN",
            ),
            (
                Material::emitter(Vec3::ZERO, Vec3::splat(1e31)),
                "overflows",
            ),
            (
                Material::emitter(Vec3::ZERO, Vec3::new(1.0, f32::INFINITY, 1.0)),
                "emission",
            ),
        ];
        for (m, words) in cases {
            let p = problem(m);
            assert!(p.contains(words), "{m:?}: '{p}' lacks '{words}'");
        }
    }

    #[test]
    fn gltf_factors_outside_0_to_1_are_rejected_with_the_reason() {
        let pbr = MetallicRoughness {
            base_color: Vec3::splat(0.5),
            metallic: 0.5,
            roughness: 0.5,
            emission: Vec3::ZERO,
            textures: Default::default(),
            coverage: Coverage::SOLID,
        };
        let gltf = |m: MetallicRoughness| Material::MetallicRoughness(m);
        let cases = [
            (
                gltf(MetallicRoughness {
                    base_color: Vec3::new(0.5, 1.5, 0.5),
                    ..pbr
                }),
                "base colour",
            ),
            (
                gltf(MetallicRoughness {
                    metallic: -0.1,
                    ..pbr
                }),
                "metallic",
            ),
            (
                gltf(MetallicRoughness {
                    roughness: f32::NAN,
                    ..pbr
                }),
                "roughness",
            ),
            (
                gltf(MetallicRoughness {
                    emission: Vec3::splat(1e31),
                    ..pbr
                }),
                "overflows",
            ),
            (
                gltf(MetallicRoughness {
                    coverage: Coverage {
                        alpha: 1.5,
                        ..Coverage::SOLID
                    },
                    ..pbr
                }),
                "alpha",
            ),
            (
                gltf(MetallicRoughness {
                    coverage: Coverage {
                        mode: AlphaMode::Mask { cutoff: f32::NAN },
                        ..Coverage::SOLID
                    },
                    ..pbr
                }),
                "cutoff",
            ),
        ];
        for (m, words) in cases {
            let p = problem(m);
            assert!(p.contains(words), "{m:?}: '{p}' lacks '{words}'");
        }
    }

    #[test]
    fn broken_geometry_and_cameras_are_named() {
        let mut s = builtin("cornell", 1.0).unwrap();
        s.meshes[0].positions[1].y = f32::NAN;
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("vertex 1") && e.contains("not finite"), "{e}");

        let mut s = builtin("cornell", 1.0).unwrap();
        s.meshes[0].indices[0][2] = 1_000_000;
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("triangle 0") && e.contains("1000000"), "{e}");

        let mut s = builtin("cornell", 1.0).unwrap();
        s.camera.up = s.camera.forward;
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("camera"), "{e}");
    }
}
