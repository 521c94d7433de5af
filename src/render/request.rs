//! What one frame is asked for: the eyes (each a camera with its own field of view and a
//! gaze), the layer config, and an optional debug view.

use super::settings::RenderSettings;
use crate::foveation::{EyeFov, FoveationConfig, Gaze, ImageGeometry};
use crate::gpu::shared::{DEBUG_LAYERS, DEBUG_NONE};
use crate::scene::Camera;

/// One eye of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeView {
    /// Position, orientation and (possibly asymmetric) field of view of the eye.
    pub camera: Camera,
    pub gaze: Gaze,
}

impl EyeView {
    pub fn fov(&self) -> EyeFov {
        EyeFov {
            left: self.camera.angle_left,
            right: self.camera.angle_right,
            up: self.camera.angle_up,
            down: self.camera.angle_down,
        }
    }

    pub fn image(&self, width: u32, height: u32) -> ImageGeometry {
        ImageGeometry::new(width, height, self.fov())
    }
}

/// What the merge pass writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DebugView {
    #[default]
    None,
    /// Each pixel tinted by the layer it comes from, blend bands darkened (thesis fig. 3.5).
    Layers,
}

impl DebugView {
    pub fn id(self) -> u32 {
        match self {
            DebugView::None => DEBUG_NONE,
            DebugView::Layers => DEBUG_LAYERS,
        }
    }
}

/// A frame: `settings.width × settings.height` per eye, eyes side by side in the output.
/// Samples per pixel come from the config's layers; `settings.spp` is not used here.
#[derive(Clone, Copy, Debug)]
pub struct FrameRequest<'a> {
    pub settings: RenderSettings,
    pub foveation: &'a FoveationConfig,
    pub eyes: &'a [EyeView],
    pub debug: DebugView,
}
