//! What must hold for every input of the glTF loader, shared by the fuzz target
//! (`fuzz/fuzz_targets/gltf_load.rs`) and the corpus regression test
//! (`tests/gltf_fuzz_corpus.rs`): an accepted scene has finite geometry, in-range indices,
//! finite materials and transforms, and survives the GPU layout; a refusal names the input.

use fovea::scene::gpu_layout::GpuScene;
use fovea::scene::{Material, Mesh, Scene, SceneError};

/// The properties of a scene the loader accepted; `Err` says which one failed.
pub fn check_scene(scene: &Scene) -> Result<(), String> {
    for (m, mesh) in scene.meshes.iter().enumerate() {
        check_mesh(mesh).map_err(|e| format!("mesh {m}: {e}"))?;
    }
    for (i, instance) in scene.instances.iter().enumerate() {
        if instance.mesh as usize >= scene.meshes.len() {
            return Err(format!(
                "instance {i} refers to missing mesh {}",
                instance.mesh
            ));
        }
        if instance.material as usize >= scene.materials.len() {
            return Err(format!(
                "instance {i} refers to missing material {}",
                instance.material
            ));
        }
        if !instance.transform.is_finite() {
            return Err(format!("instance {i} has a non-finite transform"));
        }
    }
    for (k, m) in scene.materials.iter().enumerate() {
        // α = ∞ is a perfect mirror; everything else must be a finite, non-negative number.
        let (colours, alpha_ok) = match m {
            Material::Thesis(t) => (
                vec![t.kd, t.ks, t.emission],
                !t.alpha.is_nan() && t.alpha >= 0.0,
            ),
            Material::MetallicRoughness(g) => (
                vec![g.base_color, g.emission],
                [g.metallic, g.roughness]
                    .iter()
                    .all(|x| (0.0..=1.0).contains(x)),
            ),
        };
        let colours_ok = colours
            .iter()
            .all(|c| c.is_finite() && c.min_element() >= 0.0);
        if !colours_ok || !alpha_ok {
            return Err(format!("material {k} is not finite: {m:?}"));
        }
    }
    let c = &scene.camera;
    let angles = [c.angle_left, c.angle_right, c.angle_up, c.angle_down];
    if !(c.position.is_finite()
        && c.forward.is_finite()
        && c.up.is_finite()
        && angles.iter().all(|a| a.is_finite()))
    {
        return Err(format!("the camera is not finite: {c:?}"));
    }
    Ok(())
}

/// Builds the GPU layout (BVHs and buffers) of an accepted scene: it may refuse the scene, but
/// must not panic.
pub fn build_gpu_layout(scene: &Scene) {
    let _ = GpuScene::build(scene);
}

/// A mesh's positions are finite and its indices in range.
pub fn check_mesh(mesh: &Mesh) -> Result<(), String> {
    if let Some(p) = mesh.positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("non-finite position {p}"));
    }
    let n = mesh.positions.len();
    if let Some(t) = mesh
        .indices
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(format!("triangle {t:?} out of range ({n} vertices)"));
    }
    Ok(())
}

/// A refusal must say something and name the input it refused.
pub fn check_error(error: &SceneError, what: &str) -> Result<(), String> {
    let message = error.to_string();
    if message.trim().is_empty() {
        return Err("the error message is empty".to_owned());
    }
    if !message.contains(what) {
        return Err(format!("the error does not name '{what}': {message}"));
    }
    Ok(())
}
