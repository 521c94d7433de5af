//! The winit application: window events → controls, and one frame per turn of the event loop
//! (`ControlFlow::Poll`), rendered synchronously and presented.

use super::controls::{self, Action, FlyCamera, DEGREES_PER_PIXEL};
use super::gaze::MouseGaze;
use super::script::{Script, ScriptEvent};
use super::session::{FrameParams, Session};
use super::title::{passes_by_kind, title, FrameRate, TitleInfo};
use super::{DebugMode, GazeInput, ViewError, ViewSummary, ViewerOptions};
use crate::foveation::gaze_source::{FixedGaze, GazeSource, TraceReplay};
use crate::foveation::{FoveationConfig, Gaze, GazeChoice};
use crate::gpu::{
    surface_instance_extensions, swapchain_device_extensions, ContextNeeds, GpuContext, Presented,
    SourceRect, Swapchain,
};
use crate::render::{eye_views, EyeView, RenderSettings};
use crate::scene::builtin::BUILTIN_SCENES;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

/// Samples per pixel of a frame without foveation when none are given: `fovea render`'s.
const REGULAR_SPP: u32 = 16;
/// How long a frame loop turn waits while nothing is shown (minimised), instead of spinning.
const IDLE_WAIT: Duration = Duration::from_millis(10);
/// Held movement keys fly this fraction of the distance to what the camera looks at per
/// second: a scene crosses in a few seconds whatever its scale.
const SPEED_PER_DISTANCE: f32 = 0.5;

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
    let session = Session::new(&ctx, &options.scene, aspect)?;
    let device = format!("{} ({}; {})", ctx.info.name, ctx.info.kind, ctx.info.driver);
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

/// The layer configs `L` cycles through: the one given, the thesis', and the examples in
/// assets/foveation/ (when run from the repository), each once.
fn layer_configs(given: Option<&FoveationConfig>) -> Vec<(String, FoveationConfig)> {
    let mut configs: Vec<(String, FoveationConfig)> = Vec::new();
    let mut add = |name: String, c: FoveationConfig| {
        if !configs.iter().any(|(_, k)| *k == c) {
            configs.push((name, c));
        }
    };
    if let Some(c) = given {
        add("given".into(), c.clone());
    }
    add("thesis".into(), FoveationConfig::thesis());
    if let Ok(dir) = std::fs::read_dir("assets/foveation") {
        let mut files: Vec<PathBuf> = dir
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        for path in files {
            if let Ok(c) = FoveationConfig::load(&path) {
                let stem = path.file_stem().unwrap_or_default();
                add(stem.to_string_lossy().into_owned(), c);
            }
        }
    }
    configs
}

/// Everything that makes a frame's image: when any of it changes, the running mean restarts.
#[derive(Clone, Debug, PartialEq)]
struct ViewKey {
    scene: usize,
    eyes: Vec<EyeView>,
    eye_size: [u32; 2],
    foveation: FoveationConfig,
    settings: RenderSettings,
    /// The debug views that change the image accumulated (the heat map does not).
    debug: DebugMode,
}

struct App {
    // Field order is drop order: the swapchain before its window, both before the session.
    swapchain: Option<Swapchain>,
    window: Option<Window>,
    session: Session,
    options: ViewerOptions,
    script: Script,
    scenes: Vec<String>,
    scene: usize,
    configs: Vec<(String, FoveationConfig)>,
    config: usize,
    foveated: bool,
    /// `+`/`-` or `--spp`: every layer's spp; None keeps each layer's own.
    spp: Option<u32>,
    debug: DebugMode,
    fly: FlyCamera,
    /// The gaze when it is not the mouse (`--gaze`, `--gaze-trace`).
    gaze: Option<Box<dyn GazeSource>>,
    cursor: Option<[f64; 2]>,
    drag_from: Option<[f64; 2]>,
    held: HashSet<KeyCode>,
    shift: bool,
    /// The window changed size (or the swapchain stopped matching it) since the last frame.
    resized: bool,
    occluded: bool,
    frame: u64,
    started: Instant,
    last_turn: Instant,
    last_view: Option<ViewKey>,
    rate: FrameRate,
    /// Screenshots asked for during the frame, saved after it.
    screenshots: Vec<PathBuf>,
    summary: ViewSummary,
    error: Option<ViewError>,
    done: bool,
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
            configs: layer_configs(options.foveation.as_ref()),
            config: 0,
            foveated: options.foveation.is_some(),
            spp: options.spp,
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

    /// The layer config of the next frame.
    fn foveation(&self) -> FoveationConfig {
        if self.foveated {
            let c = self.configs[self.config].1.clone();
            match self.spp {
                Some(spp) => c.with_spp(spp),
                None => c,
            }
        } else {
            let spp = match (self.spp, self.options.foveation.is_some()) {
                (Some(spp), _) => spp,
                // Started without foveation: `fovea render`'s default.
                (None, false) => REGULAR_SPP,
                // Foveation switched off: the fovea's samples everywhere.
                (None, true) => self.configs[self.config].1.layers[0].spp,
            };
            FoveationConfig::regular(spp)
        }
    }

    fn foveation_name(&self) -> String {
        match self.foveated {
            true => self.configs[self.config].0.clone(),
            false => "off".into(),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        self.done = true;
        event_loop.exit();
    }

    fn window_size(&self) -> [u32; 2] {
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
    fn eye_size(&self, window: [u32; 2]) -> [u32; 2] {
        let scale = self.options.render_scale;
        let side = |pixels: f32| ((pixels * scale).round() as u32).max(1);
        [
            side(window[0] as f32 / self.eye_count() as f32),
            side(window[1] as f32),
        ]
    }

    fn act(&mut self, event_loop: &ActiveEventLoop, action: Action) -> Result<(), ViewError> {
        match action {
            Action::ToggleFoveation => self.foveated = !self.foveated,
            Action::NextDebugView => self.debug = self.debug.next(),
            Action::NextLayerConfig => {
                self.config = (self.config + 1) % self.configs.len();
                self.foveated = true;
            }
            Action::MoreSamples | Action::FewerSamples => {
                let now = self.foveation().layers[0].spp;
                let next = match action {
                    Action::MoreSamples => now.saturating_mul(2).min(RenderSettings::MAX_SPP),
                    _ => (now / 2).max(1),
                };
                self.spp = Some(next);
            }
            Action::NextScene | Action::PreviousScene => {
                let n = self.scenes.len();
                self.scene = match action {
                    Action::NextScene => (self.scene + 1) % n,
                    _ => (self.scene + n - 1) % n,
                };
                let [w, h] = self.eye_size(self.window_size());
                let name = self.scenes[self.scene].clone();
                self.session.load_scene(&name, w as f32 / h as f32)?;
                self.fly = FlyCamera::new(self.session.scene.camera, move_speed(&self.session));
                self.last_view = None;
            }
            Action::Screenshot => {
                let path = next_free_name(
                    self.options
                        .screenshot
                        .as_deref()
                        .unwrap_or(Path::new("fovea-view.png")),
                );
                self.save_screenshot(&path)?;
            }
            Action::ResetCamera => {
                self.fly = FlyCamera::new(self.session.scene.camera, self.fly.speed)
            }
            Action::Quit => self.finish(event_loop)?,
        }
        Ok(())
    }

    fn save_screenshot(&mut self, path: &Path) -> Result<(), ViewError> {
        for written in self.session.screenshot(path)? {
            println!("wrote {}", written.display());
            self.summary.screenshots.push(written);
        }
        Ok(())
    }

    /// Ends the run: the final screenshot (`--screenshot`), then the loop exits.
    fn finish(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        if self.done {
            return Ok(());
        }
        self.done = true;
        if let Some(path) = self.options.screenshot.clone() {
            self.save_screenshot(&path)?;
        }
        self.summary.accumulated = self.session.accumulated();
        event_loop.exit();
        Ok(())
    }

    fn script_event(
        &mut self,
        event_loop: &ActiveEventLoop,
        event: ScriptEvent,
    ) -> Result<(), ViewError> {
        let Some(window) = &self.window else {
            return Ok(());
        };
        match event {
            ScriptEvent::Mouse(x, y) => self.cursor = Some([x, y]),
            ScriptEvent::Resize(w, h) => {
                if let Some(size) = window.request_inner_size(PhysicalSize::new(w, h)) {
                    tracing::info!("window resized at once to {}x{}", size.width, size.height);
                    self.resized = true;
                }
            }
            ScriptEvent::Minimise => window.set_minimized(true),
            ScriptEvent::Restore => {
                window.set_minimized(false);
                window.focus_window();
            }
            ScriptEvent::Hide => window.set_visible(false),
            ScriptEvent::Show => window.set_visible(true),
            ScriptEvent::Key(key) => {
                if let Some(action) = controls::action(key, false) {
                    self.act(event_loop, action)?;
                }
            }
            ScriptEvent::Turn(right, up) => self.fly.turn(right, up),
            ScriptEvent::Move(offset) => self.fly.translate(offset),
            ScriptEvent::Screenshot(path) => self.screenshots.push(path),
        }
        Ok(())
    }

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

    /// One turn of the frame loop: scripted events, camera movement, then a frame rendered,
    /// accumulated and presented unless the window shows nothing.
    fn turn(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        for event in self.script.take_until(self.frame) {
            self.script_event(event_loop, event)?;
            if self.done {
                return Ok(());
            }
        }
        let now = Instant::now();
        let seconds = now.duration_since(self.last_turn).as_secs_f32();
        self.last_turn = now;
        let directions: Vec<[f32; 3]> = self
            .held
            .iter()
            .filter_map(|k| controls::movement(*k))
            .collect();
        self.fly.fly(directions.into_iter(), seconds, self.shift);

        let window = self.window_size();
        if self.resized {
            self.resized = false;
            if let Some(swapchain) = &mut self.swapchain {
                swapchain.recreate(window)?;
                self.summary.swapchain_recreations += 1;
            }
        }
        let shows = window[0] > 0
            && window[1] > 0
            && !self.occluded
            && self
                .swapchain
                .as_ref()
                .is_some_and(|s| s.extent() != [0, 0]);
        if shows {
            self.render(window, now)?;
        } else {
            self.summary.not_shown += 1;
            std::thread::sleep(IDLE_WAIT);
        }
        for path in std::mem::take(&mut self.screenshots) {
            self.save_screenshot(&path)?;
        }
        self.frame += 1;
        self.summary.frames = self.frame;
        if self.options.frames.is_some_and(|n| self.frame >= n) {
            self.finish(event_loop)?;
        }
        Ok(())
    }

    fn render(&mut self, window: [u32; 2], now: Instant) -> Result<(), ViewError> {
        let eye_size = self.eye_size(window);
        let eyes = self.eyes(window, eye_size);
        let foveation = self.foveation();
        let settings = RenderSettings {
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
        let spp = match self.spp {
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
            foveation: &self.foveation_name(),
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

/// The speed of held movement keys for the session's scene: half the distance to what the
/// camera looks at per second (1 unit if it looks at nothing).
fn move_speed(session: &Session) -> f32 {
    let c = &session.scene.camera;
    let distance = session
        .raycaster
        .closest_hit(c.position, c.forward.normalize())
        .filter(|d| d.is_finite() && *d > 0.0)
        .unwrap_or(1.0);
    distance * SPEED_PER_DISTANCE
}

/// `path` with `-1`, `-2`, … before its extension: the first that does not exist.
fn next_free_name(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let ext = path
        .extension()
        .map_or("png".into(), |e| e.to_string_lossy());
    (1..)
        .map(|i| path.with_file_name(format!("{stem}-{i}.{ext}")))
        .find(|p| !p.exists())
        .expect("some name is free")
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
