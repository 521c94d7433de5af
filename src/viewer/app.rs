//! The winit application: window events → controls, and one frame per turn of the event loop
//! (`ControlFlow::Poll`), rendered synchronously and presented. The turn itself is in
//! `frame_turn`, the render step in `render_step`, key and script actions in `actions`.

use super::controls::{self, FlyCamera, DEGREES_PER_PIXEL};
use super::error::ViewError;
use super::layer_configs::LayerConfigs;
use super::move_speed::move_speed;
use super::options::{DebugMode, GazeInput, ViewerOptions};
use super::script::Script;
use super::session::{Session, ViewKey};
use super::summary::ViewSummary;
use super::title::FrameRate;
use crate::foveation::gaze_source::{FixedGaze, GazeSource, TraceReplay};
use crate::gpu::{
    surface_instance_extensions, swapchain_device_extensions, ContextNeeds, GpuContext, Swapchain,
};
use crate::scene::builtin::BUILTIN_SCENES;
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

/// Opens the window and runs until it is closed, Esc is pressed or `options.frames` have
/// been shown.
pub fn run(options: ViewerOptions) -> Result<ViewSummary, ViewError> {
    let event_loop = EventLoop::new().map_err(|e| ViewError::Window(e.to_string()))?;
    let display = event_loop
        .display_handle()
        .map_err(|e| ViewError::Window(e.to_string()))?
        .as_raw();
    let needs = ContextNeeds {
        instance_extensions: surface_instance_extensions(display)?,
        device_extensions: swapchain_device_extensions(),
        graphics_queue: true,
        ..Default::default()
    };
    let ctx = Arc::new(GpuContext::new_with(&options.gpu, &needs)?);
    let validation = ctx.validation_log();
    let eyes = if options.stereo { 2 } else { 1 };
    let aspect = options.window_size[0] as f32 / eyes as f32 / options.window_size[1] as f32;
    let session = Session::new(&ctx, &options.scene, aspect, options.display)?;
    let device = format!(
        "{} ({}; {}; {} traversal)",
        ctx.info.name,
        ctx.info.kind,
        ctx.info.driver,
        crate::render::Traversal::preferred(&ctx).name()
    );
    drop(ctx);
    let mut app = App::new(options, session);
    event_loop.set_control_flow(ControlFlow::Poll);
    let result = event_loop.run_app(&mut app);
    let error = app.error.take();
    let mut summary = std::mem::take(&mut app.summary);
    // Swapchain, then window, then the GPU resources and the context.
    drop(app);
    summary.device = device;
    summary.validation_messages = validation.take();
    result.map_err(|e| ViewError::Window(e.to_string()))?;
    match error {
        Some(e) => Err(e),
        None => Ok(summary),
    }
}

pub(super) struct App {
    // Field order is drop order: the swapchain before its window, both before the session.
    pub(super) swapchain: Option<Swapchain>,
    pub(super) window: Option<Window>,
    pub(super) session: Session,
    pub(super) options: ViewerOptions,
    pub(super) script: Script,
    pub(super) scenes: Vec<String>,
    pub(super) scene: usize,
    /// The layer configs, the current one, foveation on or off and the `+`/`-` samples.
    pub(super) layers: LayerConfigs,
    pub(super) debug: DebugMode,
    pub(super) fly: FlyCamera,
    /// The gaze when it is not the mouse (`--gaze`, `--gaze-trace`).
    pub(super) gaze: Option<Box<dyn GazeSource>>,
    pub(super) cursor: Option<[f64; 2]>,
    pub(super) drag_from: Option<[f64; 2]>,
    pub(super) held: HashSet<KeyCode>,
    pub(super) shift: bool,
    /// The window changed size (or the swapchain stopped matching it) since the last frame.
    pub(super) resized: bool,
    pub(super) occluded: bool,
    pub(super) frame: u64,
    pub(super) started: Instant,
    pub(super) last_turn: Instant,
    pub(super) last_view: Option<ViewKey>,
    pub(super) rate: FrameRate,
    /// Screenshots asked for during the frame, saved after it.
    pub(super) screenshots: Vec<PathBuf>,
    pub(super) summary: ViewSummary,
    pub(super) error: Option<ViewError>,
    pub(super) done: bool,
}

impl App {
    fn new(options: ViewerOptions, session: Session) -> Self {
        let mut scenes: Vec<String> = BUILTIN_SCENES.iter().map(|(n, _)| n.to_string()).collect();
        let scene = match scenes.iter().position(|s| *s == options.scene) {
            Some(i) => i,
            None => {
                scenes.insert(0, options.scene.clone());
                0
            }
        };
        let fly = FlyCamera::new(session.scene.camera, move_speed(&session));
        Self {
            swapchain: None,
            window: None,
            script: options.script.clone(),
            scenes,
            scene,
            layers: LayerConfigs::new(options.foveation.as_ref(), options.spp),
            debug: options.debug,
            fly,
            gaze: match &options.gaze {
                GazeInput::Mouse => None,
                GazeInput::Fixed(choice) => Some(Box::new(FixedGaze(*choice))),
                GazeInput::Trace(trace) => Some(Box::new(TraceReplay::new(trace.clone()))),
            },
            cursor: None,
            drag_from: None,
            held: HashSet::new(),
            shift: false,
            resized: false,
            occluded: false,
            frame: 0,
            started: Instant::now(),
            last_turn: Instant::now(),
            last_view: None,
            rate: FrameRate::default(),
            screenshots: Vec::new(),
            summary: ViewSummary::default(),
            error: None,
            done: false,
            session,
            options,
        }
    }

    pub(super) fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        self.done = true;
        event_loop.exit();
    }

    pub(super) fn window_size(&self) -> [u32; 2] {
        let s = self
            .window
            .as_ref()
            .map_or(PhysicalSize::new(0, 0), |w| w.inner_size());
        [s.width, s.height]
    }

    fn eye_count(&self) -> u32 {
        if self.options.stereo {
            2
        } else {
            1
        }
    }

    /// Each eye's image size for the window's size now.
    pub(super) fn eye_size(&self, window: [u32; 2]) -> [u32; 2] {
        let scale = self.options.render_scale;
        let side = |pixels: f32| ((pixels * scale).round() as u32).max(1);
        [
            side(window[0] as f32 / self.eye_count() as f32),
            side(window[1] as f32),
        ]
    }

    /// Ends the run: the final screenshot (`--screenshot`), then the loop exits.
    pub(super) fn finish(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        if self.done {
            return Ok(());
        }
        self.done = true;
        if let Some(path) = self.options.screenshot.clone() {
            self.save_screenshot(&path)?;
        }
        self.summary.accumulated = self.session.accumulated();
        self.summary.display = self.session.display_description();
        event_loop.exit();
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let [w, h] = self.options.window_size;
        let attributes = Window::default_attributes()
            .with_title("fovea view")
            .with_inner_size(PhysicalSize::new(w, h));
        let window = match event_loop.create_window(attributes) {
            Ok(w) => w,
            Err(e) => return self.fail(event_loop, ViewError::Window(e.to_string())),
        };
        let handles = window
            .display_handle()
            .and_then(|d| window.window_handle().map(|w| (d.as_raw(), w.as_raw())));
        let (display, raw) = match handles {
            Ok(h) => h,
            Err(e) => return self.fail(event_loop, ViewError::Window(e.to_string())),
        };
        let size = window.inner_size();
        self.window = Some(window);
        match Swapchain::new(
            &self.session.ctx,
            display,
            raw,
            [size.width, size.height],
            self.options.present,
        ) {
            Ok(s) => {
                self.summary.swapchain = format!("{:?}, {:?}", s.format(), s.present_mode());
                self.swapchain = Some(s);
            }
            Err(e) => self.fail(event_loop, e.into()),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => self.finish(event_loop),
            WindowEvent::Resized(_) => {
                self.resized = true;
                Ok(())
            }
            WindowEvent::Occluded(occluded) => {
                self.occluded = occluded;
                Ok(())
            }
            WindowEvent::ModifiersChanged(m) => {
                self.shift = m.state().shift_key();
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = [position.x, position.y];
                if let Some(from) = self.drag_from {
                    self.fly.turn(
                        (p[0] - from[0]) as f32 * DEGREES_PER_PIXEL,
                        -(p[1] - from[1]) as f32 * DEGREES_PER_PIXEL,
                    );
                    self.drag_from = Some(p);
                }
                self.cursor = Some(p);
                Ok(())
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.drag_from = match state {
                    ElementState::Pressed => self.cursor,
                    ElementState::Released => None,
                };
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(key) = event.physical_key else {
                    return;
                };
                match event.state {
                    ElementState::Pressed => {
                        self.held.insert(key);
                        match controls::action(key, self.shift) {
                            Some(action) if !event.repeat => self.act(event_loop, action),
                            _ => Ok(()),
                        }
                    }
                    ElementState::Released => {
                        self.held.remove(&key);
                        Ok(())
                    }
                }
            }
            WindowEvent::Focused(false) => {
                // Keys released while another window has focus never arrive.
                self.held.clear();
                self.drag_from = None;
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.done || self.window.is_none() {
            return;
        }
        if let Err(e) = self.turn(event_loop) {
            self.fail(event_loop, e);
        }
    }
}
