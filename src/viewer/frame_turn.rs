//! One turn of the frame loop: scripted events, camera movement, swapchain recreation, then
//! the render step or an idle wait, the screenshots asked for, and the end after `--frames`.

use super::app::App;
use super::controls;
use super::error::ViewError;
use std::time::{Duration, Instant};
use winit::event_loop::ActiveEventLoop;

/// How long a frame loop turn waits while nothing is shown (minimised), instead of spinning.
const IDLE_WAIT: Duration = Duration::from_millis(10);

impl App {
    /// One turn of the frame loop: scripted events, camera movement, then a frame rendered,
    /// accumulated and presented unless the window shows nothing.
    pub(super) fn turn(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
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
}
