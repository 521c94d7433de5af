//! Writes fovea's own glTF sample scenes (src/scene/gltf_samples.rs) to assets/gltf/, or to
//! the folder given: `cargo run --example write_gltf_samples [DIR]`.

use fovea::scene::glb_write::write_glb;
use fovea::scene::gltf_samples::gltf_samples;

fn main() {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "assets/gltf".into());
    for scene in gltf_samples() {
        let path = std::path::Path::new(&dir).join(format!("{}.glb", scene.name));
        if let Err(e) = write_glb(&scene, &path) {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
        println!("{}", path.display());
    }
}
