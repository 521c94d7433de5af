//! Where a frame's gaze comes from. Every front end (render, bench, the desktop viewer, the
//! OpenXR session) asks a `GazeSource` once per frame for each eye's gaze; the sources are the
//! fixed `--gaze` choice, a replayed `--gaze-trace`, the mouse (src/viewer) and the headset's
//! eye tracker (src/xr). A source that can lose the gaze (mouse, headset) runs its samples
//! through a `GazeFilter`, so what it returns is always usable.

use super::gaze::{Gaze, GazeChoice};
use super::gaze_trace::{GazeTrace, TraceStatus};
use super::view::ImageGeometry;
use crate::scene::Camera;

/// One gaze per eye, per frame.
pub trait GazeSource {
    /// Each eye's gaze for frame `frame` (counting from 0) at `time_s` seconds into the
    /// session: one entry per entry of `eyes` (the eye's pose and image, left eye first).
    fn gaze(&mut self, frame: u64, time_s: f64, eyes: &[(Camera, ImageGeometry)]) -> Vec<Gaze>;

    /// How the last gaze returned was obtained (what `--record-gaze` writes beside it).
    fn status(&self) -> TraceStatus;
}

/// `--gaze`: the same gaze every frame; a single eye takes the left one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedGaze(pub GazeChoice);

impl GazeSource for FixedGaze {
    fn gaze(&mut self, _frame: u64, _time_s: f64, eyes: &[(Camera, ImageGeometry)]) -> Vec<Gaze> {
        (0..eyes.len())
            .map(|e| if e == 1 { self.0.right } else { self.0.left })
            .collect()
    }

    fn status(&self) -> TraceStatus {
        TraceStatus::Fixed
    }
}

/// `--gaze-trace`: frame k takes row k of the trace; past its end the last row holds, and
/// that is logged once.
#[derive(Clone, Debug)]
pub struct TraceReplay {
    trace: GazeTrace,
    status: TraceStatus,
    said_past_end: bool,
}

impl TraceReplay {
    pub fn new(trace: GazeTrace) -> Self {
        let status = trace.rows[0].status;
        Self {
            trace,
            status,
            said_past_end: false,
        }
    }

    pub fn trace(&self) -> &GazeTrace {
        &self.trace
    }
}

impl GazeSource for TraceReplay {
    fn gaze(&mut self, frame: u64, _time_s: f64, eyes: &[(Camera, ImageGeometry)]) -> Vec<Gaze> {
        let (row, past_end) = self.trace.row(frame);
        if past_end && !self.said_past_end {
            tracing::warn!(
                "gaze trace {} has {} rows; frame {frame} and later hold its last row",
                self.trace.path.display(),
                self.trace.rows.len()
            );
            self.said_past_end = true;
        }
        self.status = row.status;
        let images: Vec<ImageGeometry> = eyes.iter().map(|(_, i)| *i).collect();
        row.gazes(&images)
    }

    fn status(&self) -> TraceStatus {
        self.status
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;
    use glam::Vec3;
    use std::path::Path;

    fn eyes() -> Vec<(Camera, ImageGeometry)> {
        let camera = Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 60.0, 1.0);
        [EyeFov::VIVE_PRO_EYE_LEFT, EyeFov::VIVE_PRO_EYE_RIGHT]
            .map(|f| (camera, ImageGeometry::new(64, 48, f)))
            .to_vec()
    }

    #[test]
    fn fixed_gives_each_eye_its_choice() {
        let mut s = FixedGaze("corner:3,4".parse().unwrap());
        assert_eq!(
            s.gaze(7, 0.1, &eyes()),
            vec![Gaze::Corner, Gaze::Pixel(3.0, 4.0)]
        );
        assert_eq!(s.gaze(0, 0.0, &eyes()[..1]), vec![Gaze::Corner]);
        assert_eq!(s.status(), TraceStatus::Fixed);
    }

    #[test]
    fn a_replay_walks_the_rows_then_holds_the_last() {
        let text = "frame,time_s,left_tan_x,left_tan_y,right_tan_x,right_tan_y,status\n\
                    0,0,-0.5,0,-0.5,0,tracked\n1,0.1,0.5,0,0.5,0,held\n";
        let trace = GazeTrace::parse(text, Path::new("t.csv")).unwrap();
        let mut s: Box<dyn GazeSource> = Box::new(TraceReplay::new(trace));
        let e = eyes();
        let x = |g: &Gaze| match g {
            Gaze::Pixel(x, _) => *x,
            other => panic!("{other:?}"),
        };
        let first = s.gaze(0, 0.0, &e);
        assert_eq!(s.status(), TraceStatus::Tracked);
        assert_eq!(x(&first[0]), e[0].1.pixel_of([-0.5, 0.0])[0]);
        let second = s.gaze(1, 0.0, &e);
        assert_eq!(s.status(), TraceStatus::Held);
        assert!(x(&second[0]) > x(&first[0]));
        assert_eq!(s.gaze(5, 0.0, &e), second);
        assert_eq!(s.gaze(6, 0.0, &e), second);
    }
}
