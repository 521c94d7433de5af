//! Each frame's gaze in the headset: the eye tracker's pose (or why there is none), the gaze
//! ray traced into the scene on the CPU, its fixation projected into each eye (thesis §2.7),
//! and bad samples held, then dropped to the centre, by the gaze filter.

use super::error::XrError;
use super::eye_gaze::{EyeGaze, NoGaze};
use super::poses::SpacePlacement;
use super::views::EyeViews;
use crate::foveation::fixation::eye_tangents;
use crate::foveation::gaze_filter::{FilteredGaze, GazeFilter};
use crate::scene::cpu_raycast::CpuRaycaster;
use crate::scene::Scene;
use openxr as xr;

pub(super) struct HeadsetGaze {
    tracker: Result<EyeGaze, NoGaze>,
    raycaster: CpuRaycaster,
    filter: GazeFilter,
    /// Whether the action's activity was judged (in the first focused frame: actions are
    /// only active while the session has input focus, OpenXR 1.0 §11).
    judged: bool,
    activity: GazeActivity,
}

/// How often the gaze action was active while the session had input focus.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GazeActivity {
    pub focused_frames: u64,
    pub active_frames: u64,
}

/// A frame's gaze, and when the tracker sampled it (seconds, the runtime's clock).
pub(super) struct FrameGaze {
    pub(super) filtered: FilteredGaze,
    pub(super) time_s: f64,
    /// Whether the tracker gave a sample (else `time_s` is the display time).
    pub(super) sampled: bool,
}

fn seconds(t: xr::Time) -> f64 {
    t.as_nanos() as f64 * 1e-9
}

impl HeadsetGaze {
    pub(super) fn new(tracker: Result<EyeGaze, NoGaze>, scene: &Scene, hold_s: f64) -> Self {
        Self {
            tracker,
            raycaster: CpuRaycaster::new(scene),
            filter: GazeFilter::new(hold_s),
            judged: false,
            activity: GazeActivity::default(),
        }
    }

    /// Why there is no eye gaze at all, if there is none.
    pub(super) fn unavailable(&self) -> Option<&'static str> {
        self.tracker.as_ref().err().map(|why| why.message())
    }

    /// How often the action was active in focused frames so far.
    pub(super) fn activity(&self) -> GazeActivity {
        self.activity
    }

    /// The gaze for the frame of `views` (displayed at `views.time`).
    pub(super) fn frame(
        &mut self,
        session: &xr::Session<xr::Vulkan>,
        space: &xr::Space,
        placement: &SpacePlacement,
        focused: bool,
        views: &EyeViews,
    ) -> Result<FrameGaze, XrError> {
        let (time, cameras, images) = (views.time, &views.cameras, &views.images);
        let mut time_s = seconds(time);
        let mut sampled = false;
        let tangents = match &self.tracker {
            Ok(tracker) => {
                let sample = tracker.locate(session, space, time)?;
                if let Some(t) = sample.sample_time {
                    time_s = seconds(t);
                    sampled = true;
                }
                if focused && !self.judged && !sample.active {
                    eprintln!(
                        "fovea xr: the eye gaze action is not active (the runtime delivers no \
                         gaze; common with SteamVR on the Vive Pro Eye without SRanipal): fixed \
                         centre foveation until it becomes active"
                    );
                }
                self.judged |= focused;
                self.activity.focused_frames += focused as u64;
                self.activity.active_frames += (focused && sample.active) as u64;
                sample.pose.and_then(|pose| {
                    let (origin, dir) = placement.gaze_ray(&pose);
                    let hit = |o, d| self.raycaster.closest_hit(o, d);
                    // An eye the fixation does not project into (behind it) makes the
                    // sample unusable.
                    eye_tangents(hit, origin, dir, cameras)
                        .into_iter()
                        .collect::<Option<Vec<_>>>()
                })
            }
            Err(_) => None,
        };
        let filtered = self
            .filter
            .update(seconds(time), tangents.as_deref(), images);
        Ok(FrameGaze {
            filtered,
            time_s,
            sampled,
        })
    }
}
