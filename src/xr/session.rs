//! A headset run: the OpenXR instance, the Vulkan device made through the runtime, and one
//! session after another until one ends other than by loss (frame_loop.rs runs each, from
//! set-up to teardown). `frames` ends a session by asking the runtime to stop it, as a user
//! quitting would.

use super::error::{XrContext, XrError};
use super::frame_loop::run_session;
use super::instance::{RuntimeSource, XrInstance};
use super::probe::ProbeReport;
use super::vulkan::RuntimeVulkan;
use crate::foveation::gaze_filter::FilteredGaze;
use crate::foveation::{FoveationConfig, ImageGeometry};
use crate::gpu::{ContextNeeds, GpuContext, GpuOptions};
use crate::render::{DebugView, Frame, RenderSettings, TemporalSettings};
use crate::scene::Scene;
use openxr as xr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// The view configuration fovea renders: two eyes.
pub(super) const VIEW_TYPE: xr::ViewConfigurationType = xr::ViewConfigurationType::PRIMARY_STEREO;

/// What sees every rendered frame ([`run`]'s `record`).
pub(super) type Record<'r> = dyn FnMut(&FrameRecord) -> Result<(), XrError> + 'r;

pub struct XrOptions {
    pub source: RuntimeSource,
    pub gpu: GpuOptions,
    pub scene: Scene,
    /// Per-eye image size; `None`: the runtime's recommended size.
    pub size: Option<[u32; 2]>,
    /// Seed, integrator and bounces (width and height come from the swapchains).
    pub settings: RenderSettings,
    pub foveation: FoveationConfig,
    pub debug: DebugView,
    /// End the session cleanly after this many rendered frames.
    pub frames: Option<u64>,
    /// Seconds a lost gaze is held before falling back to the centre.
    pub gaze_hold_s: f64,
    /// Use the runtime's visibility mask where offered.
    pub visibility_mask: bool,
    /// Render nothing: set everything up, submit empty frames until `frames`, and report
    /// what the runtime offers ([`XrSummary::probe`]).
    pub probe: bool,
    /// Set (by a Ctrl+C or termination handler) to end the session as `frames` does: the
    /// runtime is asked to stop, and everything is torn down and recorded.
    pub stop: Arc<AtomicBool>,
    /// Frames submitted before the CPU waits for the oldest one's GPU work (1: each frame
    /// finished before the next is planned; at most MAX_FRAMES_IN_FLIGHT).
    pub frames_in_flight: usize,
    /// Temporal history (`Renderer::set_temporal`); None: off.
    pub temporal: Option<TemporalSettings>,
}

/// One rendered frame, for whoever records the session.
pub struct FrameRecord<'a> {
    pub index: u64,
    /// Predicted display time, seconds (the runtime's clock).
    pub display_time_s: f64,
    /// The runtime's display period, seconds.
    pub display_period_s: f64,
    /// When the eye tracker took the gaze sample (XrEyeGazeSampleTimeEXT), else the display
    /// time.
    pub gaze_time_s: f64,
    /// Whether the eye tracker gave a sample (its time) for the frame.
    pub gaze_sampled: bool,
    /// GPU timings and counters of both eyes (no pixels: the image went to the headset).
    pub frame: &'a Frame,
    pub gaze: &'a FilteredGaze,
    pub images: &'a [ImageGeometry],
    /// CPU milliseconds from the end of xrWaitFrame to the end of xrEndFrame.
    pub cpu_ms: f64,
    /// CPU milliseconds from the end of xrWaitFrame to the gaze latch (right before the
    /// frame's submission) and to the end of its GPU work (when fovea saw its fence
    /// signalled: it looks after every xrWaitFrame and xrEndFrame).
    pub latch_ms: f64,
    pub gpu_done_ms: f64,
    /// fovea's GPU memory in use after the frame, bytes.
    pub gpu_bytes: u64,
}

/// How a session ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SessionEnd {
    /// fovea asked to stop (`frames` reached) and the runtime stopped the session.
    Requested,
    /// The runtime (or the user through it) stopped the session.
    RuntimeExit,
    /// The session or instance was lost (headset unplugged, runtime restarted).
    Lost,
}

pub struct XrSummary {
    pub runtime: String,
    pub device: String,
    /// Frames rendered in all sessions.
    pub frames: u64,
    /// Sessions run: more than one after the runtime lost one and fovea started another.
    pub sessions: u32,
    pub eye_size: [u32; 2],
    pub swapchain_format: String,
    /// Why there was no eye gaze, if there was none.
    pub no_gaze: Option<&'static str>,
    pub visibility_mask: bool,
    pub states: Vec<xr::SessionState>,
    pub end: SessionEnd,
    /// Validation messages, including those reported while the Vulkan device was destroyed.
    pub validation: Vec<String>,
    /// What `--probe` found (probe sessions only).
    pub probe: Option<ProbeReport>,
}

/// Runs a session to its end; `record` sees every rendered frame.
pub fn run(
    options: XrOptions,
    mut record: impl FnMut(&FrameRecord) -> Result<(), XrError>,
) -> Result<XrSummary, XrError> {
    let xr_instance = XrInstance::new(options.source)?;
    let requirements = xr_instance
        .instance
        .graphics_requirements::<xr::Vulkan>(xr_instance.system)
        .xr("xrGetVulkanGraphicsRequirements2KHR")?;
    let (min, max) = (
        requirements.min_api_version_supported,
        requirements.max_api_version_supported,
    );
    if (min.major(), min.minor()) > (1, 2) || (max.major(), max.minor()) < (1, 2) {
        return Err(XrError::VulkanVersion {
            min: format!("{}.{}", min.major(), min.minor()),
            max: format!("{}.{}", max.major(), max.minor()),
        });
    }
    let creator = RuntimeVulkan {
        instance: &xr_instance.instance,
        system: xr_instance.system,
    };
    let ctx = Arc::new(GpuContext::new_with(
        &options.gpu,
        &ContextNeeds {
            graphics_queue: true,
            creator: Some(&creator),
            ..ContextNeeds::default()
        },
    )?);
    let validation_log = ctx.validation_log();
    let result = run_sessions(&xr_instance, &ctx, &options, &mut record);
    // The traversal too: it decides a headset frame's cost (ray queries on a GPU with them).
    let device = format!(
        "{} ({} traversal)",
        ctx.info.name,
        crate::render::Traversal::preferred(&ctx).name()
    );
    // The sessions and everything in them are gone (run_session tears each down); the Vulkan
    // device goes next, then the instance (dropped last, at the end of this function).
    drop(ctx);
    let mut summary = result?;
    summary.device = device;
    summary.validation.extend(validation_log.take());
    Ok(summary)
}

/// New sessions fovea creates after the runtime lost one, before it gives up.
pub const SESSION_RETRIES: u32 = 3;
/// The wait before the first new session; it doubles for each further one.
const FIRST_RETRY_WAIT: Duration = Duration::from_millis(500);

/// Runs sessions on `ctx` until one ends other than by loss, or until a lost session has been
/// followed by SESSION_RETRIES new ones (bounded back-off between them). Frames count on
/// across the sessions; a new session that cannot be created ends the run as lost, with what
/// the earlier ones recorded.
fn run_sessions(
    xr_instance: &XrInstance,
    ctx: &Arc<GpuContext>,
    options: &XrOptions,
    record: &mut Record,
) -> Result<XrSummary, XrError> {
    let mut summary = run_session(xr_instance, ctx, options, record, 0)?;
    for retry in 0..SESSION_RETRIES {
        let wanted_more = options.frames.is_none_or(|n| summary.frames < n);
        if summary.end != SessionEnd::Lost
            || options.probe
            || !wanted_more
            || options.stop.load(Ordering::Relaxed)
        {
            break;
        }
        let wait = FIRST_RETRY_WAIT * 2u32.pow(retry);
        eprintln!(
            "fovea xr: the OpenXR session was lost after {} frames; starting a new one in {} ms \
             ({} of {SESSION_RETRIES})",
            summary.frames,
            wait.as_millis(),
            retry + 1
        );
        std::thread::sleep(wait);
        match run_session(xr_instance, ctx, options, record, summary.frames) {
            Ok(next) => summary = next.after(summary),
            Err(e) => {
                eprintln!("fovea xr: no new session: {e}");
                break;
            }
        }
    }
    Ok(summary)
}

impl XrSummary {
    /// A session's summary before it starts: on `runtime`, no frame, ended by the runtime
    /// unless something else ends it.
    pub(super) fn new(runtime: String) -> Self {
        Self {
            runtime,
            device: String::new(),
            frames: 0,
            sessions: 1,
            eye_size: [0, 0],
            swapchain_format: String::new(),
            no_gaze: None,
            visibility_mask: false,
            states: Vec::new(),
            end: SessionEnd::RuntimeExit,
            validation: Vec::new(),
            probe: None,
        }
    }

    /// This session's summary continuing `earlier` sessions': their states first.
    fn after(mut self, earlier: XrSummary) -> XrSummary {
        let mut states = earlier.states;
        states.append(&mut self.states);
        self.states = states;
        let mut validation = earlier.validation;
        validation.append(&mut self.validation);
        self.validation = validation;
        self.sessions += earlier.sessions;
        self
    }
}
