//! Foveation without a GPU: layer configs, the eye's image geometry, gaze points, the ray
//! buffer built once per config and resolution, and the per-frame plan of which of its rays
//! are traced (thesis §3.2.1). Also CPU references of the fill (eq. 3.17) and blend
//! (eq. 3.18) that the GPU passes are tested against.

pub mod acuity;
pub mod blend;
pub mod catmull_rom;
pub mod config;
pub mod display_profile;
pub mod fixation;
pub mod fraction;
pub mod gaze;
pub mod gaze_filter;
pub mod gaze_source;
pub mod gaze_trace;
pub mod lattice_shift;
pub mod plan;
pub mod ray_buffer;
pub mod view;
pub mod visibility_mask;

pub use config::*;
pub use display_profile::{DisplayProfile, Photometry};
pub use gaze::{Gaze, GazeChoice};
pub use gaze_filter::{GazeFilter, GazeStatus};
pub use gaze_source::{FixedGaze, GazeSource, TraceReplay};
pub use gaze_trace::{GazeTrace, TraceRow, TraceStatus, TraceWriter};
pub use plan::{EyePlan, LayerPlan, Span};
pub use ray_buffer::RayBuffer;
pub use view::{EyeFov, ImageGeometry};
pub use visibility_mask::VisibilityMask;
