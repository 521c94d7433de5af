//! What keys and script events do: the controls' actions (foveation, debug view, layer
//! config, samples, scene, screenshot, camera reset, quit) and the scripted window events.

use super::app::App;
use super::controls::{self, Action, FlyCamera};
use super::error::ViewError;
use super::move_speed::move_speed;
use super::screenshots::next_free_name;
use super::script::ScriptEvent;
use crate::render::RenderSettings;
use std::path::Path;
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;

impl App {
    pub(super) fn act(
        &mut self,
        event_loop: &ActiveEventLoop,
        action: Action,
    ) -> Result<(), ViewError> {
        match action {
            Action::ToggleFoveation => self.layers.foveated = !self.layers.foveated,
            Action::NextDebugView => self.debug = self.debug.next(),
            Action::NextLayerConfig => self.layers.next(),
            Action::MoreSamples | Action::FewerSamples => {
                let now = self.layers.frame_config().layers[0].spp;
                let next = match action {
                    Action::MoreSamples => now.saturating_mul(2).min(RenderSettings::MAX_SPP),
                    _ => (now / 2).max(1),
                };
                self.layers.spp = Some(next);
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

    pub(super) fn script_event(
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
}
