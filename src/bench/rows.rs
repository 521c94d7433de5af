//! The rows a bench run writes: frames.csv (one per timed frame and eye) and quality.csv (one
//! per scene, mode, spp, eye and image region). Column names are the field names.

use super::protocol::{FrameKey, Mode};
use crate::render::Frame;
use serde::{Deserialize, Serialize};

pub const EYE_NAMES: [&str; 2] = ["left", "right"];

/// One eye of one timed frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameRow {
    pub scene: String,
    pub mode: Mode,
    pub repeat: u32,
    pub frame: u32,
    pub eye: String,
    /// GPU milliseconds of this eye's passes: plan (which lattice points are traced), trace
    /// and resolve.
    pub gpu_plan_ms: f64,
    pub trace_ms: f64,
    pub resolve_ms: f64,
    /// This eye's passes together (the frame's also has the dispatch sizes, both eyes').
    pub eye_gpu_ms: f64,
    /// Both eyes' passes: the frame's GPU time, from which fps is computed.
    pub frame_gpu_ms: f64,
    /// Wall-clock milliseconds of the whole frame on the CPU: planning, recording, submit and
    /// wait (no image read-back).
    pub cpu_ms: f64,
    /// CPU milliseconds planning both eyes (gaze → their layers' parameters).
    pub plan_ms: f64,
    /// CPU milliseconds recording the frame's command buffer (both eyes).
    pub record_ms: f64,
    /// Camera paths and all rays this eye traced, counted on the GPU.
    pub paths: u64,
    pub rays: u64,
    pub nonfinite: u64,
    pub overflows: u64,
    /// The gaze pixel the eye was foveated around (the view axis for regular frames).
    pub gaze_x: f64,
    pub gaze_y: f64,
    /// Wall-clock time the frame was submitted, microseconds since the Unix epoch (places
    /// the frame on the trace timeline, across resumed runs too).
    pub wall_us: u64,
    /// Headset sessions only (empty in bench runs), see [`HeadsetTiming`].
    #[serde(default)]
    pub gaze_to_photon_ms: Option<f64>,
    #[serde(default)]
    pub latch_ms: Option<f64>,
    #[serde(default)]
    pub gpu_done_ms: Option<f64>,
    #[serde(default)]
    pub frame_period_ms: Option<f64>,
    #[serde(default)]
    pub missed_frames: Option<u32>,
    #[serde(default)]
    pub busy_at_submit: Option<u32>,
    /// Headset sessions only: the process's resident memory (Linux; empty elsewhere) and
    /// fovea's GPU memory in use, MiB, after the frame.
    #[serde(default)]
    pub rss_mib: Option<f64>,
    #[serde(default)]
    pub gpu_mib: Option<f64>,
}

/// When a headset frame's work happened and how old its gaze was when it was shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadsetTiming {
    /// The frame's predicted display time minus the time the eye tracker took its gaze
    /// sample (both the runtime's clock): the gaze-to-photon estimate; NaN without a sample.
    pub gaze_to_photon_ms: f64,
    /// CPU ms from the end of xrWaitFrame to the gaze latch (the last thing before the
    /// frame's submission).
    pub latch_ms: f64,
    /// CPU ms from the end of xrWaitFrame to the frame's fence (its GPU work done).
    pub gpu_done_ms: f64,
    /// This frame's predicted display time minus the previous frame's (NaN for the first).
    pub frame_period_ms: f64,
    /// Display periods between the two with no frame of ours (0: none missed).
    pub missed_frames: u32,
    /// Earlier frames still running on the GPU when this one was submitted (frames in
    /// flight overlapping; always 0 with one frame in flight).
    pub busy_at_submit: u32,
}

impl FrameRow {
    /// The row with a headset frame's timing.
    pub fn with_timing(self, t: &HeadsetTiming) -> Self {
        Self {
            gaze_to_photon_ms: t
                .gaze_to_photon_ms
                .is_finite()
                .then_some(t.gaze_to_photon_ms),
            latch_ms: Some(t.latch_ms),
            gpu_done_ms: Some(t.gpu_done_ms),
            frame_period_ms: t.frame_period_ms.is_finite().then_some(t.frame_period_ms),
            missed_frames: Some(t.missed_frames),
            busy_at_submit: Some(t.busy_at_submit),
            ..self
        }
    }

    /// The row with the process's memory after the frame.
    pub fn with_memory(self, rss_mib: Option<f64>, gpu_mib: f64) -> Self {
        Self {
            rss_mib,
            gpu_mib: Some(gpu_mib),
            ..self
        }
    }
}

impl FrameRow {
    pub fn key(&self) -> FrameKey {
        FrameKey {
            scene: self.scene.clone(),
            mode: self.mode,
            repeat: self.repeat,
            frame: self.frame,
        }
    }

    /// One row per eye of `frame`, measured as `key`.
    pub fn from_frame(key: &FrameKey, frame: &Frame, cpu_ms: f64, wall_us: u64) -> Vec<FrameRow> {
        let s = &frame.stats;
        let stereo = s.eyes.len() == 2;
        let pass = |eye: usize, name: &str| -> f64 {
            let full = match stereo {
                true => format!("{} {name}", EYE_NAMES[eye]),
                false => name.to_string(),
            };
            s.pass_ms
                .iter()
                .filter(|(n, _)| *n == full)
                .fold(0.0, |sum, (_, ms)| sum + ms)
        };
        s.eyes
            .iter()
            .enumerate()
            .map(|(e, counters)| {
                let (plan, trace, resolve) =
                    (pass(e, "plan"), pass(e, "trace"), pass(e, "resolve"));
                FrameRow {
                    scene: key.scene.clone(),
                    mode: key.mode,
                    repeat: key.repeat,
                    frame: key.frame,
                    eye: EYE_NAMES[e].to_string(),
                    gpu_plan_ms: plan,
                    trace_ms: trace,
                    resolve_ms: resolve,
                    eye_gpu_ms: plan + trace + resolve,
                    frame_gpu_ms: s.gpu_ms(),
                    cpu_ms,
                    plan_ms: s.plan_ms,
                    record_ms: s.record_ms,
                    paths: counters.paths,
                    rays: counters.rays,
                    nonfinite: counters.nonfinite_samples,
                    overflows: counters.stack_overflows,
                    gaze_x: frame.gazes.get(e).map_or(f64::NAN, |g| g.0[0]),
                    gaze_y: frame.gazes.get(e).map_or(f64::NAN, |g| g.0[1]),
                    wall_us,
                    // The headset's columns stay empty.
                    ..Default::default()
                }
            })
            .collect()
    }
}

/// The error of one eye's image region against the converged reference, at one spp.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QualityRow {
    pub scene: String,
    pub mode: Mode,
    pub spp: u32,
    pub eye: String,
    /// "whole", or an eccentricity band around the mode's gaze ("0-6", "6-10", "10-20",
    /// "20+" degrees; regular frames use the forward gaze's bands). Only pixels the eye can
    /// see count: inside the config's occlusion mask, which foveated frames leave black.
    pub region: String,
    pub pixels: u64,
    pub mse: f64,
    pub rel_mse: f64,
    /// Infinite when the images are identical (written as "inf").
    pub psnr_db: f64,
    /// Mean FLIP (LDR, of the sRGB-encoded image) over the region.
    pub flip: f64,
    /// Median GPU milliseconds of the frame (both eyes) at this spp.
    pub frame_gpu_ms: f64,
    /// FovVideoVDP's JOD of the eye's visible image, foveated at its gaze (10 = as the
    /// reference): "whole" rows only, and only where its venv is (tools/setup-fvvdp.sh).
    #[serde(default)]
    pub jod: Option<f64>,
}

/// One eye's image region in one frame of a motion sequence (motion.csv), against the
/// converged reference of the same frame's pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionRow {
    pub scene: String,
    /// The sequence's name, e.g. "temporal-on-4spp" (see `motion::Sequence`).
    pub sequence: String,
    pub temporal: bool,
    pub spp: u32,
    pub frame: u32,
    /// The frame's time in the script, milliseconds (frame / display rate).
    pub time_ms: f64,
    pub eye: String,
    /// "whole", or an eccentricity band around this frame's gaze (as in quality.csv).
    pub region: String,
    pub pixels: u64,
    pub rel_mse: f64,
    pub mse: f64,
    /// Frame-to-frame change beyond the reference's own (`metrics::flicker`); empty for
    /// the first frame and for a region with no pixels.
    pub flicker: Option<f64>,
    /// GPU milliseconds of the frame (both eyes), and of its temporal and denoise passes.
    pub frame_gpu_ms: f64,
    pub temporal_ms: f64,
    pub gaze_x: f64,
    pub gaze_y: f64,
    /// Whether the eye was mid-saccade.
    pub saccade: bool,
}

/// One eye's whole motion sequence judged as a video by FovVideoVDP (motion-jod.csv),
/// foveated at each frame's gaze, shown at the script's display rate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionJodRow {
    pub scene: String,
    pub sequence: String,
    pub eye: String,
    pub frames: u32,
    pub jod: f64,
}
