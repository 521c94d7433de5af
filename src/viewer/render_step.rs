//! The per-frame render step: the eyes and their gazes, the frame rendered and accumulated
//! (restarting the running mean when the view changed), presented, and the window's title.

use super::app::App;
use super::error::ViewError;
use super::gaze::MouseGaze;
use super::options::DebugMode;
use super::session::{FrameParams, ViewKey};
use super::title::{passes_by_kind, title, TitleInfo};
use crate::foveation::gaze_source::GazeSource;
use crate::foveation::{Gaze, GazeChoice};
use crate::gpu::{Presented, SourceRect};
use crate::render::{eye_views, EyeView, RenderSettings};
use std::time::Instant;

impl App {
    /// The eyes of the next frame, with their gazes.
    fn eyes(&mut self, window: [u32; 2], eye_size: [u32; 2]) -> Vec<EyeView> {
        let aspect = eye_size[0] as f32 / eye_size[1] as f32;
        let forward = GazeChoice {
            left: Gaze::Forward,
            right: Gaze::Forward,
        };
        let mut eyes = eye_views(
            &self.fly.camera,
            aspect,
            self.options.fov,
            self.options.stereo,
            forward,
        );
        let poses: Vec<_> = eyes
            .iter()
            .map(|e| (e.camera, e.image(eye_size[0], eye_size[1])))
            .collect();
        let time_s = self.started.elapsed().as_secs_f64();
        let mut mouse = MouseGaze {
            cursor: self.cursor,
            window,
            raycaster: &self.session.raycaster,
        };
        let source: &mut dyn GazeSource = match &mut self.gaze {
            Some(source) => source.as_mut(),
            None => &mut mouse,
        };
        for (eye, gaze) in eyes.iter_mut().zip(source.gaze(self.frame, time_s, &poses)) {
            eye.gaze = gaze;
        }
        eyes
    }

    pub(super) fn render(&mut self, window: [u32; 2], now: Instant) -> Result<(), ViewError> {
        let eye_size = self.eye_size(window);
        let eyes = self.eyes(window, eye_size);
        let foveation = self.layers.frame_config();
        let settings = RenderSettings {
            sampler: crate::render::Sampler::chosen(),
            width: eye_size[0],
            height: eye_size[1],
            spp: foveation.layers[0].spp,
            seed: self.options.seed,
            integrator: self.options.integrator,
            max_bounces: self.options.max_bounces,
        };
        let key = ViewKey {
            scene: self.scene,
            eyes: eyes.clone(),
            eye_size,
            foveation: foveation.clone(),
            settings,
            debug: match self.debug {
                DebugMode::Heat => DebugMode::Image,
                d => d,
            },
        };
        let restart = self.last_view.as_ref() != Some(&key);
        self.last_view = Some(key);
        let cost = self.session.frame(&FrameParams {
            eyes: &eyes,
            eye_size,
            foveation: &foveation,
            settings,
            debug: self.debug,
            restart,
            refine: self.options.refine,
        })?;
        self.summary.rendered += 1;
        if cost.stack_overflows > 0 || cost.nonfinite_samples > 0 {
            tracing::warn!(
                "frame {}: {} BVH stack overflows, {} non-finite samples dropped",
                self.frame,
                cost.stack_overflows,
                cost.nonfinite_samples
            );
        }
        let image = self.session.shown().expect("a frame was just rendered");
        let rect = SourceRect {
            offset: [0, 0],
            extent: [image.width, image.height],
        };
        let swapchain = self.swapchain.as_mut().expect("checked by the caller");
        match swapchain.present(image, rect)? {
            Presented::Shown => self.summary.presented += 1,
            Presented::Suboptimal => {
                self.summary.presented += 1;
                self.resized = true;
            }
            Presented::OutOfDate | Presented::NoSurfaceArea => {
                self.summary.not_shown += 1;
                self.resized = true;
            }
        }
        self.rate.frame(now);
        let passes = passes_by_kind(cost.passes.iter().map(|(n, ms)| (n.as_str(), *ms)));
        let spp = match self.layers.spp {
            Some(spp) => spp.to_string(),
            None => {
                let mut all: Vec<u32> = foveation.layers.iter().map(|l| l.spp).collect();
                all.dedup();
                all.iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join("/")
            }
        };
        let text = title(&TitleInfo {
            scene: &self.session.scene.name,
            foveation: &self.layers.name(),
            spp: &spp,
            view: self.debug.name(),
            accumulated: self.session.accumulated(),
            passes: &passes,
            fps: self.rate.fps(),
            rays: cost.rays,
        });
        if let Some(w) = &self.window {
            w.set_title(&text);
        }
        tracing::debug!("frame {}: {text}", self.frame);
        Ok(())
    }
}
