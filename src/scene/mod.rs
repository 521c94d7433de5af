//! Scenes: the description (`types`), the built-in scenes, glTF loading, BVH construction and
//! the GPU layout, and the feature flags that let shaders skip what a scene does not need.

mod alias_table;
mod area_emitters;
pub mod builtin;
mod camera_path;
pub mod cpu_raycast;
pub mod env_choice;
pub mod env_map;
pub mod env_sampling;
mod error;
mod features;
pub mod fingerprint;
pub mod glb_write;
pub mod gltf_from_thesis;
pub mod gltf_load;
pub mod gltf_samples;
pub mod gpu_layout;
mod gpu_materials;
pub mod light_choice;
mod light_selection;
pub mod lights;
pub mod mipmaps;
pub mod shapes;
pub mod tangents;
pub mod texture_size;
pub mod types;
pub mod validate;

pub use camera_path::{CameraPath, CameraPathError, CameraPose};
pub use cpu_raycast::CpuRaycaster;
pub use env_map::{EnvSampling, EnvironmentLight, EnvironmentMap};
pub use error::SceneError;
pub use features::SceneFeatures;
pub use lights::{LightKind, LightSelection, PunctualLight};
pub use types::*;

/// Whether a scene named on the command line is a .gltf/.glb file (else a built-in name).
pub fn is_scene_file(name_or_path: &str) -> bool {
    std::path::Path::new(name_or_path)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// A built-in scene by name, or a .gltf/.glb file by path, lit by the environment of `--env`
/// where one was given (env_choice.rs).
pub fn load(name_or_path: &str, aspect: f32) -> Result<Scene, SceneError> {
    let mut scene = load_own(name_or_path, aspect)?;
    env_choice::apply(&mut scene);
    light_choice::apply(&mut scene);
    Ok(scene)
}

/// A scene as its file or built-in definition has it.
fn load_own(name_or_path: &str, aspect: f32) -> Result<Scene, SceneError> {
    let path = std::path::Path::new(name_or_path);
    if is_scene_file(name_or_path) {
        let mut scene = gltf_load::load_gltf(path, aspect)?;
        if let Some(max_side) = texture_size::max_texture_size() {
            let changed = texture_size::downscale_textures(&mut scene, max_side);
            if !changed.is_empty() {
                tracing::warn!(
                    "--max-texture-size {max_side}: downscaled {}",
                    changed.join(", ")
                );
            }
        }
        Ok(scene)
    } else {
        builtin::builtin(name_or_path, aspect)
    }
}
