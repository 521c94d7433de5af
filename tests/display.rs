//! `--exposure` and `--tonemap` on what `fovea render` shows: the PNG goes through them, the
//! EXR beside it stays scene-referred; built-in scenes keep clamping, glTF files default to
//! Khronos PBR Neutral.

mod common;

use std::path::Path;

/// Renders `scene` at 16×16 with `flags` into `dir/name.png`; returns the PNG's and the EXR's
/// bytes.
fn render(dir: &Path, name: &str, scene: &str, flags: &[&str]) -> (Vec<u8>, Vec<u8>) {
    let png = dir.join(format!("{name}.png"));
    let size = ["--width", "16", "--height", "16", "--spp", "2"];
    let out = ["--scene", scene, "--out", png.to_str().unwrap()];
    let (ok, text) = common::fovea(&[&["render"][..], &size, &out, flags].concat());
    assert!(ok, "{text}");
    (
        std::fs::read(&png).unwrap(),
        std::fs::read(png.with_extension("exr")).unwrap(),
    )
}

/// The mean of a PNG's 8-bit sRGB values.
fn mean_byte(png: &[u8]) -> f64 {
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bytes = &buf[..info.buffer_size()];
    bytes.iter().map(|&b| b as f64).sum::<f64>() / bytes.len() as f64
}

#[test]
fn built_in_scenes_clamp_and_gltf_files_default_to_pbr_neutral() {
    let dir = common::test_dir("display");
    let builtin = render(&dir, "cornell", "cornell", &[]);
    assert_eq!(
        builtin,
        render(&dir, "cornell-clamp", "cornell", &["--tonemap", "clamp"])
    );

    let card = format!("{}/assets/gltf/alpha-card.glb", env!("CARGO_MANIFEST_DIR"));
    let default = render(&dir, "card", &card, &[]);
    let neutral = render(&dir, "card-neutral", &card, &["--tonemap", "pbr-neutral"]);
    let clamp = render(&dir, "card-clamp", &card, &["--tonemap", "clamp"]);
    assert_eq!(default, neutral);
    assert_ne!(neutral.0, clamp.0, "the tone mapper changes the PNG");
    assert_eq!(neutral.1, clamp.1, "and leaves the EXR scene-referred");

    let brighter = render(&dir, "card-up", &card, &["--exposure", "1"]);
    let darker = render(&dir, "card-down", &card, &["--exposure=-1"]);
    assert_eq!(brighter.1, neutral.1);
    assert!(mean_byte(&brighter.0) > mean_byte(&neutral.0));
    assert!(mean_byte(&darker.0) < mean_byte(&neutral.0));
}

#[test]
fn a_bad_exposure_or_tone_mapper_is_named() {
    for (flag, value) in [
        ("--exposure", "bright"),
        ("--exposure", "99"),
        ("--tonemap", "aces"),
    ] {
        let (ok, text) = common::fovea(&["render", "--width", "8", "--height", "8", flag, value]);
        assert!(!ok && text.contains(value), "{flag} {value}: {text}");
    }
}
