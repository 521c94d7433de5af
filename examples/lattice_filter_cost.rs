//! What the lattice filter (glsl/lattice_filter.comp) costs against the trace it filters: GPU
//! milliseconds of the "trace" and "lattice filter" passes (timestamps), the median of 8
//! frames after 2 of warm-up, with history on, the gaze ahead, on cornell, bunny-high and
//! assets/gltf/textured-room.glb. Two configs per scene:
//! - uniform: one layer of spacing 2 whose every point is filtered (filter_px = 2), so the
//!   ratio is the filter's cost against the trace of exactly the points it filters;
//! - thesis: the thesis' layers, the three sparse ones filtered by acuity (filter_mar = 1),
//!   the fovea copied; the ratio is against the whole trace.
//!
//!   cargo run --release --example lattice_filter_cost -- [--width W] [--height H]
//!   [--spp N] [--sampler independent|zsobol]

use std::sync::Arc;

use fovea::foveation::{FoveationConfig, Gaze};
use fovea::gpu::{GpuContext, GpuOptions};
use fovea::render::{
    DebugView, EyeView, FrameOptions, FrameRequest, Integrator, RenderSettings, Renderer,
    TemporalSettings,
};
use shared::arg;

mod shared;

/// Frames timed after the warm-up.
const TIMED: usize = 8;
const WARM_UP: usize = 2;

fn uniform_filtered(spp: u32) -> FoveationConfig {
    let mut config = FoveationConfig::regular(spp);
    config.layers[0].spacing = 2;
    config.layers[0].filter_px = 2.0;
    config
}

fn thesis_filtered(spp: u32) -> FoveationConfig {
    let mut config = FoveationConfig::thesis().with_spp(spp);
    for layer in config.layers.iter_mut().skip(1) {
        layer.filter_mar = 1.0;
    }
    config
}

/// Median GPU ms of the trace and of the lattice filter over [`TIMED`] frames.
fn pass_costs(
    renderer: &mut Renderer,
    settings: &RenderSettings,
    config: &FoveationConfig,
    eyes: &[EyeView],
) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    renderer.reset_history();
    let (mut trace, mut filter) = (Vec::new(), Vec::new());
    for k in 0..WARM_UP + TIMED {
        let request = FrameRequest {
            settings: RenderSettings {
                seed: 1 + k as u32,
                ..*settings
            },
            foveation: config,
            eyes,
            debug: DebugView::None,
        };
        let frame = renderer
            .frame(&request, FrameOptions::measure())?
            .ok_or("no frame")?;
        let ms = |name: &str| {
            let found = frame.stats.pass_ms.iter().find(|(n, _)| n == name);
            found.map_or(0.0, |(_, ms)| *ms)
        };
        if k >= WARM_UP {
            trace.push(ms("trace"));
            filter.push(ms("lattice filter"));
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    Ok((median(trace), median(filter)))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    shared::choose_sampler()?;
    let (width, height, spp) = (arg("--width", 720), arg("--height", 800), arg("--spp", 1));
    let ctx = Arc::new(GpuContext::new(&GpuOptions::default())?);
    println!("{width}×{height}, {spp} spp, history on; median of {TIMED} frames, GPU ms");
    println!("| scene | config | trace | lattice filter | filter ÷ trace |");
    println!("|---|---|---:|---:|---:|");
    let room = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/gltf/textured-room.glb");
    for name in ["cornell", "bunny-high", room] {
        let scene = fovea::scene::load(name, width as f32 / height as f32)?;
        let mut renderer = Renderer::new(&ctx, &scene)?;
        renderer.set_temporal(Some(TemporalSettings::default()))?;
        let settings = RenderSettings {
            sampler: fovea::render::Sampler::chosen(),
            width,
            height,
            spp,
            seed: 1,
            integrator: Integrator::Pt,
            max_bounces: 8,
        };
        let eyes = [EyeView {
            camera: scene.camera,
            gaze: Gaze::Forward,
        }];
        for (label, config) in [
            ("uniform, spacing 2, filter_px 2", uniform_filtered(spp)),
            ("thesis, sparse layers filter_mar 1", thesis_filtered(spp)),
        ] {
            let (trace, filter) = pass_costs(&mut renderer, &settings, &config, &eyes)?;
            println!(
                "| {name} | {label} | {trace:.2} | {filter:.2} | {:.3} |",
                filter / trace
            );
        }
    }
    Ok(())
}
