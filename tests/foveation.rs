//! Foveated frames on the device against CPU references: the rays the GPU traces are exactly
//! the planned ones, the fovea is bit-identical to a regular frame, the resolve pass is the
//! CPU's blend (eq. 3.18) of Catmull-Rom layers (eq. 3.17), blend masks bound the steps at
//! layer borders, bad gazes are made safe, and the debug view changes the picture.

mod common;

use fovea::foveation::blend::{max_border_step, weight};
use fovea::foveation::catmull_rom::Lattice;
use fovea::foveation::fraction;
use fovea::foveation::gaze::GazeFix;
use fovea::foveation::plan::{gaze_anchor, Regions};
use fovea::foveation::view::angle_between;
use fovea::foveation::{
    EyePlan, FoveationConfig, Gaze, GazeChoice, ImageGeometry, Layer, RayBuffer, VisibilityMask,
    DEFAULT_DENOISE_SIGMA,
};
use fovea::gpu::GpuContext;
use fovea::render::FrameOptions;
use fovea::render::{
    eye_views, DebugView, EyeView, FovChoice, Frame, FrameRequest, Integrator, LatticePoint,
    Renderer,
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
                denoise: 0,
                filter_mar: 0.0,
                filter_px: 0.0,
                denoise_mar: 0.0,
                denoise_sigma: DEFAULT_DENOISE_SIGMA,
                fraction: 1,
            },
            Layer {
                radius_deg: None,
                spacing: 5,
                spp: 1,
                denoise: 0,
                filter_mar: 0.0,
                filter_px: 0.0,
                denoise_mar: 0.0,
                denoise_sigma: DEFAULT_DENOISE_SIGMA,
                fraction: 1,
            },
        ],
        blend_deg: 3.0,
        occlusion_deg: None,
    }
}

/// Camera paths per layer, summed over the eyes, counted by visiting every pixel of every
/// eye: a pixel is traced by a layer if it lies on the layer's lattice (anchored at the gaze
/// pixel, or at (0, 0) for the background) and in the layer's traced region, and a
/// fractional layer's pattern (frame 0's) does not skip it, or skips it while its owner is
/// off the image or outside the region. Also the points skipped and filled, all layers.
fn brute_force_layer_samples(
    config: &FoveationConfig,
    images: &[ImageGeometry],
    gazes: &[[f64; 2]],
) -> (Vec<u64>, u64) {
    let buffer = RayBuffer::build(config, images);
    let mut samples = vec![0u64; config.layers.len()];
    let mut filled = 0;
    for (image, &gaze) in images.iter().zip(gazes) {
        let regions = Regions::new(&buffer, image, gaze);
        for (k, layer) in config.layers.iter().enumerate() {
            let d = layer.spacing as i64;
            let a = match layer.radius_deg {
                Some(_) => gaze_anchor(image, gaze),
                None => [0, 0],
            };
            let (w, h) = (image.width as i64, image.height as i64);
            for y in 0..h {
                for x in 0..w {
                    let on = (x - a[0] as i64).rem_euclid(d) == 0
                        && (y - a[1] as i64).rem_euclid(d) == 0;
                    if !(on && regions.traced(k, x, y)) {
                        continue;
                    }
                    let (i, j) = (
                        ((x - a[0] as i64) / d) as i32,
                        ((y - a[1] as i64) / d) as i32,
                    );
                    let [oi, oj] = fraction::owner(layer.fraction, 0, i, j);
                    let (ox, oy) = (a[0] as i64 + oi as i64 * d, a[1] as i64 + oj as i64 * d);
                    let owner_traced =
                        (0..w).contains(&ox) && (0..h).contains(&oy) && regions.traced(k, ox, oy);
                    match fraction::traces(layer.fraction, 0, i, j) || !owner_traced {
                        true => samples[k] += layer.spp as u64,
                        false => filled += 1,
                    }
                }
            }
        }
    }
    (samples, filled)
}

/// Regular rendering at 2 spp, half of the pixels traced per frame.
fn fractional_config_regular() -> FoveationConfig {
    let mut config = FoveationConfig::regular(2);
    config.layers[0].fraction = 2;
    config
}

/// The two layers with the fovea tracing half its points and the background a quarter.
fn fractional_config() -> FoveationConfig {
    let mut config = two_layer_config();
    config.layers[0].fraction = 2;
    config.layers[1].fraction = 4;
    config
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
        ("fractions", fractional_config()),
        ("regular at half", fractional_config_regular()),
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
                    .frame(
                        &request(size, 3, config, &eyes, DebugView::None),
                        FrameOptions::pixels(),
                    )
                    .map(Option::unwrap)
                    .unwrap();
                let images = images(&eyes, size);
                let gazes: Vec<[f64; 2]> = eyes
                    .iter()
                    .zip(&images)
                    .map(|(e, image)| e.gaze.resolve(image).0)
                    .collect();
                let used: Vec<[f64; 2]> = frame.gazes.iter().map(|g| g.0).collect();
                assert_eq!(used, gazes, "{what}: gaze pixels");
                let (expected, filled) = brute_force_layer_samples(config, &images, &gazes);
                assert_eq!(frame.stats.filled_points, filled, "{what}: filled points");
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
                        .0
                        .iter()
                        .sum();
                    assert_eq!(counted.paths, own, "{what}: GPU-counted paths of eye {e}");
                    assert!(counted.rays >= counted.paths, "{what}: eye {e} rays");
                }
                assert!(total > 0, "{what}: nothing traced");
                assert_eq!(frame.stats.nonfinite_samples, 0, "{what}");
                assert_eq!(frame.stats.stack_overflows, 0, "{what}");
                let pixels = (size.0 * size.1) as u64 * eyes.len() as u64;
                if *name == "regular" {
                    assert_eq!(total, pixels * 2, "{what}: regular traces every pixel");
                }
                if *name == "regular at half" {
                    // A checkerboard, whose every skipped point's left neighbour is traced
                    // but in column 0: those are traced too.
                    let column_0 = (size.1 as u64 / 2) * eyes.len() as u64;
                    assert_eq!(
                        total,
                        (pixels / 2 + column_0) * 2,
                        "{what}: half of it traced"
                    );
                    assert_eq!(
                        filled,
                        pixels / 2 - column_0,
                        "{what}: the other half filled"
                    );
                }
                if *name == "fractions" {
                    assert!(filled > 0, "{what}: nothing filled");
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

#[test]
fn a_fractional_frame_traces_its_pattern_and_fills_the_rest_from_it() {
    // Regular rendering with half or a quarter of the pixels traced, against every pixel
    // traced with the same seed: a traced pixel is the same samples (the sampler's numbers
    // depend on the pixel, spp and seed only), a skipped one the mean of its traced 3x3
    // neighbours (Catmull-Rom resolve at a lattice point is the point's value).
    let ctx = common::context();
    let size = (48, 40);
    let scene = builtin("cornell", size.0 as f32 / size.1 as f32).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let eyes = eyes(
        &scene,
        size,
        FovChoice::Scene,
        false,
        Gaze::Forward,
        Gaze::Forward,
    );
    let full_config = FoveationConfig::regular(2);
    let render = |renderer: &mut Renderer, config: &FoveationConfig| {
        let request = request(size, 5, config, &eyes, DebugView::None);
        renderer
            .frame(&request, FrameOptions::pixels())
            .map(Option::unwrap)
            .unwrap()
    };
    let full = render(&mut renderer, &full_config);
    for fraction in [2u32, 4] {
        let mut config = full_config.clone();
        config.layers[0].fraction = fraction;
        let part = render(&mut renderer, &config);
        let (mut traced, mut filled) = (0u64, 0u64);
        for y in 0..size.1 as i32 {
            for x in 0..size.0 as i32 {
                let got = part.pixel(x as u32, y as u32);
                let [ox, oy] = fraction::owner(fraction, 0, x, y);
                let skipped = !fraction::traces(fraction, 0, x, y) && ox >= 0 && oy >= 0;
                if !skipped {
                    traced += 1;
                    assert_eq!(
                        got,
                        full.pixel(x as u32, y as u32),
                        "{fraction}: traced {x},{y}"
                    );
                    continue;
                }
                filled += 1;
                let mut sum = [0.0f32; 3];
                let mut n = 0.0f32;
                for (dx, dy) in (0..9).map(|i| (i % 3 - 1, i / 3 - 1)) {
                    let (qx, qy) = (x + dx, y + dy);
                    let inside =
                        (0..size.0 as i32).contains(&qx) && (0..size.1 as i32).contains(&qy);
                    if (dx, dy) == (0, 0) || !inside || !fraction::traces(fraction, 0, qx, qy) {
                        continue;
                    }
                    let v = full.pixel(qx as u32, qy as u32);
                    (0..3).for_each(|c| sum[c] += v[c]);
                    n += 1.0;
                }
                assert!(n >= 1.0, "{fraction}: {x},{y} has no traced neighbour");
                for c in 0..3 {
                    let want = sum[c] / n;
                    assert!(
                        (got[c] - want).abs() <= 1e-5 * want.abs().max(1.0),
                        "{fraction}: filled {x},{y} channel {c}: {} against {want}",
                        got[c]
                    );
                }
            }
        }
        assert_eq!(
            part.stats.filled_points, filled,
            "{fraction}: filled points"
        );
        assert_eq!(part.stats.paths, traced * 2, "{fraction}: traced paths");
        assert!(
            traced * fraction as u64 <= 2 * (size.0 * size.1) as u64,
            "{fraction}: {traced}"
        );
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
            .frame(
                &request(size, seed, &config, &eyes, DebugView::None),
                FrameOptions::pixels(),
            )
            .map(Option::unwrap)
            .unwrap();
        let reference = renderer
            .frame(
                &request(size, seed, &regular, &eyes, DebugView::None),
                FrameOptions::pixels(),
            )
            .map(Option::unwrap)
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
        .frame(
            &request(size, seed, &config, &eyes, DebugView::None),
            FrameOptions::pixels(),
        )
        .map(Option::unwrap)
        .unwrap();
    let reference = renderer
        .frame(
            &request(size, seed, &regular, &eyes, DebugView::None),
            FrameOptions::pixels(),
        )
        .map(Option::unwrap)
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

/// A deterministic value in [0, 1) for channel `c` of a lattice point.
fn point_value(p: LatticePoint, c: usize) -> f32 {
    let mut h = (p.eye as u64) << 56 ^ (p.layer as u64) << 48 ^ (c as u64) << 40;
    h ^= ((p.x as i64 as u64) & 0xfffff) << 20 ^ ((p.y as i64 as u64) & 0xfffff);
    h = h.wrapping_mul(0x9E3779B97F4A7C15);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58476D1CE4E5B9);
    ((h >> 40) as f32) / (1u64 << 24) as f32
}

/// A mask hiding a triangle over the top-left corner and one over the right edge.
fn lens_mask(image: &ImageGeometry) -> VisibilityMask {
    let (w, h) = (image.width as f64, image.height as f64);
    let corner = |x: f64, y: f64| {
        let t = image.tan_of(x, y);
        [t[0] as f32, t[1] as f32]
    };
    let vertices = [
        corner(-1.0, -1.0),
        corner(0.6 * w, -1.0),
        corner(-1.0, 0.6 * h),
        corner(w + 1.0, 0.2 * h),
        corner(0.8 * w, 0.6 * h),
        corner(w + 1.0, h + 1.0),
    ];
    VisibilityMask::from_hidden_triangles(image, &vertices, &[0, 1, 2, 3, 4, 5])
}

/// What the CPU says resolve writes at pixel (x, y) of one eye: eq. 3.18's blend of the
/// innermost layer containing the pixel with the next one out, each layer's value the
/// Catmull-Rom of eq. 3.17 over its lattice; black outside the occlusion mask and where the
/// lens hides the pixel. `None` within a hair of an edge where f32 and f64 may choose
/// differently. Also returns the blend's own uncertainty: |F1 - F0| times the error of the
/// GPU's f32 angle (pixel tangent, normalisation and atan2 together: 2e-6 rad bounds it at
/// these fields of view) over the band.
#[allow(clippy::too_many_arguments)]
fn expected_pixel(
    config: &FoveationConfig,
    image: &ImageGeometry,
    gaze_px: [f64; 2],
    plan: &EyePlan,
    mask: Option<&VisibilityMask>,
    value: &dyn Fn(usize, i32, i32, usize) -> f32,
    x: i32,
    y: i32,
) -> Option<([f32; 3], f32)> {
    const HAIR: f64 = 1e-5;
    let t = image.pixel_centre_tan(x as i64, y as i64);
    let theta = angle_between(t, image.tan_of(gaze_px[0], gaze_px[1]));
    let axis = angle_between(t, [0.0, 0.0]);
    let occlusion = config
        .occlusion_deg
        .map_or(f64::INFINITY, |o| (o as f64).to_radians());
    if (axis - occlusion).abs() < HAIR {
        return None;
    }
    if axis >= occlusion || mask.is_some_and(|m| !m.visible(x as u32, y as u32)) {
        return Some(([0.0; 3], 0.0));
    }
    let band = (config.blend_deg as f64).to_radians();
    let radius = |k: usize| {
        config.layers[k]
            .radius_deg
            .map_or(f64::INFINITY, |r| (r as f64).to_radians())
    };
    let last = config.layers.len() - 1;
    let k = (0..last).find(|&k| theta < radius(k)).unwrap_or(last);
    for edge in (0..last).flat_map(|k| [radius(k), radius(k) - band]) {
        if (theta - edge).abs() < HAIR {
            return None;
        }
    }
    let layer_value = |k: usize, c: usize| {
        let p = &plan.layers[k];
        let lattice = Lattice {
            anchor: p.anchor,
            spacing: config.layers[k].spacing as i32,
            min: p.lattice_min,
            max: p.lattice_max,
        };
        lattice.interpolate(x, y, |x, y| value(k, x, y, c))
    };
    let v = weight(theta, radius(k), band) as f32;
    let mut rgb = [0.0f32; 3];
    let mut spread = 0.0f32;
    for (c, out) in rgb.iter_mut().enumerate() {
        let inner = layer_value(k, c);
        *out = match v < 1.0 && k < last {
            true => {
                let outer = layer_value(k + 1, c);
                spread = spread.max((inner - outer).abs() * (2e-6 / band) as f32);
                outer * (1.0 - v) + inner * v
            }
            false => inner,
        };
    }
    Some((rgb, spread))
}

/// One resolve case: a config, a scene's eyes, the image size and whether a lens mask hides
/// part of each eye.
struct ResolveCase {
    name: &'static str,
    config: FoveationConfig,
    fov: FovChoice,
    stereo: bool,
    gazes: (Gaze, Gaze),
    size: (u32, u32),
    lens: bool,
}

fn resolve_cases() -> Vec<ResolveCase> {
    let background = FoveationConfig {
        layers: vec![Layer {
            radius_deg: None,
            spacing: 3,
            spp: 1,
            denoise: 0,
            filter_mar: 0.0,
            filter_px: 0.0,
            denoise_mar: 0.0,
            denoise_sigma: DEFAULT_DENOISE_SIGMA,
            fraction: 1,
        }],
        blend_deg: 1.0,
        occlusion_deg: None,
    };
    let mut unmasked = FoveationConfig::thesis();
    unmasked.occlusion_deg = None;
    let case = |name, config: &FoveationConfig, fov, stereo, gazes, size, lens| ResolveCase {
        name,
        config: config.clone(),
        fov,
        stereo,
        gazes,
        size,
        lens,
    };
    let (fwd, corner) = (Gaze::Forward, Gaze::Corner);
    let off_screen = Gaze::Pixel(-500.0, 10_000.0);
    let vive = FovChoice::ViveProEye;
    let scene = FovChoice::Scene;
    vec![
        case(
            "background spacing 3",
            &background,
            scene,
            false,
            (fwd, fwd),
            (65, 49),
            false,
        ),
        case(
            "two layers",
            &two_layer_config(),
            scene,
            false,
            (corner, corner),
            (63, 51),
            false,
        ),
        case(
            "thesis without occlusion",
            &unmasked,
            scene,
            false,
            (fwd, fwd),
            (97, 81),
            false,
        ),
        case(
            "thesis stereo",
            &unmasked,
            vive,
            true,
            (fwd, Gaze::Pixel(10.3, 60.7)),
            (63, 73),
            false,
        ),
        case(
            "thesis stereo, lens",
            &FoveationConfig::thesis(),
            vive,
            true,
            (corner, Gaze::Pixel(40.0, 20.0)),
            (65, 71),
            true,
        ),
        case(
            "thesis, off-screen gaze, lens",
            &FoveationConfig::thesis(),
            vive,
            false,
            (off_screen, off_screen),
            (61, 67),
            true,
        ),
        case(
            "two layers, lens",
            &two_layer_config(),
            vive,
            true,
            (fwd, corner),
            (64, 72),
            true,
        ),
    ]
}

#[test]
fn gpu_resolve_equals_the_cpu_blend_of_catmull_rom_layers() {
    let ctx = common::context();
    let scene = builtin("control", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    for case in resolve_cases() {
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
        let mut masks: Vec<VisibilityMask> = match case.lens {
            true => images.iter().map(lens_mask).collect(),
            false => Vec::new(),
        };
        renderer.set_visibility_masks(masks.clone());
        let req = request(size, 1, &case.config, &eyes, DebugView::None);
        let buffer = RayBuffer::build(&case.config, &images);
        for m in &mut masks {
            for l in &case.config.layers {
                m.prepare(l.spacing);
            }
        }

        // Random data: every pixel is the CPU's blend of Catmull-Rom layers.
        let frame = renderer
            .compose(&req, |p| [0, 1, 2, 3].map(|c| point_value(p, c)))
            .unwrap();
        let mut checked = 0;
        for (e, image) in images.iter().enumerate() {
            let gaze_px = frame.gazes[e].0;
            let mask = masks.get(e);
            let plan = EyePlan::masked(&buffer, image, gaze_px, mask);
            let value = |layer, x, y, c| {
                point_value(
                    LatticePoint {
                        eye: e,
                        layer,
                        x,
                        y,
                    },
                    c,
                )
            };
            for y in 0..h {
                for x in 0..w {
                    let Some((want, spread)) =
                        expected_pixel(&case.config, image, gaze_px, &plan, mask, &value, x, y)
                    else {
                        continue;
                    };
                    let got = frame.pixel(x as u32 + e as u32 * size.0, y as u32);
                    for c in 0..3 {
                        let tolerance = 1e-5 * want[c].abs().max(1.0) + spread;
                        assert!(
                            (got[c] - want[c]).abs() <= tolerance,
                            "{}: eye {e} pixel ({x}, {y}) channel {c}: GPU {} CPU {}",
                            case.name,
                            got[c],
                            want[c]
                        );
                    }
                    checked += 1;
                }
            }
        }
        let pixels = (w * h) as usize * eyes.len();
        assert!(
            checked * 10 > pixels * 9,
            "{}: only {checked} of {pixels} pixels checked",
            case.name
        );

        // A linear gradient on every layer's lattice: Catmull-Rom reproduces it and blending
        // equal layers changes nothing, so every shown pixel two lattice steps from the
        // image's border is the gradient itself (no CPU interpolation involved).
        let coefficients = [
            [0.011, 0.004, 0.5],
            [-0.003, 0.009, 1.5],
            [0.006, -0.007, 2.0],
        ];
        let f = |x: i32, y: i32, c: usize| {
            let [a, b, z] = coefficients[c];
            a * x as f32 + b * y as f32 + z
        };
        let frame = renderer
            .compose(&req, |p| {
                [f(p.x, p.y, 0), f(p.x, p.y, 1), f(p.x, p.y, 2), 1.0]
            })
            .unwrap();
        let margin = 2 * case
            .config
            .layers
            .iter()
            .map(|l| l.spacing as i32)
            .max()
            .unwrap();
        let mut gradient = 0;
        for (e, image) in images.iter().enumerate() {
            let gaze_px = frame.gazes[e].0;
            let plan = EyePlan::masked(&buffer, image, gaze_px, masks.get(e));
            let value = |_: usize, x: i32, y: i32, c: usize| f(x, y, c);
            for y in margin..h - margin {
                for x in margin..w - margin {
                    let shown = expected_pixel(
                        &case.config,
                        image,
                        gaze_px,
                        &plan,
                        masks.get(e),
                        &value,
                        x,
                        y,
                    );
                    if shown.is_none_or(|(rgb, _)| rgb == [0.0; 3]) {
                        continue;
                    }
                    let got = frame.pixel(x as u32 + e as u32 * size.0, y as u32);
                    for (c, got) in got.into_iter().enumerate() {
                        let want = f(x, y, c);
                        assert!(
                            (got - want).abs() <= 1e-4 * want.abs(),
                            "{}: eye {e} pixel ({x}, {y}) channel {c}: {got} vs {want}",
                            case.name
                        );
                    }
                    gradient += 1;
                }
            }
        }
        assert!(gradient > 0, "{}: no interior pixel shown", case.name);

        // The GPU traces exactly the points the CPU planner plans, lens mask included.
        let traced = renderer
            .frame(&req, FrameOptions::pixels())
            .map(Option::unwrap)
            .unwrap();
        let planned: Vec<u64> = (0..case.config.layers.len())
            .map(|k| {
                images
                    .iter()
                    .enumerate()
                    .map(|(e, image)| {
                        let plan = EyePlan::masked(&buffer, image, traced.gazes[e].0, masks.get(e));
                        plan.layers[k].targets * case.config.layers[k].spp as u64
                    })
                    .sum()
            })
            .collect();
        assert_eq!(
            traced.stats.layer_samples, planned,
            "{}: traced per layer",
            case.name
        );
    }
    renderer.set_visibility_masks(Vec::new());
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
    // The inner layer is the gradient, the outer one the gradient plus the difference.
    let input = |p: LatticePoint| {
        let v = 0.3 + gx * p.x as f32 + gy * p.y as f32 + difference * p.layer as f32;
        [v, v, v, 1.0]
    };
    let config = |blend_deg: f32| FoveationConfig {
        layers: vec![
            Layer {
                radius_deg: Some(10.0),
                spacing: 1,
                spp: 1,
                denoise: 0,
                filter_mar: 0.0,
                filter_px: 0.0,
                denoise_mar: 0.0,
                denoise_sigma: DEFAULT_DENOISE_SIGMA,
                fraction: 1,
            },
            Layer {
                radius_deg: None,
                spacing: 1,
                spp: 1,
                denoise: 0,
                filter_mar: 0.0,
                filter_px: 0.0,
                denoise_mar: 0.0,
                denoise_sigma: DEFAULT_DENOISE_SIGMA,
                fraction: 1,
            },
        ],
        blend_deg,
        occlusion_deg: None,
    };
    for gaze in [Gaze::Forward, Gaze::Pixel(30.5, 90.2)] {
        let eyes = eyes(&scene, size, FovChoice::Scene, false, gaze, gaze);
        let image = eyes[0].image(size.0, size.1);

        let blended = config(2.0);
        let frame = renderer
            .compose(&request(size, 1, &blended, &eyes, DebugView::None), input)
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
        let frame = renderer
            .compose(&request(size, 1, &hard, &eyes, DebugView::None), input)
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
            .frame(
                &request(size, 9, &config, &eyes, DebugView::None),
                FrameOptions::pixels(),
            )
            .map(Option::unwrap)
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
        .frame(
            &request(size, 2, &config, &eyes, DebugView::None),
            FrameOptions::pixels(),
        )
        .map(Option::unwrap)
        .unwrap();
    let debug = renderer
        .frame(
            &request(size, 2, &config, &eyes, DebugView::Layers),
            FrameOptions::pixels(),
        )
        .map(Option::unwrap)
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
