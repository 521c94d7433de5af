//! The results directory's layout: what every stage of the bench (run → measure → report)
//! writes where, in one place, so that no stage has to import another for a file name.

use std::path::{Path, PathBuf};

pub const PLAN_FILE: &str = "plan.json";
pub const FRAMES_FILE: &str = "frames.csv";
pub const QUALITY_FILE: &str = "quality.csv";
pub const TRACE_FILE: &str = "trace.json";
/// A motion run's rows (one per scene, sequence, frame, eye and region).
pub const MOTION_FILE: &str = "motion.csv";
/// A motion run's FovVideoVDP scores: one per scene, sequence and eye, the sequence judged as
/// a video (so flicker counts).
pub const MOTION_JOD_FILE: &str = "motion-jod.csv";
/// Every command line that measured into the directory, one per line: the first one started
/// the run, later ones resumed it.
pub const COMMANDS_FILE: &str = "commands.txt";

/// Where a scene's side-by-side pictures go.
pub fn strip_path(dir: &Path, scene: &str) -> PathBuf {
    dir.join("images").join(format!("{scene}.png"))
}

/// Each frame of the motion animation is shown this long: a 90 Hz sequence at a third of its
/// speed, slow enough to see a saccade's few frames (browsers stretch delays under 20 ms).
pub const ANIMATION_FRAME_MS: u16 = 33;

/// Where a scene's motion sequences play side by side with the reference (animated PNG).
pub fn animation_path(dir: &Path, scene: &str) -> PathBuf {
    dir.join("images").join(format!("{scene}-motion.png"))
}
