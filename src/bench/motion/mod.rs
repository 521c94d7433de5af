//! `fovea bench --motion`: sequences of frames under a moving head and gaze, each frame
//! measured against its own converged reference, with flicker between frames and JOD per
//! sequence. One direction, as the still run: `run` renders and measures, then calls
//! `images` (the animation) and `report`; `script` (where head and eye look) is below them
//! all, and the plan's `motion` field holds one.

pub mod images;
pub mod report;
pub mod run;
pub mod script;

pub use run::run;
pub use script::{MotionChoice, MotionScript, Sequence};
