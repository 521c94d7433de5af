//! `fovea scenes`: the built-in scenes and what each needs.

use anyhow::Result;
use fovea::scene::{builtin::BUILTIN_SCENES, SceneFeatures};

pub fn run() -> Result<()> {
    println!(
        "{:<12} {:>9}  {:<40} description",
        "name", "triangles", "needs"
    );
    for (name, description) in BUILTIN_SCENES {
        let scene = fovea::scene::builtin::builtin(name, 1.0)?;
        let features = SceneFeatures::of(&scene);
        println!(
            "{:<12} {:>9}  {:<40} {}",
            name,
            scene.triangle_count(),
            features.describe(),
            description
        );
    }
    Ok(())
}
