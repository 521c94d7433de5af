//! The entry points callers used before [`Renderer::frame`], each now one call of it. They
//! go once their callers (bench, check, commands, tune, realtime, viewer, xr) call `frame`.

use super::frame::Frame;
use super::renderer::Renderer;
use super::request::{AfterFrame, DebugView, EyeView, FrameOptions, FrameRequest};
use super::settings::RenderSettings;
use super::RenderError;
use crate::foveation::{FoveationConfig, Gaze};
use crate::scene::Camera;

impl Renderer {
    /// One regular (non-foveated) mono frame of `camera`: the one-layer config with
    /// `settings.spp` samples per pixel, through the same passes as a foveated frame.
    pub fn render(
        &mut self,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<Frame, RenderError> {
        let config = FoveationConfig::regular(settings.spp);
        let eyes = [EyeView {
            camera: *camera,
            gaze: Gaze::Forward,
        }];
        self.render_frame(&FrameRequest {
            settings: *settings,
            foveation: &config,
            eyes: &eyes,
            debug: DebugView::None,
        })
    }

    pub fn render_frame(&mut self, request: &FrameRequest) -> Result<Frame, RenderError> {
        Ok(self
            .frame(request, FrameOptions::pixels())?
            .expect("waited"))
    }

    pub fn measure_frame(&mut self, request: &FrameRequest) -> Result<Frame, RenderError> {
        Ok(self
            .frame(request, FrameOptions::measure())?
            .expect("waited"))
    }

    pub fn measure_frame_latched(
        &mut self,
        request: &FrameRequest,
        latch: &mut dyn FnMut() -> Vec<Gaze>,
    ) -> Result<Frame, RenderError> {
        let options = FrameOptions {
            latch: Some(latch),
            ..FrameOptions::measure()
        };
        Ok(self.frame(request, options)?.expect("waited"))
    }

    pub fn submit_frame_latched(
        &mut self,
        request: &FrameRequest,
        latch: &mut dyn FnMut() -> Vec<Gaze>,
        after: &mut AfterFrame<'_>,
    ) -> Result<(), RenderError> {
        let options = FrameOptions {
            latch: Some(latch),
            after: Some(after),
            ..Default::default()
        };
        self.frame(request, options).map(|_| ())
    }
}
