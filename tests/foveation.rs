//! Foveated frames on the device against CPU references: the rays the GPU traces are exactly
//! the planned ones, the fovea is bit-identical to a regular frame, the fill pass is the
//! Catmull-Rom reference, blend masks bound the steps at layer borders, bad gazes are made
//! safe, and the debug view changes the picture.

mod common;

use fovea::foveation::blend::max_border_step;
use fovea::foveation::catmull_rom::Lattice;
use fovea::foveation::gaze::GazeFix;
use fovea::foveation::plan::{gaze_anchor, Regions};
use fovea::foveation::view::angle_between;
use fovea::foveation::{
    EyePlan, FoveationConfig, Gaze, GazeChoice, ImageGeometry, Layer, RayBuffer,
};
use fovea::gpu::GpuContext;
use fovea::render::{
    eye_views, DebugView, EyeView, FovChoice, Frame, FrameRequest, Integrator, Renderer,
};
use fovea::scene::builtin::builtin;
use fovea::scene::Scene;

/// The eyes of a frame of `w × h` per eye looking where the scene camera looks.
fn eyes(
    scene: &Scene,
    (w, h): (u32, u32),
    fov: FovChoice,
    stereo: bool,
    left: Gaze,
    right: Gaze,
) -> Vec<EyeView> {
    eye_views(
        &scene.camera,
        w as f32 / h as f32,
        fov,
        stereo,
        GazeChoice { left, right },
    )
}

/// A frame request; `settings.spp` is not used by foveated frames (the layers give spp).
fn request<'a>(
    (w, h): (u32, u32),
    seed: u32,
    foveation: &'a FoveationConfig,
    eyes: &'a [EyeView],
    debug: DebugView,
) -> FrameRequest<'a> {
    FrameRequest {
        settings: common::settings(w, h, 1, seed, Integrator::Pt),
        foveation,
        eyes,
        debug,
    }
}

fn images(eyes: &[EyeView], (w, h): (u32, u32)) -> Vec<ImageGeometry> {
    eyes.iter().map(|e| e.image(w, h)).collect()
}

/// Drops the renderer (and with it every resource it made), then fails on any validation
/// message the test produced.
fn finish(renderer: Renderer, ctx: &GpuContext) {
    drop(renderer);
    common::assert_no_validation_messages(ctx);
}

fn two_layer_config() -> FoveationConfig {
    FoveationConfig {
        layers: vec![
            Layer {
                radius_deg: Some(15.0),
                spacing: 2,
                spp: 2,
            },
            Layer {
                radius_deg: None,
                spacing: 5,
                spp: 1,
            },
        ],
        blend_deg: 3.0,
        occlusion_deg: None,
    }
}

/// Camera paths per layer, summed over the eyes, counted by visiting every pixel of every
/// eye: a pixel is traced by a layer if it lies on the layer's lattice (anchored at the gaze
/// pixel, or at (0, 0) for the background) and in the layer's traced region.
fn brute_force_layer_samples(
    config: &FoveationConfig,
    images: &[ImageGeometry],
    gazes: &[[f64; 2]],
) -> Vec<u64> {
    let buffer = RayBuffer::build(config, images);
    let mut samples = vec![0u64; config.layers.len()];
    for (image, &gaze) in images.iter().zip(gazes) {
        let regions = Regions::new(&buffer, image, gaze);
        for (k, layer) in config.layers.iter().enumerate() {
            let d = layer.spacing as i64;
            let a = match layer.radius_deg {
                Some(_) => gaze_anchor(image, gaze),
                None => [0, 0],
            };
            for y in 0..image.height as i64 {
                for x in 0..image.width as i64 {
                    let on = (x - a[0] as i64).rem_euclid(d) == 0
                        && (y - a[1] as i64).rem_euclid(d) == 0;
                    if on && regions.traced(k, x, y) {
                        samples[k] += layer.spp as u64;
                    }
                }
            }
        }
    }
    samples
}

#[test]
fn traced_paths_equal_the_plan_and_a_count_over_every_pixel() {
    let ctx = common::context();
    let size = (96, 80);
    let scene = builtin("control", size.0 as f32 / size.1 as f32).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let mut unmasked = FoveationConfig::thesis();
    unmasked.occlusion_deg = None;
    let configs = [
        ("thesis", FoveationConfig::thesis()),
        ("thesis without mask", unmasked),
        ("two layers", two_layer_config()),
        ("regular", FoveationConfig::regular(2)),
    ];
    for (fov, stereo) in [
        (FovChoice::Scene, false),
        (FovChoice::ViveProEye, false),
        (FovChoice::ViveProEye, true),
        (FovChoice::Scene, true),
    ] {
        let mut thesis_paths = Vec::new();
        for (name, config) in &configs {
            for gaze in [Gaze::Forward, Gaze::Corner] {
                let what = format!("{name}, {fov:?}, stereo {stereo}, {gaze:?}");
                let eyes = eyes(&scene, size, fov, stereo, gaze, gaze);
                let frame = renderer
                    .render_frame(&request(size, 3, config, &eyes, DebugView::None))
                    .unwrap();
                let images = images(&eyes, size);
                let gazes: Vec<[f64; 2]> = eyes
                    .iter()
                    .zip(&images)
                    .map(|(e, image)| e.gaze.resolve(image).0)
                    .collect();
                let used: Vec<[f64; 2]> = frame.gazes.iter().map(|g| g.0).collect();
                assert_eq!(used, gazes, "{what}: gaze pixels");
                let expected = brute_force_layer_samples(config, &images, &gazes);
                assert_eq!(
                    frame.stats.layer_samples, expected,
                    "{what}: planned paths per layer"
                );
                let total: u64 = expected.iter().sum();
                assert_eq!(frame.stats.paths, total, "{what}: GPU-counted paths");
                assert_eq!(
                    frame.stats.eyes.len(),
                    eyes.len(),
                    "{what}: counters per eye"
                );
                for (e, counted) in frame.stats.eyes.iter().enumerate() {
                    let own: u64 = brute_force_layer_samples(config, &images[e..=e], &gazes[e..=e])
                        .iter()
                        .sum();
                    assert_eq!(counted.paths, own, "{what}: GPU-counted paths of eye {e}");
                    assert!(counted.rays >= counted.paths, "{what}: eye {e} rays");
                }
                assert!(total > 0, "{what}: nothing traced");
                assert_eq!(frame.stats.nonfinite_samples, 0, "{what}");
                assert_eq!(frame.stats.stack_overflows, 0, "{what}");
                if *name == "regular" {
                    let pixels = (size.0 * size.1) as u64 * eyes.len() as u64;
                    assert_eq!(total, pixels * 2, "{what}: regular traces every pixel");
                }
                if *name == "thesis" {
                    thesis_paths.push(total);
                }
            }
        }
        // At the scene's desktop field of view most of each disc around a corner gaze is off
        // the image. (Not so with the headset's at these sizes: the fill margins, two lattice
        // steps plus two pixels at the image's largest angle per pixel, reach past the
        // occlusion mask's corners at small sizes (still at 360×400, no longer at 720×800),
        // and a degree spans more pixels off axis, so the corner traces more there.)
        if fov == FovChoice::Scene {
            let (forward, corner) = (thesis_paths[0], thesis_paths[1]);
            assert!(
                corner < forward,
                "{fov:?} stereo {stereo}: corner gaze traced {corner} paths, forward {forward}"
            );
        }
    }
    finish(renderer, &ctx);
}

/// Compares a foveated frame with a regular one of the same eyes and seed. Returns, per eye,
/// the number of pixels in the fovea (all checked bit-identical), the number of pixels well
/// outside the innermost layer that are not black in the regular frame (black ones see
/// nothing but the empty background, and interpolating zeros gives zeros), and how many of
/// those differ.
fn compare_fovea(
    frame: &Frame,
    regular: &Frame,
    config: &FoveationConfig,
    images: &[ImageGeometry],
    what: &str,
) -> Vec<(usize, usize, usize)> {
    assert_eq!((frame.width, frame.height), (regular.width, regular.height));
    let radius = config.layers[0].radius_deg.unwrap() as f64;
    let alone = (radius - config.blend_deg as f64).to_radians();
    let outer = radius.to_radians();
    let occlusion = config
        .occlusion_deg
        .map_or(f64::INFINITY, |o| (o as f64).to_radians());
    let mut out = Vec::new();
    for (e, image) in images.iter().enumerate() {
        let px = image.max_radians_per_pixel();
        let gaze = image.tan_of(frame.gazes[e].0[0], frame.gazes[e].0[1]);
        let (mut fovea, mut outside, mut differing) = (0, 0, 0);
        for y in 0..image.height {
            for x in 0..image.width {
                let t = image.pixel_centre_tan(x as i64, y as i64);
                if angle_between(t, [0.0, 0.0]) >= occlusion - px {
                    continue;
                }
                let theta = angle_between(t, gaze);
                let fx = e as u32 * image.width + x;
                let (a, b) = (frame.pixel(fx, y), regular.pixel(fx, y));
                let same = a.map(f32::to_bits) == b.map(f32::to_bits);
                if theta < alone - px {
                    assert!(
                        same,
                        "{what}: eye {e} pixel ({x}, {y}) at {:.2}° from the gaze: foveated {a:?}, regular {b:?}",
                        theta.to_degrees()
                    );
                    fovea += 1;
                } else if theta > outer + px && b.iter().any(|&v| v != 0.0) {
                    outside += 1;
                    differing += usize::from(!same);
                }
            }
        }
        out.push((fovea, outside, differing));
    }
    out
}

#[test]
fn fovea_is_bit_identical_to_a_regular_frame() {
    let ctx = common::context();
    let config = FoveationConfig::thesis();
    assert_eq!(config.layers[0].spp, 4);
    assert_eq!(config.layers[0].spacing, 1);
    let regular = FoveationConfig::regular(4);
    let seed = 5;

    // Mono, the scene's field of view.
    let size = (96, 96);
    let scene = builtin("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    for gaze in [Gaze::Forward, Gaze::Pixel(30.0, 40.0)] {
        let eyes = eyes(&scene, size, FovChoice::Scene, false, gaze, gaze);
        let foveated = renderer
            .render_frame(&request(size, seed, &config, &eyes, DebugView::None))
            .unwrap();
        let reference = renderer
            .render_frame(&request(size, seed, &regular, &eyes, DebugView::None))
            .unwrap();
        assert_eq!(reference.stats.paths, 96 * 96 * 4);
        assert!(foveated.stats.paths < reference.stats.paths);
        let what = format!("mono {gaze:?}");
        let [(fovea, outside, differing)] =
            compare_fovea(&foveated, &reference, &config, &images(&eyes, size), &what)[..]
        else {
            unreachable!("one eye")
        };
        assert!(fovea >= 50, "{what}: only {fovea} pixels in the fovea");
        assert!(
            differing * 2 > outside,
            "{what}: only {differing} of {outside} pixels outside the fovea differ from the regular frame"
        );
    }
    finish(renderer, &ctx);

    // Stereo, the headset's asymmetric fields of view, a different gaze per eye.
    let size = (64, 72);
    let scene = builtin("cornell", size.0 as f32 / size.1 as f32).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let eyes = eyes(
        &scene,
        size,
        FovChoice::ViveProEye,
        true,
        Gaze::Forward,
        Gaze::Pixel(28.0, 40.0),
    );
    let foveated = renderer
        .render_frame(&request(size, seed, &config, &eyes, DebugView::None))
        .unwrap();
    let reference = renderer
        .render_frame(&request(size, seed, &regular, &eyes, DebugView::None))
        .unwrap();
    let per_eye = compare_fovea(
        &foveated,
        &reference,
        &config,
        &images(&eyes, size),
        "stereo",
    );
    for (e, (fovea, outside, differing)) in per_eye.into_iter().enumerate() {
        // One pixel spans about 2.3° here, so the 5° fovea holds only a few whole pixels.
        assert!(
            fovea >= 3,
            "stereo eye {e}: only {fovea} pixels in the fovea"
        );
        assert!(
            differing * 2 > outside,
            "stereo eye {e}: only {differing} of {outside} pixels outside the fovea differ"
        );
    }
    finish(renderer, &ctx);
}

/// What the fill pass must do to one pixel of one layer image.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fill {
    /// Left as uploaded: a lattice point, a layer of spacing 1, or a pixel the layer never shows.
    Kept,
    /// The Catmull-Rom value of the lattice around it: the merge may show it.
    Filled,
    /// Within a pixel's angle of the fill's edge: either is right.
    Either,
}

struct LayerFill {
    lattice: Lattice,
    spacing: i32,
    /// Row-major, one per pixel of the eye's image.
    pixels: Vec<Fill>,
}

/// The CPU's expectation of the fill pass for every eye (outer) and layer (inner).
fn expected_fill(
    config: &FoveationConfig,
    images: &[ImageGeometry],
    gazes: &[[f64; 2]],
) -> Vec<Vec<LayerFill>> {
    let buffer = RayBuffer::build(config, images);
    let occlusion = config
        .occlusion_deg
        .map_or(f64::INFINITY, |o| (o as f64).to_radians());
    let blend = (config.blend_deg as f64).to_radians();
    images
        .iter()
        .zip(gazes)
        .map(|(image, &gaze_px)| {
            let plan = EyePlan::new(&buffer, image, gaze_px);
            let gaze = image.tan_of(gaze_px[0], gaze_px[1]);
            let slack = image.max_radians_per_pixel();
            config
                .layers
                .iter()
                .enumerate()
                .map(|(k, layer)| {
                    let p = &plan.layers[k];
                    let anchor = match layer.radius_deg {
                        Some(_) => gaze_anchor(image, gaze_px),
                        None => [0, 0],
                    };
                    assert_eq!(p.anchor, anchor, "layer {k} anchor");
                    let spacing = layer.spacing as i32;
                    let lattice = Lattice {
                        anchor,
                        spacing,
                        min: p.lattice_min,
                        max: p.lattice_max,
                    };
                    let outer = layer
                        .radius_deg
                        .map_or(f64::INFINITY, |r| (r as f64).to_radians());
                    let inner = match k {
                        0 => f64::NEG_INFINITY,
                        _ => (config.layers[k - 1].radius_deg.unwrap() as f64).to_radians() - blend,
                    };
                    let mut pixels = Vec::new();
                    for y in 0..image.height as i32 {
                        for x in 0..image.width as i32 {
                            if spacing == 1 || lattice.contains(x, y) {
                                pixels.push(Fill::Kept);
                                continue;
                            }
                            let t = image.pixel_centre_tan(x as i64, y as i64);
                            let theta = angle_between(t, gaze);
                            let axis = angle_between(t, [0.0, 0.0]);
                            let within = |m: f64| {
                                theta < outer + m * slack
                                    && theta > inner - m * slack
                                    && axis < occlusion + m * slack
                            };
                            let in_rect = (p.fill_min[0]..p.fill_max[0]).contains(&x)
                                && (p.fill_min[1]..p.fill_max[1]).contains(&y);
                            pixels.push(if within(0.5) {
                                Fill::Filled
                            } else if !within(1.5) || !in_rect {
                                Fill::Kept
                            } else {
                                Fill::Either
                            });
                        }
                    }
                    LayerFill {
                        lattice,
                        spacing,
                        pixels,
                    }
                })
                .collect()
        })
        .collect()
}

/// Deterministic values in [0, 1).
fn lcg_values(n: usize, mut state: u64) -> Vec<f32> {
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect()
}

/// Index of channel `c` of pixel `(x, y)` of layer `k` of eye `e` in the layer images.
fn layer_index(
    (w, h): (u32, u32),
    layers: usize,
    e: usize,
    k: usize,
    x: i32,
    y: i32,
    c: usize,
) -> usize {
    (((e * layers + k) * h as usize + y as usize) * w as usize + x as usize) * 4 + c
}

/// One fill case: a config, a scene's eyes and the image size.
struct FillCase {
    name: &'static str,
    config: FoveationConfig,
    fov: FovChoice,
    stereo: bool,
    gazes: (Gaze, Gaze),
    size: (u32, u32),
}

fn fill_cases() -> Vec<FillCase> {
    let background = FoveationConfig {
        layers: vec![Layer {
            radius_deg: None,
            spacing: 3,
            spp: 1,
        }],
        blend_deg: 1.0,
        occlusion_deg: None,
    };
    let mut unmasked = FoveationConfig::thesis();
    unmasked.occlusion_deg = None;
    vec![
        FillCase {
            name: "background spacing 3",
            config: background,
            fov: FovChoice::Scene,
            stereo: false,
            gazes: (Gaze::Forward, Gaze::Forward),
            size: (64, 50),
        },
        FillCase {
            name: "thesis without mask, scene view",
            config: unmasked.clone(),
            fov: FovChoice::Scene,
            stereo: false,
            gazes: (Gaze::Forward, Gaze::Forward),
            size: (96, 80),
        },
        FillCase {
            name: "thesis without mask, stereo headset",
            config: unmasked,
            fov: FovChoice::ViveProEye,
            stereo: true,
            gazes: (Gaze::Forward, Gaze::Pixel(10.3, 60.7)),
            size: (64, 72),
        },
        FillCase {
            name: "thesis, stereo headset",
            config: FoveationConfig::thesis(),
            fov: FovChoice::ViveProEye,
            stereo: true,
            gazes: (Gaze::Corner, Gaze::Pixel(40.0, 20.0)),
            size: (64, 72),
        },
    ]
}

#[test]
fn gpu_fill_equals_the_cpu_catmull_rom_reference() {
    let ctx = common::context();
    let scene = builtin("control", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    for case in fill_cases() {
        let size = case.size;
        let (w, h) = (size.0 as i32, size.1 as i32);
        let eyes = eyes(
            &scene,
            size,
            case.fov,
            case.stereo,
            case.gazes.0,
            case.gazes.1,
        );
        let images = images(&eyes, size);
        let gazes: Vec<[f64; 2]> = eyes
            .iter()
            .zip(&images)
            .map(|(e, image)| e.gaze.resolve(image).0)
            .collect();
        let expected = expected_fill(&case.config, &images, &gazes);
        let layers = case.config.layers.len();
        let n = eyes.len() * layers * (w * h) as usize * 4;
        let req = request(size, 1, &case.config, &eyes, DebugView::None);

        // Random data: every filled pixel is the bicubic of its lattice neighbours.
        let input = lcg_values(n, 0x5eed ^ n as u64);
        let (frame, filled) = renderer.compose(&req, &input).unwrap();
        assert_eq!(filled.len(), n, "{}: layer images", case.name);
        assert!(frame.rgb.iter().all(|v| v.is_finite()), "{}", case.name);
        for (e, eye) in expected.iter().enumerate() {
            for (k, layer) in eye.iter().enumerate() {
                let input = &input;
                let at = |c: usize| {
                    move |x: i32, y: i32| input[layer_index(size, layers, e, k, x, y, c)]
                };
                let mut filled_count = 0;
                for y in 0..h {
                    for x in 0..w {
                        let what = format!("{}: eye {e} layer {k} pixel ({x}, {y})", case.name);
                        let i = layer_index(size, layers, e, k, x, y, 0);
                        let got = &filled[i..i + 4];
                        let kept = &input[i..i + 4];
                        let reference: Vec<f32> = (0..4)
                            .map(|c| layer.lattice.interpolate(x, y, at(c)))
                            .collect();
                        let is_kept = got
                            .iter()
                            .zip(kept)
                            .all(|(a, b)| a.to_bits() == b.to_bits());
                        let is_filled = got
                            .iter()
                            .zip(&reference)
                            .all(|(a, b)| (a - b).abs() <= 1e-5);
                        match layer.pixels[(y * w + x) as usize] {
                            Fill::Kept => {
                                assert!(is_kept, "{what}: changed to {got:?} from {kept:?}")
                            }
                            Fill::Filled => {
                                assert!(is_filled, "{what}: GPU {got:?}, CPU {reference:?}");
                                filled_count += 1;
                            }
                            Fill::Either => assert!(
                                is_kept || is_filled,
                                "{what}: GPU {got:?}, neither kept {kept:?} nor CPU {reference:?}"
                            ),
                        }
                    }
                }
                if layer.spacing > 1 {
                    assert!(
                        filled_count > 0,
                        "{}: eye {e} layer {k} filled nothing",
                        case.name
                    );
                }
            }
        }

        // A linear gradient on the lattice points (and a sentinel elsewhere): Catmull-Rom
        // reproduces it wherever no tap is clamped at the image border.
        let coefficients = [
            [0.011, 0.004, 0.5],
            [-0.003, 0.009, 1.5],
            [0.006, -0.007, 2.0],
            [0.001, 0.002, 0.25],
        ];
        let f = |x: i32, y: i32, c: usize| {
            let [a, b, z] = coefficients[c];
            a * x as f32 + b * y as f32 + z
        };
        let mut input = vec![-7.0f32; n];
        for (e, eye) in expected.iter().enumerate() {
            for (k, layer) in eye.iter().enumerate() {
                for y in 0..h {
                    for x in 0..w {
                        if layer.lattice.contains(x, y) {
                            for c in 0..4 {
                                input[layer_index(size, layers, e, k, x, y, c)] = f(x, y, c);
                            }
                        }
                    }
                }
            }
        }
        let (_, filled) = renderer.compose(&req, &input).unwrap();
        for (e, eye) in expected.iter().enumerate() {
            for (k, layer) in eye.iter().enumerate() {
                let margin = 2 * layer.spacing;
                let mut checked = 0;
                for y in margin..h - margin {
                    for x in margin..w - margin {
                        if layer.pixels[(y * w + x) as usize] != Fill::Filled {
                            continue;
                        }
                        for c in 0..4 {
                            let got = filled[layer_index(size, layers, e, k, x, y, c)];
                            let want = f(x, y, c);
                            assert!(
                                (got - want).abs() <= 1e-4 * want.abs(),
                                "{}: eye {e} layer {k} pixel ({x}, {y}) channel {c}: {got} vs {want}",
                                case.name
                            );
                        }
                        checked += 1;
                    }
                }
                if layer.spacing > 1 {
                    assert!(
                        checked > 0,
                        "{}: eye {e} layer {k}: no interior pixel filled",
                        case.name
                    );
                }
            }
        }
    }
    finish(renderer, &ctx);
}

/// The largest step of any channel between horizontally or vertically neighbouring pixels.
fn largest_step(frame: &Frame) -> f32 {
    let mut step = 0.0f32;
    for y in 0..frame.height {
        for x in 0..frame.width {
            let p = frame.pixel(x, y);
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if nx < frame.width && ny < frame.height {
                    let q = frame.pixel(nx, ny);
                    for c in 0..3 {
                        step = step.max((p[c] - q[c]).abs());
                    }
                }
            }
        }
    }
    step
}

#[test]
fn blend_masks_bound_the_step_at_a_layer_border() {
    let ctx = common::context();
    let size = (128u32, 128u32);
    let scene = builtin("control", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let (gx, gy) = (0.002f32, 0.001f32);
    let g = |x: u32, y: u32| 0.3 + gx * x as f32 + gy * y as f32;
    let difference = 0.25f32;
    let mut input = Vec::new();
    for offset in [0.0, difference] {
        for y in 0..size.1 {
            for x in 0..size.0 {
                let v = g(x, y) + offset;
                input.extend([v, v, v, 1.0]);
            }
        }
    }
    let config = |blend_deg: f32| FoveationConfig {
        layers: vec![
            Layer {
                radius_deg: Some(10.0),
                spacing: 1,
                spp: 1,
            },
            Layer {
                radius_deg: None,
                spacing: 1,
                spp: 1,
            },
        ],
        blend_deg,
        occlusion_deg: None,
    };
    for gaze in [Gaze::Forward, Gaze::Pixel(30.5, 90.2)] {
        let eyes = eyes(&scene, size, FovChoice::Scene, false, gaze, gaze);
        let image = eyes[0].image(size.0, size.1);

        let blended = config(2.0);
        let (frame, _) = renderer
            .compose(&request(size, 1, &blended, &eyes, DebugView::None), &input)
            .unwrap();
        let gaze_px = frame.gazes[0].0;
        // The layers really both show: the gaze pixel is the inner one, a far corner the outer.
        let (cx, cy) = (gaze_px[0] as u32, gaze_px[1] as u32);
        assert_eq!(frame.pixel(cx, cy)[0], g(cx, cy), "{gaze:?}: gaze pixel");
        let far = |c: u32, side: u32| if c < side / 2 { side - 1 } else { 0 };
        let (fx, fy) = (far(cx, size.0), far(cy, size.1));
        assert_eq!(
            frame.pixel(fx, fy)[0],
            g(fx, fy) + difference,
            "{gaze:?}: far pixel"
        );
        let bound = (gx * gx + gy * gy).sqrt() as f64
            + max_border_step(
                difference as f64,
                (blended.blend_deg as f64).to_radians(),
                image.max_radians_per_pixel(),
            )
            + 1e-5;
        let step = largest_step(&frame);
        assert!(
            step as f64 <= bound,
            "{gaze:?}: step {step} beyond the bound {bound}"
        );
        assert!(
            step < difference / 2.0,
            "{gaze:?}: step {step} is not clearly below the layer difference"
        );

        let hard = config(0.0);
        let (frame, _) = renderer
            .compose(&request(size, 1, &hard, &eyes, DebugView::None), &input)
            .unwrap();
        let step = largest_step(&frame);
        assert!(step >= 0.2, "{gaze:?}: a hard edge steps by only {step}");
    }
    finish(renderer, &ctx);
}

#[test]
fn bad_gazes_render_safely_and_are_reported() {
    let ctx = common::context();
    let size = (48u32, 48u32);
    let scene = builtin("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let config = FoveationConfig::thesis();
    let axis = {
        let eyes = eyes(
            &scene,
            size,
            FovChoice::Scene,
            false,
            Gaze::Forward,
            Gaze::Forward,
        );
        Gaze::Forward.resolve(&eyes[0].image(size.0, size.1)).0
    };
    for (gaze, fix, pixel) in [
        (Gaze::Pixel(f64::NAN, 3.0), GazeFix::NotFinite, axis),
        (
            Gaze::Pixel(f64::INFINITY, f64::NEG_INFINITY),
            GazeFix::NotFinite,
            axis,
        ),
        (Gaze::Pixel(-500.0, 10_000.0), GazeFix::Clamped, [0.0, 48.0]),
        (Gaze::Corner, GazeFix::None, [0.5, 0.5]),
    ] {
        let eyes = eyes(&scene, size, FovChoice::Scene, false, gaze, gaze);
        let frame = renderer
            .render_frame(&request(size, 9, &config, &eyes, DebugView::None))
            .unwrap_or_else(|e| panic!("{gaze:?}: {e}"));
        assert_eq!(frame.gazes.len(), 1);
        assert_eq!(frame.gazes[0], (pixel, fix), "{gaze:?}");
        assert!(
            frame.rgb.iter().all(|v| v.is_finite()),
            "{gaze:?}: non-finite pixels"
        );
        assert!(frame.mean().iter().any(|&m| m > 1e-3), "{gaze:?}: black");
        let planned: u64 = frame.stats.layer_samples.iter().sum();
        assert_eq!(frame.stats.paths, planned, "{gaze:?}");
        assert!(planned > 0, "{gaze:?}: nothing traced");
        assert_eq!(frame.stats.nonfinite_samples, 0, "{gaze:?}");
    }
    finish(renderer, &ctx);
}

#[test]
fn debug_layers_view_tints_a_stereo_frame() {
    let ctx = common::context();
    let size = (48u32, 48u32);
    let scene = builtin("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let config = FoveationConfig::thesis().with_spp(1);
    let eyes = eyes(
        &scene,
        size,
        FovChoice::ViveProEye,
        true,
        Gaze::Forward,
        Gaze::Forward,
    );
    let plain = renderer
        .render_frame(&request(size, 2, &config, &eyes, DebugView::None))
        .unwrap();
    let debug = renderer
        .render_frame(&request(size, 2, &config, &eyes, DebugView::Layers))
        .unwrap();
    assert_eq!(plain.width, 2 * size.0);
    assert_eq!((debug.width, debug.height), (plain.width, plain.height));
    assert!(
        debug.rgb.iter().all(|v| v.is_finite()),
        "non-finite pixels in the debug view"
    );
    let differing = plain
        .rgb
        .chunks_exact(3)
        .zip(debug.rgb.chunks_exact(3))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differing > (size.0 * size.1) as usize,
        "the debug view changed only {differing} pixels"
    );
    // The gaze pixel of each eye is in the innermost layer, tinted red.
    for (e, (g, _)) in debug.gazes.iter().enumerate() {
        let p = debug.pixel(e as u32 * size.0 + g[0] as u32, g[1] as u32);
        assert!(
            p[0] > 2.0 * p[1] && p[0] > 2.0 * p[2],
            "eye {e}: gaze pixel {p:?} is not tinted as the innermost layer"
        );
    }
    finish(renderer, &ctx);
}
