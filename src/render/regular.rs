//! A regular frame: the request most checks and tests make, built for them.

use super::frame::Frame;
use super::renderer::Renderer;
use super::request::{DebugView, EyeView, FrameOptions, FrameRequest};
use super::settings::RenderSettings;
use super::RenderError;
use crate::foveation::{FoveationConfig, Gaze};
use crate::scene::Camera;

/// One regular (non-foveated) mono frame of `camera`, with its pixels: the one-layer config
/// with `settings.spp` samples per pixel, through the same passes as a foveated frame.
pub fn regular_frame(
    renderer: &mut Renderer,
    camera: &Camera,
    settings: &RenderSettings,
) -> Result<Frame, RenderError> {
    let config = FoveationConfig::regular(settings.spp);
    let eyes = [EyeView {
        camera: *camera,
        gaze: Gaze::Forward,
    }];
    let request = FrameRequest {
        settings: *settings,
        foveation: &config,
        eyes: &eyes,
        debug: DebugView::None,
    };
    renderer
        .frame(&request, FrameOptions::pixels())
        .map(Option::unwrap)
}
