//! Each eye reads its own part of the lattice through its own texel views (shared.h's
//! EYE_TEXEL_VIEWS): the right eye's views start at its first lattice entry, so that one eye's
//! lattice, not both, is what maxTexelBufferElements bounds. Both eyes here see the same
//! camera and gaze, so their frames differ only by their own samples' noise: the right eye
//! reading outside its part (nothing, or the left eye's values) would show as a black or
//! copied image. And a pass that binds a single view where shared.h declares one per eye (or
//! the other way round) is refused before its set is written.

mod common;

use fovea::foveation::{FoveationConfig, Gaze};
use fovea::gpu::{vk, Bound, Buffer, DescriptorArena, EyeTexels, PipelineLayout, TexelView};
use fovea::render::{DebugView, EyeView, FrameOptions, FrameRequest, Integrator};
use fovea::shader_layout::{
    BINDING_HISTORY_TEXELS, BINDING_LATTICE_SURFACE_TEXELS, BINDING_LATTICE_TEXELS,
};
use gpu_allocator::MemoryLocation;

const SIDE: u32 = 32;
/// Pixels per side of the blocks whose means (summed over RGB) are compared.
const BLOCK: usize = 8;

/// A fovea over a sparse background, both filtered on their lattice and resolved with the
/// history: every pass that reads the lattice's texel views (lattice filter, resolve,
/// temporal) runs.
const CONFIG: &str = "blend_deg = 2.0\n\
    [[layer]]\nradius_deg = 15.0\nspacing = 1\nspp = 2\nfilter_px = 1.0\n\
    [[layer]]\nspacing = 2\nspp = 2\nfilter_mar = 2.0\n";

/// Each eye's image of `frame` (eyes side by side in its rows): RGB rows of SIDE pixels.
fn eye_images(rgb: &[f32]) -> [Vec<f32>; 2] {
    let row = SIDE as usize * 3;
    let mut eyes = [Vec::new(), Vec::new()];
    for pair in rgb.chunks_exact(2 * row) {
        eyes[0].extend_from_slice(&pair[..row]);
        eyes[1].extend_from_slice(&pair[row..]);
    }
    eyes
}

#[test]
fn each_eye_reads_its_own_lattice_through_its_own_views() {
    let ctx = common::context();
    let scene = fovea::scene::load("cornell", 1.0).unwrap();
    let mut renderer = common::renderer_with_history(&ctx, &scene);
    let config = FoveationConfig::from_toml_str(CONFIG, "test").unwrap();
    let eye = EyeView {
        camera: scene.camera,
        gaze: Gaze::Forward,
    };
    let eyes = [eye, eye];
    let mut frame = None;
    for seed in 1..=8 {
        let request = FrameRequest {
            settings: common::settings(SIDE, SIDE, 1, seed, Integrator::Pt),
            foveation: &config,
            eyes: &eyes,
            debug: DebugView::None,
        };
        frame = renderer.frame(&request, FrameOptions::pixels()).unwrap();
    }
    let frame = frame.expect("the last frame was waited for");
    let [left, right] = eye_images(&frame.rgb);
    assert_eq!(left.len(), right.len());
    assert_ne!(left, right, "each eye traces its own samples");
    let block_sums = |image: &[f32]| -> Vec<f64> {
        let stats = common::block_stats(image, SIDE as usize, BLOCK);
        stats
            .iter()
            .map(|b| b.iter().map(|(mean, _)| mean).sum())
            .collect()
    };
    let (l, r) = (block_sums(&left), block_sums(&right));
    let mean = l.iter().sum::<f64>() / l.len() as f64;
    assert!(mean > 0.05, "the left eye sees the lit box: {mean}");
    eprintln!("block means, left: {l:.3?}\nright: {r:.3?}");
    for (b, (a, c)) in l.iter().zip(&r).enumerate() {
        // Eight frames of 2 spp, filtered, over 64 pixels: within 20% of the brighter block
        // (the lamp's is the noisiest) and a tenth of the image's mean (the dark ones).
        assert!(
            (a - c).abs() < 0.2 * a.max(*c) + 0.1 * mean,
            "block {b}: left {a:.4}, right {c:.4} (image mean {mean:.4})"
        );
    }
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
}

#[test]
fn a_single_view_where_one_per_eye_is_declared_is_refused() {
    let ctx = common::context();
    let layout = PipelineLayout::new(&ctx).unwrap();
    let mut descriptors = DescriptorArena::new(&ctx).unwrap();
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER;
    let buffer = Buffer::new(&ctx, "lattice", 64, usage, MemoryLocation::GpuOnly).unwrap();
    let single = TexelView::of_frame(&buffer, "lattice").unwrap();
    let per_eye = EyeTexels::of_frame(&buffer, "lattice", 2, 2).unwrap();
    let refused = [
        (BINDING_LATTICE_TEXELS, Bound::Texels(&single)),
        (BINDING_LATTICE_SURFACE_TEXELS, Bound::Texels(&single)),
        (BINDING_HISTORY_TEXELS, Bound::EyeTexels(&per_eye)),
    ];
    for (binding, bound) in refused {
        let error = descriptors.set(&layout, &[(binding, bound)]).unwrap_err();
        assert!(
            error.to_string().contains("bug in fovea"),
            "{binding}: {error}"
        );
    }
    let set = descriptors.set(
        &layout,
        &[(BINDING_LATTICE_TEXELS, Bound::EyeTexels(&per_eye))],
    );
    assert!(set.is_ok(), "{:?}", set.err());
}
