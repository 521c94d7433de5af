//! What a headset run did: the runtime and device, the frames, how the sessions ended.

use super::probe::ProbeReport;
use openxr as xr;

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
    /// Where the foveation layers came from (given, or the headset's shipped config).
    pub foveation: String,
    pub states: Vec<xr::SessionState>,
    pub end: SessionEnd,
    /// Validation messages, including those reported while the Vulkan device was destroyed.
    pub validation: Vec<String>,
    /// What `--probe` found (probe sessions only).
    pub probe: Option<ProbeReport>,
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
            foveation: String::new(),
            states: Vec::new(),
            end: SessionEnd::RuntimeExit,
            validation: Vec::new(),
            probe: None,
        }
    }

    /// This session's summary continuing `earlier` sessions': their states first.
    pub(super) fn after(mut self, earlier: XrSummary) -> XrSummary {
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
