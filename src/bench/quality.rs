//! Image quality beside speed: each mode's image against a converged reference of the same
//! view (regular rendering at many spp, cached on disk), over the whole image and per
//! eccentricity band around the gaze, as MSE, relMSE, PSNR and FLIP.

use super::error::BenchError;
use super::protocol::{BenchPlan, Mode};
use super::rows::{QualityRow, EYE_NAMES};
use crate::foveation::FoveationConfig;
use crate::metrics::jod::Fvvdp;
use crate::metrics::{self, hidden_black, visible_pixels, BANDS};
use crate::render::FrameOptions;
use crate::render::{DebugView, EyeView, Frame, FrameRequest, RenderSettings, Renderer};
use crate::scene::fingerprint::Fingerprint;
use std::path::{Path, PathBuf};

/// Samples per pixel of one reference pass. The reference is the mean of several passes
/// with different seeds, so no single dispatch runs long enough to trip a GPU watchdog.
const REFERENCE_CHUNK_SPP: u32 = 32;

/// Settings of a frame of the plan at `spp` samples per pixel.
pub fn settings(plan: &BenchPlan, spp: u32) -> RenderSettings {
    RenderSettings {
        sampler: crate::render::Sampler::chosen(),
        width: plan.width,
        height: plan.height,
        spp,
        seed: plan.seed,
        integrator: plan.integrator,
        max_bounces: plan.max_bounces,
    }
}

/// Everything that changes a converged reference, for its cache file's name.
#[derive(Clone, Copy)]
pub struct ReferenceKey<'a> {
    pub scene: &'a str,
    /// The scene as uploaded ([`Renderer::scene_fingerprint`]): an edited scene file or
    /// built-in under the same name.
    pub scene_contents: u64,
    /// [`crate::render::renderer_version`]: a changed integrator or shader.
    pub renderer: u64,
    /// Size, integrator, bounces, seed, reference spp.
    pub plan: &'a BenchPlan,
    /// Each eye's camera: pose and field of view.
    pub eyes: &'a [EyeView],
}

impl<'a> ReferenceKey<'a> {
    /// The key of `renderer`'s scene under `plan`, seen by `eyes`.
    pub fn new(
        renderer: &Renderer,
        plan: &'a BenchPlan,
        scene: &'a str,
        eyes: &'a [EyeView],
    ) -> Self {
        Self {
            scene,
            scene_contents: renderer.scene_fingerprint(),
            renderer: crate::render::renderer_version(),
            plan,
            eyes,
        }
    }

    /// The cached reference's path in `cache`: what a reader needs to tell files apart, then
    /// a fingerprint of the whole key.
    pub fn path(&self, cache: &Path) -> PathBuf {
        let p = self.plan;
        let cameras = self.eyes.iter().flat_map(|e| {
            let c = &e.camera;
            [c.position.to_array(), c.forward.to_array(), c.up.to_array()]
                .into_iter()
                .flatten()
                .chain([c.angle_left, c.angle_right, c.angle_up, c.angle_down])
        });
        let key = Fingerprint::default()
            .u64(self.scene_contents)
            .u64(self.renderer)
            .bytes(super::protocol::flag_value(&p.integrator).as_bytes())
            .u64(p.max_bounces as u64)
            .u64(p.seed as u64)
            .u64(p.reference_spp as u64)
            .u64(p.width as u64)
            .u64(p.height as u64)
            .f32s(cameras)
            .value();
        cache.join(format!(
            "{}-{}x{}x{}-{}spp-{key:016x}.exr",
            self.scene,
            p.width,
            p.height,
            self.eyes.len(),
            p.reference_spp
        ))
    }
}

/// The converged image of `eyes` (side by side, linear RGB): read from `path` (in the cache,
/// see [`ReferenceKey`]), or rendered and written there. `progress` hears about each pass
/// rendered.
pub fn reference_image(
    renderer: &mut Renderer,
    plan: &BenchPlan,
    scene: &str,
    eyes: &[EyeView],
    path: &Path,
    progress: &mut dyn FnMut(u32, u32),
) -> Result<Vec<f32>, BenchError> {
    let (width, height) = (plan.width * eyes.len() as u32, plan.height);
    if let Some(rgb) = read_exr(path, width, height) {
        return Ok(rgb);
    }
    let passes = plan.reference_spp.div_ceil(REFERENCE_CHUNK_SPP);
    let mut sum = vec![0.0f64; (width * height * 3) as usize];
    for pass in 0..passes {
        let spp = REFERENCE_CHUNK_SPP.min(plan.reference_spp - pass * REFERENCE_CHUNK_SPP);
        let config = FoveationConfig::regular(spp);
        // Seeds far from the plan's: the reference must not share random numbers with the
        // images it judges.
        let settings = RenderSettings {
            seed: plan.seed.wrapping_add(0x5eed_0000).wrapping_add(pass),
            ..settings(plan, spp)
        };
        let frame = renderer
            .frame(
                &FrameRequest {
                    settings,
                    foveation: &config,
                    eyes,
                    debug: DebugView::None,
                },
                FrameOptions::pixels(),
            )
            .map(Option::unwrap)
            .map_err(BenchError::render(scene))?;
        for (s, v) in sum.iter_mut().zip(&frame.rgb) {
            *s += *v as f64 * spp as f64;
        }
        progress(pass + 1, passes);
    }
    let rgb: Vec<f32> = sum
        .iter()
        .map(|s| (s / plan.reference_spp as f64) as f32)
        .collect();
    if let Some(cache) = path.parent() {
        std::fs::create_dir_all(cache).map_err(|e| BenchError::file(cache, e))?;
    }
    // Written under a temporary name and moved, so a kill never leaves half a reference.
    let partial = path.with_extension("partial.exr");
    crate::render::output::write_rgb_exr(&partial, width, height, &rgb)
        .map_err(|e| BenchError::file(&partial, e))?;
    std::fs::rename(&partial, path).map_err(|e| BenchError::file(path, e))?;
    Ok(rgb)
}

/// A cached reference, if there is one of the right size that reads.
fn read_exr(path: &Path, width: u32, height: u32) -> Option<Vec<f32>> {
    if !path.exists() {
        return None;
    }
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0.0f32; size.width() * size.height() * 3]),
        |(w, rgb), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * *w + pos.x());
            rgb[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    );
    match image {
        Ok(image) => {
            let size = image.layer_data.size;
            let (_, rgb) = image.layer_data.channel_data.pixels;
            if size.width() == width as usize && size.height() == height as usize {
                Some(rgb)
            } else {
                tracing::warn!(
                    "{}: wrong size {size:?}; rendering it again",
                    path.display()
                );
                None
            }
        }
        Err(e) => {
            tracing::warn!("{}: unreadable ({e}); rendering it again", path.display());
            None
        }
    }
}

/// One eye's image out of a side-by-side frame.
pub fn eye_image(rgb: &[f32], eyes: u32, width: u32, height: u32, eye: u32) -> Vec<f32> {
    let row = (3 * width * eyes) as usize;
    let (start, len) = ((3 * width * eye) as usize, (3 * width) as usize);
    (0..height as usize)
        .flat_map(|y| rgb[y * row + start..y * row + start + len].iter().copied())
        .collect()
}

/// What one (scene, mode, spp) point of the sweep measured.
pub struct Point {
    pub rows: Vec<QualityRow>,
    /// The left eye's image and its FLIP map, for the side-by-side pictures.
    pub left_rgb: Vec<f32>,
    pub left_flip: Vec<f32>,
}

/// Times `mode` at `spp` (median frame GPU ms over the plan's sweep frames) and compares one
/// image of it with the reference, eye by eye (and with FovVideoVDP, when given `metric`).
#[allow(clippy::too_many_arguments)]
pub fn measure_point(
    renderer: &mut Renderer,
    plan: &BenchPlan,
    scene: &str,
    mode: Mode,
    spp: u32,
    eyes: &[EyeView],
    reference: &[f32],
    mut metric: Option<&mut Fvvdp>,
) -> Result<Point, BenchError> {
    let config = plan.config(mode, spp);
    let request = FrameRequest {
        settings: settings(plan, spp),
        foveation: &config,
        eyes,
        debug: DebugView::None,
    };
    let frame = renderer
        .frame(&request, FrameOptions::pixels())
        .map(Option::unwrap)
        .map_err(BenchError::render(scene))?;
    let frame_gpu_ms = median_gpu_ms(renderer, plan, scene, &request)?;
    let at = PointAt {
        scene,
        mode,
        spp,
        eyes: eyes.len() as u32,
        frame_gpu_ms,
    };
    let mut point = Point {
        rows: Vec::new(),
        left_rgb: Vec::new(),
        left_flip: Vec::new(),
    };
    for (e, eye) in eyes.iter().enumerate() {
        let judged = judge_eye(plan, &at, &frame, reference, e, eye, metric.as_deref_mut())?;
        point.rows.extend(judged.rows);
        if e == 0 {
            point.left_rgb = judged.test;
            point.left_flip = judged.flip_map;
        }
    }
    Ok(point)
}

/// The median GPU time of the plan's sweep frames of `request`.
fn median_gpu_ms(
    renderer: &mut Renderer,
    plan: &BenchPlan,
    scene: &str,
    request: &FrameRequest,
) -> Result<f64, BenchError> {
    let mut gpu_ms = Vec::new();
    for _ in 0..plan.sweep_frames {
        let timed = renderer
            .frame(request, FrameOptions::measure())
            .map(Option::unwrap)
            .map_err(BenchError::render(scene))?;
        gpu_ms.push(timed.stats.gpu_ms());
    }
    Ok(super::stats::summarize(&gpu_ms).map_or(f64::NAN, |s| s.median))
}

/// Which point of the sweep an eye's rows belong to, and its time.
struct PointAt<'a> {
    scene: &'a str,
    mode: Mode,
    spp: u32,
    /// Eyes side by side in the frame.
    eyes: u32,
    frame_gpu_ms: f64,
}

/// One eye of a point, judged: its rows (whole image, then each band), and its image and
/// FLIP map.
struct JudgedEye {
    rows: Vec<QualityRow>,
    test: Vec<f32>,
    flip_map: Vec<f32>,
}

/// Compares eye `e` of `frame` with the reference inside the lens: error and FLIP over the
/// whole image and per band around the eye's gaze, and JOD of the whole image.
fn judge_eye(
    plan: &BenchPlan,
    at: &PointAt,
    frame: &Frame,
    reference: &[f32],
    e: usize,
    eye: &EyeView,
    metric: Option<&mut Fvvdp>,
) -> Result<JudgedEye, BenchError> {
    let n = at.eyes;
    let (width, height) = (plan.width, plan.height);
    let image = eye.image(width, height);
    let visible = visible_pixels(&image, plan.foveation.occlusion_deg);
    let test = hidden_black(eye_image(&frame.rgb, n, width, height, e as u32), &visible);
    let truth = hidden_black(eye_image(reference, n, width, height, e as u32), &visible);
    // FLIP and FovVideoVDP judge what the display shows (the scene's display transform).
    let display = plan.display.transform(at.scene);
    let flip = metrics::flip_shown(
        &truth,
        &test,
        width,
        height,
        metrics::pixels_per_degree(&image),
        &display,
    )?;
    let whole = metrics::image_error(&truth, &test, width, height, Some(&visible))?;
    let gaze = frame.gazes[e].0;
    let jod = match metric {
        Some(m) => Some(m.image(&test, &truth, &image, gaze, &display)?),
        None => None,
    };
    let row = |region: &str, error: metrics::ImageError, flip: f64| QualityRow {
        scene: at.scene.to_string(),
        mode: at.mode,
        spp: at.spp,
        eye: EYE_NAMES[e].to_string(),
        region: region.to_string(),
        pixels: error.pixels,
        mse: error.mse,
        rel_mse: error.rel_mse,
        psnr_db: error.psnr_db,
        flip,
        frame_gpu_ms: at.frame_gpu_ms,
        jod: None,
    };
    let mut rows = vec![QualityRow {
        jod,
        ..row(
            "whole",
            whole,
            metrics::flip_masked_mean(&flip.map, &visible)?,
        )
    }];
    // Regular frames are foveated around the view axis too (their gaze is "forward"),
    // so their bands are the forward mode's.
    let masks = metrics::band_masks(&image, gaze)?;
    for (band, mut mask) in BANDS.iter().zip(masks) {
        for (m, v) in mask.iter_mut().zip(&visible) {
            *m &= v;
        }
        let error = metrics::image_error(&truth, &test, width, height, Some(&mask))?;
        let flip = metrics::flip_masked_mean(&flip.map, &mask)?;
        rows.push(row(band.name, error, flip));
    }
    Ok(JudgedEye {
        rows,
        test,
        flip_map: flip.map,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_eye_comes_out_of_a_side_by_side_frame() {
        // 2 eyes of 2×2: left pixels hold 0..4, right pixels 10..14 (one value per channel).
        let mut rgb = Vec::new();
        for y in 0..2 {
            for eye in 0..2 {
                for x in 0..2 {
                    let v = (eye * 10 + y * 2 + x) as f32;
                    rgb.extend([v, v, v]);
                }
            }
        }
        let right = eye_image(&rgb, 2, 2, 2, 1);
        assert_eq!(right.len(), 12);
        let values: Vec<f32> = right.chunks(3).map(|p| p[0]).collect();
        assert_eq!(values, vec![10.0, 11.0, 12.0, 13.0]);
    }

    /// One eye looking down +z from the origin, gaze forward.
    fn one_eye() -> [EyeView; 1] {
        let camera = crate::scene::Camera::look_at(
            glam::Vec3::ZERO,
            glam::Vec3::Z,
            glam::Vec3::Y,
            60.0,
            1.0,
        );
        [EyeView {
            camera,
            gaze: crate::foveation::Gaze::Forward,
        }]
    }

    /// The key of the built-in control scene under `plan`, seen by `eyes`.
    fn control_key<'a>(plan: &'a BenchPlan, eyes: &'a [EyeView]) -> ReferenceKey<'a> {
        ReferenceKey {
            scene: "control",
            scene_contents: 1,
            renderer: 2,
            plan,
            eyes,
        }
    }

    #[test]
    fn every_setting_of_the_plan_that_changes_the_reference_changes_its_key() {
        let plan = BenchPlan::quick();
        let eyes = one_eye();
        let a = control_key(&plan, &eyes).path(Path::new("c"));
        assert!(
            a.to_str()
                .unwrap()
                .starts_with("c/control-360x400x1-256spp-"),
            "{a:?}"
        );
        let plans = [
            BenchPlan {
                width: 100,
                ..plan.clone()
            },
            BenchPlan {
                height: 100,
                ..plan.clone()
            },
            BenchPlan {
                reference_spp: 512,
                ..plan.clone()
            },
            BenchPlan {
                max_bounces: 2,
                ..plan.clone()
            },
            BenchPlan {
                seed: 2,
                ..plan.clone()
            },
            BenchPlan {
                integrator: crate::render::Integrator::Seed,
                ..plan.clone()
            },
        ];
        for p in &plans {
            assert_ne!(control_key(p, &eyes).path(Path::new("c")), a);
        }
    }

    #[test]
    fn the_scene_renderer_and_cameras_change_the_key_and_the_gaze_does_not() {
        let plan = BenchPlan::quick();
        let eyes = one_eye();
        let key = control_key(&plan, &eyes);
        let a = key.path(Path::new("c"));
        let camera = eyes[0].camera;
        let moved = [EyeView {
            camera: crate::scene::Camera {
                position: camera.position + glam::Vec3::X * 1e-3,
                ..camera
            },
            ..eyes[0]
        }];
        let wider = [EyeView {
            camera: crate::scene::Camera {
                angle_left: camera.angle_left - 0.1,
                ..camera
            },
            ..eyes[0]
        }];
        for changed in [
            ReferenceKey {
                scene_contents: 3,
                ..key
            },
            ReferenceKey { renderer: 3, ..key },
            ReferenceKey {
                eyes: &moved,
                ..key
            },
            ReferenceKey {
                eyes: &wider,
                ..key
            },
        ] {
            assert_ne!(changed.path(Path::new("c")), a);
        }
        // The gaze is not part of a reference.
        let elsewhere = [EyeView {
            gaze: crate::foveation::Gaze::Corner,
            ..eyes[0]
        }];
        assert_eq!(
            ReferenceKey {
                eyes: &elsewhere,
                ..key
            }
            .path(Path::new("c")),
            a
        );
    }
}
