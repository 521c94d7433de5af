//! `fovea xr`: an OpenXR session in the headset (SteamVR on a Vive Pro Eye), the eye tracker
//! moving each eye's foveation; or the same through the simulated headset.

use super::render::args::OnOff;
use super::GpuArgs;
use super::{check_validation_messages, parse_size};
use anyhow::{bail, Result};
use clap::Args;
use fovea::bench::stats::Summary;
use fovea::foveation::gaze_filter::DEFAULT_HOLD_S;
use fovea::foveation::FoveationConfig;
use fovea::render::{DebugView, Integrator, RenderSettings};
use fovea::scene;
use fovea::xr::{
    self, FoveationChoice, RuntimeSource, SessionEnd, SessionRecorder, XrOptions, XrSummary,
};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

#[derive(Args)]
pub struct XrArgs {
    /// A built-in scene (see `fovea scenes`) or a .gltf/.glb file; the headset starts at its
    /// camera.
    #[arg(long, default_value = "cornell")]
    pub scene: String,
    /// End the session cleanly after this many frames (default: run until the runtime or
    /// the user ends it).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Per-eye image size WIDTHxHEIGHT (default: the runtime's recommended size).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<[u32; 2]>,
    /// Foveation layers: auto (the config fovea ships for the headset the runtime reports,
    /// assets/foveation/vive-pro-eye.toml for a Vive Pro Eye, varjo-xr-4.toml for a Varjo XR-4;
    /// the thesis' layers for another),
    /// thesis, off (regular rendering) or a TOML file.
    #[arg(long, default_value = "auto")]
    pub foveation: String,
    /// Samples per target pixel, replacing every layer's.
    #[arg(long)]
    pub spp: Option<u32>,
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    #[arg(long, value_enum, default_value_t = Integrator::Pt)]
    pub integrator: Integrator,
    #[arg(long, default_value_t = 8)]
    pub max_bounces: u32,
    /// Colour each pixel by the layer it comes from.
    #[arg(long, value_parser = ["layers"])]
    pub debug: Option<String>,
    /// Seconds a lost gaze (blink, tracking loss) is held before foveating the centre.
    #[arg(long, default_value_t = DEFAULT_HOLD_S, allow_negative_numbers = true)]
    pub gaze_hold: f64,
    /// Trace every pixel the lens shows, ignoring the runtime's visibility mask.
    #[arg(long)]
    pub no_visibility_mask: bool,
    /// Frames submitted before the CPU waits for the oldest one's GPU work: 2 lets the CPU
    /// plan and record a frame while the GPU runs the one before; 1 renders one frame at a
    /// time (for comparison).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(1..=fovea::render::MAX_FRAMES_IN_FLIGHT as u64))]
    pub frames_in_flight: u64,
    /// Keep a temporal history: every pixel accumulates the samples traced at it, carried by
    /// reprojection as the head moves (see `fovea render --camera-path`). On by default:
    /// `fovea bench --motion` measured it under head turns and saccades to cut error in every
    /// eccentricity band and peripheral flicker 5-12x, at less GPU time than twice the spp
    /// without it (README, "Temporal history under motion").
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub temporal: OnOff,
    /// Use the simulated headset linked into fovea instead of the system's OpenXR runtime
    /// (configured by SIM_HEADSET_* variables, see tools/sim-headset/README.md).
    #[arg(long)]
    pub simulated: bool,
    /// Profile the session into this directory: frames.csv (GPU time of every pass of both
    /// eyes, per frame, as `fovea bench` writes), gaze.csv and session.json.
    #[arg(long, value_name = "DIR")]
    pub session: Option<PathBuf>,
    /// Diagnose the set-up and exit without rendering: runtime, headset, extensions, eye gaze
    /// (offered, supported, delivered), view sizes, refresh rates, swapchain formats and the
    /// Vulkan device, from a session of empty frames.
    #[arg(long, conflicts_with_all = ["session", "record_gaze", "debug"])]
    pub probe: bool,
    /// Save the gaze trace (replay it with `render`/`bench --gaze-trace`).
    #[arg(long, value_name = "FILE")]
    pub record_gaze: Option<PathBuf>,
    #[command(flatten)]
    pub display: super::DisplayArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

pub fn run(args: &XrArgs) -> Result<()> {
    let (settings, foveation) = frame_settings(args)?;
    let aspect = args.size.map_or(0.9, |s| s[0] as f32 / s[1] as f32);
    let scene = scene::load(&args.scene, aspect)?;
    let gpu = args.gpu.options();
    if args.gpu.device.is_some() {
        bail!("--device cannot be used with xr: the OpenXR runtime picks the GPU that drives the headset");
    }
    let mut recorder = SessionRecorder::new(
        &scene.name,
        match &foveation {
            FoveationChoice::Given(config) => !config.is_regular(),
            FoveationChoice::ForHeadset { .. } => true, // a headset's config, or the thesis'
        },
        args.session.as_deref(),
        args.record_gaze.as_deref(),
    )?;
    let stop = stop_on_signals()?;
    let options = XrOptions {
        source: match args.simulated {
            true => RuntimeSource::Simulated,
            false => RuntimeSource::Loader,
        },
        gpu,
        scene,
        size: args.size,
        settings,
        foveation,
        debug: match args.debug.as_deref() {
            Some("layers") => DebugView::Layers,
            _ => DebugView::None,
        },
        frames: args.frames,
        gaze_hold_s: args.gaze_hold,
        visibility_mask: !args.no_visibility_mask,
        probe: args.probe,
        stop,
        frames_in_flight: args.frames_in_flight as usize,
        temporal: (args.temporal == OnOff::On).then(fovea::render::TemporalSettings::default),
        display: args.display.transform(&args.scene),
    };
    if args.probe {
        return probe(args, options);
    }
    let summary = xr::run(options, |record| recorder.frame(record))?;
    let latency = recorder.latency();
    recorder.finish(&summary)?;
    print_session(&summary);
    if latency.frames > 0 {
        print_latency(
            latency.gaze_to_photon_ms,
            latency.latch_ms,
            latency.gpu_done_ms,
            latency.missed_frames,
        );
    }
    if let Some(dir) = &args.session {
        println!("session profile written to {}", dir.display());
    }
    check_validation_messages(&summary.validation)?;
    match summary.end {
        SessionEnd::Lost => bail!(
            "the OpenXR session was lost after {} frames, in {} session(s): fovea started a new \
             one after each loss, up to {} times; everything rendered until then was recorded",
            summary.frames,
            summary.sessions,
            xr::SESSION_RETRIES
        ),
        SessionEnd::Requested | SessionEnd::RuntimeExit => Ok(()),
    }
}

/// The frame settings and layers the options ask for, checked with the same ranges and
/// messages as `fovea render`, before any session starts.
fn frame_settings(args: &XrArgs) -> Result<(RenderSettings, FoveationChoice)> {
    RenderSettings {
        spp: args.spp.unwrap_or(1),
        max_bounces: args.max_bounces,
        ..RenderSettings::default()
    }
    .validate()
    .map_err(anyhow::Error::msg)?;
    let foveation = match args.foveation.as_str() {
        "auto" => FoveationChoice::ForHeadset { spp: args.spp },
        given => {
            let mut foveation = match FoveationConfig::from_arg(given)? {
                Some(config) => config,
                None => FoveationConfig::regular(args.spp.unwrap_or(4)),
            };
            if let Some(spp) = args.spp {
                foveation = foveation.with_spp(spp);
            }
            foveation.validate()?;
            FoveationChoice::Given(foveation)
        }
    };
    let settings = RenderSettings {
        seed: args.seed,
        integrator: args.integrator,
        max_bounces: args.max_bounces,
        ..RenderSettings::default()
    };
    if !args.gaze_hold.is_finite() || args.gaze_hold < 0.0 {
        bail!(
            "--gaze-hold {}: give a number of seconds, 0 or more",
            args.gaze_hold
        );
    }
    if args.frames == Some(0) {
        bail!("--frames 0 renders nothing: give 1 or more, or leave it out to run until stopped");
    }
    Ok((settings, foveation))
}

/// Ctrl+C, SIGTERM, SIGHUP or a closed console window: end the session as --frames does, so
/// the session files are complete. The flag they set.
fn stop_on_signals() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .map_err(|e| anyhow::anyhow!("cannot install the Ctrl+C handler: {e}"))?;
    Ok(stop)
}

/// `--probe`: a session of empty frames, and what it found.
fn probe(args: &XrArgs, options: XrOptions) -> Result<()> {
    let options = XrOptions {
        frames: Some(args.frames.unwrap_or(xr::PROBE_FRAMES)),
        ..options
    };
    let summary = xr::run(options, |_| Ok(()))?;
    if let Some(report) = &summary.probe {
        print!("{report}");
    }
    check_validation_messages(&summary.validation)?;
    match summary.end {
        SessionEnd::Lost => bail!("the OpenXR session was lost while probing"),
        SessionEnd::Requested | SessionEnd::RuntimeExit => Ok(()),
    }
}

/// What ran: runtime, device, size, frames, gaze and mask, and the session's states.
fn print_session(summary: &XrSummary) {
    println!(
        "OpenXR runtime {}; device {}; {}x{} per eye ({}); {} frames; eye gaze: {}; visibility mask: {}",
        summary.runtime,
        summary.device,
        summary.eye_size[0],
        summary.eye_size[1],
        summary.swapchain_format,
        summary.frames,
        match summary.no_gaze {
            Some(_) => "none (fixed centre foveation)",
            None => "from the headset",
        },
        if summary.visibility_mask { "used" } else { "not used" },
    );
    println!("foveation: {}", summary.foveation);
    println!(
        "session states: {}",
        summary
            .states
            .iter()
            .map(|s| format!("{s:?}"))
            .collect::<Vec<_>>()
            .join(" → ")
    );
}

/// The latency line: gaze to photon, when the gaze was latched and the GPU done after
/// xrWaitFrame (median / p99), and the frames missed.
fn print_latency(
    gaze_to_photon_ms: Option<Summary>,
    latch_ms: Option<Summary>,
    gpu_done_ms: Option<Summary>,
    missed_frames: u64,
) {
    let ms = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
    let quantiles = |s: Option<Summary>| (s.map(|s| s.median), s.map(|s| s.p99));
    let g = quantiles(gaze_to_photon_ms);
    let l = quantiles(latch_ms);
    let d = quantiles(gpu_done_ms);
    println!(
        "gaze to photon: median {} ms, p99 {} ms (the runtime's display time minus the gaze \
         sample's); after xrWaitFrame: gaze latched at {} / {} ms, GPU done at {} / {} ms \
         (median / p99); frames missed: {}",
        ms(g.0),
        ms(g.1),
        ms(l.0),
        ms(l.1),
        ms(d.0),
        ms(d.1),
        missed_frames
    );
}
