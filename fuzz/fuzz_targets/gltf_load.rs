//! Fuzzes the glTF loader with arbitrary bytes (`.glb` or `.gltf` with embedded buffers, the
//! content decides): it must refuse bad input with an error that names it, never panic, hang
//! or allocate absurdly, and what it accepts must satisfy [`checks::check_scene`] (finite
//! positions and materials, in-range indices) and have a GPU layout that does not panic.
//! Run it with `tools/fuzz.sh`.

#![no_main]

use fovea::scene::gltf_load::{load_gltf_bytes, mesh_from_glb_bytes};
use libfuzzer_sys::fuzz_target;

#[path = "../src/checks.rs"]
mod checks;

const WHAT: &str = "fuzz-input.gltf";

fuzz_target!(|data: &[u8]| {
    match load_gltf_bytes(data, WHAT, 16.0 / 9.0) {
        Ok(scene) => {
            checks::check_scene(&scene).unwrap_or_else(|e| panic!("accepted: {e}"));
            checks::build_gpu_layout(&scene);
        }
        Err(e) => checks::check_error(&e, WHAT).unwrap_or_else(|e| panic!("refused: {e}")),
    }
    // The built-in scenes' path: every triangle merged into one mesh.
    match mesh_from_glb_bytes(data, "fuzz-input.glb") {
        Ok(mesh) => checks::check_mesh(&mesh).unwrap_or_else(|e| panic!("merged: {e}")),
        Err(e) => checks::check_error(&e, "fuzz-input.glb").unwrap_or_else(|e| panic!("{e}")),
    }
});
