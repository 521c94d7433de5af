//! Key bindings and the fly camera. Keys are physical (where they sit on a US layout), so
//! WASD works on any keyboard layout; scripts name them the same way.

use crate::scene::Camera;
use glam::{Quat, Vec3};
use winit::keyboard::KeyCode;

/// What a key press asks for (held movement keys are [`Movement`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    ToggleFoveation,
    NextDebugView,
    NextScene,
    PreviousScene,
    MoreSamples,
    FewerSamples,
    NextLayerConfig,
    Screenshot,
    ResetCamera,
    Quit,
}

/// The bindings, for `--help` and the README.
pub const KEY_HELP: &str = "  F           foveation on/off
  V           next view: image, layer overlay, difference from regular (x4), samples-per-pixel heat map
  L           next layer config (--foveation, thesis, assets/foveation/*.toml)
  + / -       double / halve the samples per pixel of every layer
  N / Shift+N next / previous built-in scene
  P or F12    screenshot (PNG + linear EXR)
  W A S D     fly forward, left, back, right; Q / E down / up; Shift: 4x faster
  left drag   look around (the mouse is the gaze otherwise)
  R           back to the scene's camera
  Esc         quit";

/// The action of a pressed key, `shift` held or not.
pub fn action(key: KeyCode, shift: bool) -> Option<Action> {
    Some(match key {
        KeyCode::KeyF => Action::ToggleFoveation,
        KeyCode::KeyV => Action::NextDebugView,
        KeyCode::KeyL => Action::NextLayerConfig,
        KeyCode::KeyN if shift => Action::PreviousScene,
        KeyCode::KeyN => Action::NextScene,
        KeyCode::Equal | KeyCode::NumpadAdd => Action::MoreSamples,
        KeyCode::Minus | KeyCode::NumpadSubtract => Action::FewerSamples,
        KeyCode::KeyP | KeyCode::F12 => Action::Screenshot,
        KeyCode::KeyR => Action::ResetCamera,
        KeyCode::Escape => Action::Quit,
        _ => return None,
    })
}

/// The camera-axis direction (right, up, forward) a held key flies in.
pub fn movement(key: KeyCode) -> Option<[f32; 3]> {
    Some(match key {
        KeyCode::KeyW => [0.0, 0.0, 1.0],
        KeyCode::KeyS => [0.0, 0.0, -1.0],
        KeyCode::KeyA => [-1.0, 0.0, 0.0],
        KeyCode::KeyD => [1.0, 0.0, 0.0],
        KeyCode::KeyQ => [0.0, -1.0, 0.0],
        KeyCode::KeyE => [0.0, 1.0, 0.0],
        _ => return None,
    })
}

/// Degrees of turn per window pixel of mouse drag: a drag across a 1000-pixel window turns
/// 150°, enough to look behind with one sweep while single pixels stay fine-grained.
pub const DEGREES_PER_PIXEL: f32 = 0.15;
/// Frames longer than this move the camera as if they took this long, so one slow frame
/// (a scene switch, lavapipe) does not fling the camera across the scene.
pub const MAX_MOVE_SECONDS: f32 = 0.25;
/// How much faster Shift flies.
pub const SHIFT_SPEED: f32 = 4.0;
/// Looking closer than this to straight up or down would make the view's right vector
/// (forward × up) degenerate.
const MAX_PITCH_DEG: f32 = 89.0;

/// The scene camera moved by the user: position and direction change; field of view and the
/// world's up direction stay the scene's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub camera: Camera,
    /// Scene units per second of held movement key.
    pub speed: f32,
}

impl FlyCamera {
    pub fn new(camera: Camera, speed: f32) -> Self {
        Self { camera, speed }
    }

    /// Moves `offset` scene units along the camera's right, up and forward axes.
    pub fn translate(&mut self, offset: [f32; 3]) {
        let (r, u, f) = self.camera.basis();
        self.camera.position += r * offset[0] + u * offset[1] + f * offset[2];
    }

    /// Turns `right_deg` to the right around the world's up and `up_deg` upwards, never past
    /// [`MAX_PITCH_DEG`] from the horizon.
    pub fn turn(&mut self, right_deg: f32, up_deg: f32) {
        let up = self.camera.up.normalize();
        let f = self.camera.forward.normalize();
        let f = Quat::from_axis_angle(up, -right_deg.to_radians()) * f;
        let pitch = f.dot(up).clamp(-1.0, 1.0).asin().to_degrees();
        let target = (pitch + up_deg).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
        let right = f.cross(up).normalize();
        let f = Quat::from_axis_angle(right, (target - pitch).to_radians()) * f;
        self.camera.forward = f.normalize();
    }

    /// Applies the held movement keys for a frame of `seconds`.
    pub fn fly(&mut self, directions: impl Iterator<Item = [f32; 3]>, seconds: f32, fast: bool) {
        let mut d = Vec3::ZERO;
        for v in directions {
            d += Vec3::from(v);
        }
        if d == Vec3::ZERO {
            return;
        }
        let speed = self.speed * if fast { SHIFT_SPEED } else { 1.0 };
        let step = d.normalize() * speed * seconds.min(MAX_MOVE_SECONDS);
        self.translate(step.into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> FlyCamera {
        FlyCamera::new(
            Camera::look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 60.0, 1.0),
            1.0,
        )
    }

    #[test]
    fn turning_right_then_left_comes_back_and_pitch_stops_short_of_vertical() {
        let mut c = camera();
        c.turn(90.0, 0.0);
        // Looking along -z, a right turn looks along +x.
        assert!(
            (c.camera.forward - Vec3::X).length() < 1e-5,
            "{:?}",
            c.camera.forward
        );
        c.turn(-90.0, 30.0);
        let expect = Vec3::new(0.0, 0.5, -(0.75f32).sqrt());
        assert!((c.camera.forward - expect).length() < 1e-5);
        c.turn(0.0, 500.0);
        let pitch = c.camera.forward.dot(Vec3::Y).asin().to_degrees();
        assert!((pitch - MAX_PITCH_DEG).abs() < 1e-3, "{pitch}");
    }

    #[test]
    fn flying_follows_the_camera_axes_at_the_set_speed() {
        let mut c = camera();
        c.fly([[0.0, 0.0, 1.0]].into_iter(), 0.1, false);
        assert!((c.camera.position - Vec3::new(0.0, 0.0, -0.1)).length() < 1e-6);
        c.fly([[1.0, 0.0, 0.0]].into_iter(), 0.1, true);
        assert!((c.camera.position - Vec3::new(0.4, 0.0, -0.1)).length() < 1e-6);
        // A long frame moves no further than MAX_MOVE_SECONDS.
        let before = c.camera.position;
        c.fly([[0.0, 1.0, 0.0]].into_iter(), 10.0, false);
        assert!((c.camera.position - before - Vec3::Y * MAX_MOVE_SECONDS).length() < 1e-6);
    }

    #[test]
    fn bindings() {
        assert_eq!(action(KeyCode::KeyF, false), Some(Action::ToggleFoveation));
        assert_eq!(action(KeyCode::KeyN, true), Some(Action::PreviousScene));
        assert_eq!(action(KeyCode::KeyW, false), None);
        assert_eq!(movement(KeyCode::KeyW), Some([0.0, 0.0, 1.0]));
    }
}
