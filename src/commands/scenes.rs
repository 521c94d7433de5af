//! `fovea scenes [FILE...]`: the built-in scenes and what each needs, or what the given glTF
//! files hold and need.

use std::io::Write;

use anyhow::Result;
use clap::Args;
use fovea::scene::{builtin::BUILTIN_SCENES, Scene, SceneFeatures};

#[derive(Args)]
pub struct ScenesArgs {
    /// .gltf/.glb files to describe instead of the built-in scenes.
    files: Vec<String>,
}

pub fn run(args: &ScenesArgs) -> Result<()> {
    let mut rows = Vec::new();
    if args.files.is_empty() {
        for (name, description) in BUILTIN_SCENES {
            rows.push(row(
                &fovea::scene::builtin::builtin(name, 1.0)?,
                description,
            ));
        }
    }
    for file in &args.files {
        let scene = fovea::scene::load(file, 1.0)?;
        let description = format!(
            "{} meshes, {} instances, {} materials: {file}",
            scene.meshes.len(),
            scene.instances.len(),
            scene.materials.len()
        );
        rows.push(row(&scene, &description));
    }
    let name_width = rows.iter().map(|r| r[0].len()).max().unwrap_or(0).max(12);
    // A closed pipe (`fovea scenes | head`) ends the listing: main exits quietly on it.
    let mut out = std::io::stdout().lock();
    let header = ["name", "triangles", "textures", "needs", "description"].map(String::from);
    for [name, triangles, textures, needs, description] in std::iter::once(header).chain(rows) {
        writeln!(
            out,
            "{name:<name_width$} {triangles:>9} {textures:>8}  {needs:<40} {description}"
        )?;
    }
    Ok(())
}

fn row(scene: &Scene, description: &str) -> [String; 5] {
    [
        scene.name.clone(),
        scene.triangle_count().to_string(),
        scene.textures.len().to_string(),
        SceneFeatures::of(scene).describe(),
        description.to_string(),
    ]
}
