//! What one frame is asked for: the eyes (each a camera with its own field of view and a
//! gaze), the layer config, and an optional debug view.

use super::settings::RenderSettings;
use crate::foveation::{EyeFov, FoveationConfig, Gaze, ImageGeometry};
use crate::scene::Camera;
use crate::shader_layout::{DEBUG_LAYERS, DEBUG_NONE};

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

/// Whose field of view the eyes get.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum FovChoice {
    /// The scene camera's (symmetric; horizontal extent fitted to the image aspect).
    #[default]
    Scene,
    /// The HTC Vive Pro Eye's per-eye asymmetric field of view (about 105° × 111°).
    ViveProEye,
    /// The Varjo XR-4's 120° × 105° (taken as symmetric).
    #[value(name = "varjo-xr-4")]
    #[serde(rename = "varjo-xr-4")]
    VarjoXr4,
}

impl FovChoice {
    /// A display's left (or mono) and right eyes' fields of view; None for the scene
    /// camera's, which depends on the camera and the image's aspect.
    pub fn display_fovs(self) -> Option<(EyeFov, EyeFov)> {
        match self {
            FovChoice::Scene => None,
            FovChoice::ViveProEye => Some((EyeFov::VIVE_PRO_EYE_LEFT, EyeFov::VIVE_PRO_EYE_RIGHT)),
            FovChoice::VarjoXr4 => Some((EyeFov::VARJO_XR_4, EyeFov::VARJO_XR_4)),
        }
    }
}

/// Distance between the eyes in scene units (metres): a typical adult IPD.
pub const IPD: f32 = 0.063;

/// The eyes of a frame looking where `camera` looks: one at the camera (mono), or two
/// `IPD` apart along its right vector (stereo). `gaze` gives each eye's gaze.
pub fn eye_views(
    camera: &Camera,
    aspect: f32,
    fov: FovChoice,
    stereo: bool,
    gaze: crate::foveation::GazeChoice,
) -> Vec<EyeView> {
    let with_fov = |mut c: Camera, f: EyeFov| {
        c.angle_left = f.left;
        c.angle_right = f.right;
        c.angle_up = f.up;
        c.angle_down = f.down;
        c
    };
    let (left_fov, right_fov) = fov.display_fovs().unwrap_or_else(|| {
        let c = camera.with_aspect(aspect);
        let f = EyeFov {
            left: c.angle_left,
            right: c.angle_right,
            up: c.angle_up,
            down: c.angle_down,
        };
        (f, f)
    });
    if !stereo {
        return vec![EyeView {
            camera: with_fov(*camera, left_fov),
            gaze: gaze.left,
        }];
    }
    let (right, _, _) = camera.basis();
    let eye = |side: f32, f: EyeFov, gaze: Gaze| EyeView {
        camera: with_fov(
            Camera {
                position: camera.position + right * (side * IPD * 0.5),
                ..*camera
            },
            f,
        ),
        gaze,
    };
    vec![
        eye(-1.0, left_fov, gaze.left),
        eye(1.0, right_fov, gaze.right),
    ]
}

/// Commands recorded at the end of a frame's submission, reading its output image (a copy
/// into a headset's swapchain images).
pub type AfterFrame<'a> = dyn FnMut(crate::gpu::vk::CommandBuffer, &crate::gpu::StorageImage) + 'a;

/// How [`crate::render::Renderer::frame`] renders a frame: what it waits for, reads back
/// and latches.
#[derive(Default)]
pub struct FrameOptions<'a> {
    /// Wait for the frame and return it; else it is left in flight and comes from
    /// `Renderer::next_finished`, in submission order (the oldest frame in flight is waited
    /// for first when as many as allowed are, `Renderer::set_frames_in_flight`).
    pub wait: bool,
    /// Read the frame's pixels back (`Frame::rgb`). Frame-time measurements leave them on
    /// the GPU, as a headset frame does.
    pub read_pixels: bool,
    /// Every eye's gaze (the request's are not used), called after the frame's commands are
    /// recorded, as the last thing before they are submitted: the gaze is the latest the
    /// caller can give. Planning from it (O(layers) numbers per eye, `FrameStats::plan_ms`)
    /// is all that happens on the CPU between the two.
    pub latch: Option<&'a mut dyn FnMut() -> Vec<crate::foveation::Gaze>>,
    /// Commands that read the frame's output image, recorded into the frame's own
    /// submission (a copy into a swapchain image); not called without an output image
    /// (`Renderer::set_output_image`).
    pub after: Option<&'a mut AfterFrame<'a>>,
}

impl FrameOptions<'_> {
    /// Wait and read the pixels back: a frame to write or compare.
    pub fn pixels() -> Self {
        Self {
            wait: true,
            read_pixels: true,
            ..Default::default()
        }
    }

    /// Wait, but leave the pixels on the GPU: a frame to time.
    pub fn measure() -> Self {
        Self {
            wait: true,
            ..Default::default()
        }
    }
}
