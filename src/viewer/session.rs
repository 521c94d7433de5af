//! The GPU side of the viewer: the scene's renderer, the running means, and one frame of
//! each view: render → accumulate (→ the regular frame for the difference view) → the image
//! to show, left in the renderer's output image.

use super::error::ViewError;
use super::options::{DebugMode, Refine};
use crate::foveation::FoveationConfig;
use crate::gpu::{GpuContext, StorageImage};
use crate::render::accumulate::{AccumulateRequest, Accumulator, Mean, Show};
use crate::render::display::{DisplayChoice, DisplayTransform};
use crate::render::display_stage::DisplayStage;
use crate::render::FrameOptions;
use crate::render::{
    output, DebugView, EyeView, Frame, FrameRequest, FrameStats, RenderSettings, Renderer,
    TemporalSettings,
};
use crate::scene::{CpuRaycaster, Scene};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub struct Session {
    // Field order is drop order: GPU resources before the context.
    renderer: Renderer,
    accumulator: Accumulator,
    /// The display transform's pass, where the scene's transform (`choice` gives each
    /// scene's) needs one; none for clamp at 0 EV, which the swapchain's blit shows alike.
    display: Option<DisplayStage>,
    choice: DisplayChoice,
    /// Whether the last frame's image went through the display pass (the image and temporal
    /// views do; the debug views are shown as made).
    displayed: bool,
    /// Frames rendered with the temporal history (its seeds: the settings' seed + this).
    temporal_frames: u32,
    pub raycaster: CpuRaycaster,
    pub scene: Scene,
    pub ctx: Arc<GpuContext>,
}

/// One frame asked of [`Session::frame`].
pub struct FrameParams<'a> {
    pub eyes: &'a [EyeView],
    pub eye_size: [u32; 2],
    pub foveation: &'a FoveationConfig,
    /// Integrator, bounces and the seed of the running mean's first frame; the size is
    /// `eye_size` and spp the innermost layer's.
    pub settings: RenderSettings,
    pub debug: DebugMode,
    /// Start a new running mean with this frame.
    pub restart: bool,
    pub refine: Refine,
}

/// Everything that makes a frame's image: when any of it changes, the running mean restarts.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ViewKey {
    pub(super) scene: usize,
    pub(super) eyes: Vec<EyeView>,
    pub(super) eye_size: [u32; 2],
    pub(super) foveation: FoveationConfig,
    pub(super) settings: RenderSettings,
    /// The debug views that change the image accumulated (the heat map does not).
    pub(super) debug: DebugMode,
}

/// What a frame cost.
pub struct FrameCost {
    /// GPU ms per pass of every frame rendered for the view, then the accumulation.
    pub passes: Vec<(String, f64)>,
    /// All rays traced (both frames in the difference view).
    pub rays: u64,
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
}

/// A renderer whose frames land in an image: the accumulator reads it, the window shows it.
fn presenting_renderer(ctx: &Arc<GpuContext>, scene: &Scene) -> Result<Renderer, ViewError> {
    let mut renderer = Renderer::new(ctx, scene)?;
    renderer.set_output_image(true);
    Ok(renderer)
}

impl Session {
    /// Loads `scene` for eyes of aspect `aspect` and uploads it; the window shows each scene
    /// through the transform `display` gives it.
    pub fn new(
        ctx: &Arc<GpuContext>,
        name: &str,
        aspect: f32,
        display: DisplayChoice,
    ) -> Result<Self, ViewError> {
        let scene = crate::scene::load(name, aspect)?;
        let renderer = presenting_renderer(ctx, &scene)?;
        let accumulator = Accumulator::new(ctx)?;
        Ok(Self {
            renderer,
            display: accumulator.display_stage(display.transform(name))?,
            accumulator,
            choice: display,
            displayed: false,
            temporal_frames: 0,
            raycaster: CpuRaycaster::new(&scene),
            scene,
            ctx: ctx.clone(),
        })
    }

    /// Replaces the scene (the running mean restarts with the next frame).
    pub fn load_scene(&mut self, name: &str, aspect: f32) -> Result<(), ViewError> {
        let scene = crate::scene::load(name, aspect)?;
        self.display = (self.accumulator).display_stage(self.choice.transform(name))?;
        self.displayed = false;
        self.renderer = presenting_renderer(&self.ctx, &scene)?;
        self.raycaster = CpuRaycaster::new(&scene);
        self.scene = scene;
        self.accumulator.reset();
        Ok(())
    }

    /// Frames in the running mean.
    pub fn accumulated(&self) -> u32 {
        self.accumulator.frames()
    }

    /// Renders the frame, adds it to the running mean and leaves what is shown in
    /// [`Self::shown`].
    pub fn frame(&mut self, p: &FrameParams) -> Result<FrameCost, ViewError> {
        if p.restart {
            self.accumulator.reset();
        }
        let settings = RenderSettings {
            width: p.eye_size[0],
            height: p.eye_size[1],
            spp: p.foveation.layers[0].spp,
            ..p.settings
        };
        let base_seed = p.settings.seed;
        let temporal = p.refine == Refine::Temporal && p.debug == DebugMode::Image;
        self.renderer
            .set_temporal(temporal.then(TemporalSettings::default))?;
        if temporal {
            return self.temporal_frame(p, settings);
        }
        // Refining with regular frames: every frame of the image view after a mean's first.
        let refining = FoveationConfig::regular(settings.spp);
        let foveation = match p.refine == Refine::Regular
            && p.debug == DebugMode::Image
            && !p.restart
            && self.accumulator.frames() > 0
        {
            true => &refining,
            false => p.foveation,
        };
        let p = &FrameParams { foveation, ..*p };
        let request = FrameRequest {
            settings: RenderSettings {
                seed: self.accumulator.next_seed(base_seed, Mean::Main),
                ..settings
            },
            foveation: p.foveation,
            eyes: p.eyes,
            debug: match p.debug {
                DebugMode::Layers => DebugView::Layers,
                _ => DebugView::None,
            },
        };
        let mut frames = vec![self
            .renderer
            .frame(&request, FrameOptions::measure())
            .map(Option::unwrap)?];
        let show = match p.debug {
            DebugMode::Image | DebugMode::Layers => Show::Mean,
            DebugMode::Difference => Show::Nothing,
            DebugMode::Heat => Show::Heat,
        };
        let mut accumulate_ms = self.accumulate(p, Mean::Main, show)?;
        self.displayed = false;
        let display_ms = match show == Show::Mean {
            true => self.show_through_display()?,
            false => 0.0,
        };
        if p.debug == DebugMode::Difference {
            let (regular, ms) = self.regular_alongside(p, settings)?;
            frames.push(regular);
            accumulate_ms += ms;
        }
        let stats: Vec<&FrameStats> = frames.iter().map(|f| &f.stats).collect();
        let mut passes: Vec<(String, f64)> = stats
            .iter()
            .flat_map(|s| s.pass_ms.iter().cloned())
            .collect();
        passes.push(("accumulate".into(), accumulate_ms));
        if self.displayed {
            passes.push(("display".into(), display_ms));
        }
        Ok(FrameCost {
            passes,
            rays: stats.iter().map(|s| s.rays).sum(),
            nonfinite_samples: stats.iter().map(|s| s.nonfinite_samples).sum(),
            stack_overflows: stats.iter().map(|s| s.stack_overflows).sum(),
        })
    }

    /// The difference view's other half: the same view rendered regularly at the innermost
    /// layer's spp and the same seed, accumulated alongside (in the fovea the two are
    /// bit-identical). Returns the frame and the accumulation's GPU ms.
    fn regular_alongside(
        &mut self,
        p: &FrameParams,
        settings: RenderSettings,
    ) -> Result<(Frame, f64), ViewError> {
        let regular = FoveationConfig::regular(settings.spp);
        let request = FrameRequest {
            settings: RenderSettings {
                seed: (self.accumulator).next_seed(p.settings.seed, Mean::Regular),
                ..settings
            },
            foveation: &regular,
            eyes: p.eyes,
            debug: DebugView::None,
        };
        let frame = (self.renderer)
            .frame(&request, FrameOptions::measure())
            .map(Option::unwrap)?;
        let p = &FrameParams {
            foveation: &regular,
            ..*p
        };
        let ms = self.accumulate(p, Mean::Regular, Show::Difference)?;
        Ok((frame, ms))
    }

    /// A frame of the image view with the temporal history: shown as rendered, no mean.
    fn temporal_frame(
        &mut self,
        p: &FrameParams,
        settings: RenderSettings,
    ) -> Result<FrameCost, ViewError> {
        let seed = settings.seed.wrapping_add(self.temporal_frames);
        self.temporal_frames = self.temporal_frames.wrapping_add(1);
        let frame = self
            .renderer
            .frame(
                &FrameRequest {
                    settings: RenderSettings { seed, ..settings },
                    foveation: p.foveation,
                    eyes: p.eyes,
                    debug: DebugView::None,
                },
                FrameOptions::measure(),
            )
            .map(Option::unwrap)?;
        let mut s = frame.stats;
        self.displayed = false;
        let display_ms = self.show_through_display()?;
        if self.displayed {
            s.pass_ms.push(("display".into(), display_ms));
        }
        Ok(FrameCost {
            passes: s.pass_ms,
            rays: s.rays,
            nonfinite_samples: s.nonfinite_samples,
            stack_overflows: s.stack_overflows,
        })
    }

    fn accumulate(&mut self, p: &FrameParams, into: Mean, show: Show) -> Result<f64, ViewError> {
        let frame = self
            .renderer
            .output_image()
            .expect("a frame was rendered just before");
        Ok(self.accumulator.add(&AccumulateRequest {
            frame,
            eyes: p.eyes,
            eye_size: p.eye_size,
            foveation: p.foveation,
            into,
            show,
        })?)
    }

    /// Runs the display transform on the frame image, where it needs a pass; returns its
    /// GPU milliseconds.
    fn show_through_display(&mut self) -> Result<f64, ViewError> {
        let (Some(stage), Some(frame)) = (&mut self.display, self.renderer.output_image()) else {
            return Ok(0.0);
        };
        let ms = self.accumulator.show(frame, stage)?;
        self.displayed = true;
        Ok(ms)
    }

    /// What the window shows of the scene-referred image.
    fn transform(&self) -> DisplayTransform {
        (self.display.as_ref()).map_or(DisplayTransform::CLAMP, |stage| stage.transform)
    }

    /// The window's display transform, in words.
    pub fn display_description(&self) -> String {
        let t = self.transform();
        let pass = match self.display.is_some() {
            true => "a display pass before presenting",
            false => "clipped by the swapchain's sRGB encoding",
        };
        format!("{:?} at {:+} EV ({pass})", t.tonemap, t.exposure)
    }

    /// The image shown after the last frame (eyes side by side, linear RGBA), if any.
    pub fn shown(&self) -> Option<&StorageImage> {
        let display = self.display.as_ref().and_then(DisplayStage::image);
        match self.displayed {
            true => display,
            false => self.renderer.output_image(),
        }
    }

    /// Writes the image shown as `fovea render` writes its frames (PNG + linear EXR, or EXR).
    pub fn screenshot(&self, path: &Path) -> Result<Vec<PathBuf>, ViewError> {
        let image = self.renderer.output_image().ok_or_else(|| {
            ViewError::Input(format!(
                "no frame has been shown yet, so there is nothing to save as '{}'",
                path.display()
            ))
        })?;
        let rgba = image
            .read_back()
            .map_err(crate::render::RenderError::from)?;
        let frame = Frame {
            width: image.width,
            height: image.height,
            rgb: rgba
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect(),
            gazes: Vec::new(),
            stats: FrameStats::default(),
        };
        // The PNG shows what the window does: the image through the display transform, or a
        // debug view clipped (the blit's conversion); the EXR stays scene-referred.
        let transform = match self.displayed {
            true => self.transform(),
            false => DisplayTransform::CLAMP,
        };
        Ok(output::write_frame(&frame, path, &transform)?)
    }
}
