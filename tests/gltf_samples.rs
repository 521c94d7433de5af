//! fovea's own glTF samples (assets/gltf/, written by examples/write_gltf_samples.rs from
//! src/scene/gltf_samples.rs): the committed files are what the code writes today, and each
//! loads back with what it is for and renders.

mod common;

use fovea::render::Integrator;
use fovea::scene::glb_write::glb_bytes;
use fovea::scene::gltf_load::load_gltf;
use fovea::scene::gltf_samples::gltf_samples;
use fovea::scene::{AlphaMode, LightKind, Material, MetallicRoughness, Scene};

fn path(name: &str) -> String {
    format!("{}/assets/gltf/{name}.glb", env!("CARGO_MANIFEST_DIR"))
}

fn gltf_materials(scene: &Scene) -> Vec<MetallicRoughness> {
    (scene.materials.iter())
        .filter_map(|m| match m {
            Material::MetallicRoughness(m) => Some(*m),
            Material::Thesis(_) => None,
        })
        .collect()
}

#[test]
fn the_committed_samples_are_what_the_code_writes() {
    for scene in gltf_samples() {
        let committed = std::fs::read(path(&scene.name)).expect("assets/gltf/ has every sample");
        assert!(
            glb_bytes(&scene).unwrap() == committed,
            "assets/gltf/{}.glb is stale: run `cargo run --example write_gltf_samples`",
            scene.name
        );
    }
}

#[test]
fn each_sample_loads_with_what_it_shows_and_renders() {
    let ctx = common::context();
    let names: Vec<String> = gltf_samples().into_iter().map(|s| s.name).collect();
    assert_eq!(
        names,
        [
            "sphere-grid",
            "normal-mapped-quad",
            "alpha-card",
            "emissive-panel",
            "textured-room",
            "punctual-lights"
        ]
    );
    for name in &names {
        let scene = load_gltf(path(name).as_ref(), 1.0).expect("a sample loads");
        let materials = gltf_materials(&scene);
        match name.as_str() {
            "sphere-grid" => {
                let mut grid: Vec<(u32, u32)> = (materials.iter())
                    .filter(|m| m.base_color.x == 0.9)
                    .map(|m| ((m.metallic * 4.0) as u32, (m.roughness * 100.0) as u32))
                    .collect();
                grid.sort();
                grid.dedup();
                assert_eq!(grid.len(), 25, "5 metallic × 5 roughness: {grid:?}");
            }
            "normal-mapped-quad" => {
                assert!(materials.iter().any(|m| m.textures.normal.is_some()));
                assert!(scene.meshes.iter().any(|m| !m.shading.tangents.is_empty()));
            }
            "alpha-card" => assert!(materials
                .iter()
                .any(|m| m.coverage.mode == AlphaMode::Mask { cutoff: 0.5 }
                    && m.textures.base_color.is_some())),
            "emissive-panel" => {
                assert!(materials.iter().any(|m| m.emission.max_element() > 1.0))
            }
            "punctual-lights" => {
                let kinds: Vec<_> = scene.lights.iter().map(|l| l.kind).collect();
                assert!(matches!(
                    kinds[..],
                    [
                        LightKind::Point,
                        LightKind::Spot { .. },
                        LightKind::Directional
                    ]
                ));
            }
            _ => assert_eq!(
                (materials.iter())
                    .filter(|m| m.textures.base_color.is_some())
                    .count(),
                3,
                "the floor, the back wall and the box are textured"
            ),
        }
        let frame = common::render(
            &ctx,
            &scene,
            &common::settings(24, 24, 4, 1, Integrator::Pt),
        );
        assert_eq!(frame.stats.nonfinite_samples, 0, "{name}");
        let mean = frame.rgb.iter().sum::<f32>() / frame.rgb.len() as f32;
        assert!(mean > 0.01, "{name}: a dark image (mean {mean})");
    }
}

#[test]
fn fovea_scenes_describes_the_files_it_is_given() {
    let (ok, text) = common::fovea(&["scenes", &path("alpha-card"), &path("sphere-grid")]);
    assert!(ok, "{text}");
    let card = text
        .lines()
        .find(|l| l.starts_with("alpha-card"))
        .expect("a row per file");
    for word in ["textures", "alpha", "3 materials"] {
        assert!(card.contains(word), "'{word}' missing: {card}");
    }
    assert!(text.lines().any(|l| l.starts_with("sphere-grid")), "{text}");
    assert!(
        !text.contains("cornell"),
        "files replace the built-in list: {text}"
    );
    let (ok, text) = common::fovea(&["scenes", "no-such-file.glb"]);
    assert!(!ok && text.contains("no-such-file.glb"), "{text}");
}
