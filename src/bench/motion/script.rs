//! The motion protocol's script: where the head looks and where the eye looks, frame by frame,
//! at a headset's display rate. A headset frame is seen as part of a moving sequence, so the
//! bench measures sequences too: the head turns at the speed of someone looking around a
//! room, and the eye fixates scene points and jumps between them in saccades.
//!
//! - **Head**: yaw and pitch are sinusoids about the scene camera (no translation): yaw
//!   `A sin(2πt/T)`, pitch `B sin(2πt/(1.5T))`. With the defaults (10°, 3°, 2 s) the head
//!   turns at up to 31°/s, the range of casual head movement in VR.
//! - **Eye**: fixations on fixed *scene* directions (given as yaw/pitch from the scene
//!   camera's axis), so while the head turns the eye counter-rotates and the gaze moves on the
//!   image, as the vestibulo-ocular reflex makes it do. Between fixations a saccade moves the
//!   gaze along a smooth (raised-cosine) profile lasting `21 ms + 2.2 ms/deg` of amplitude,
//!   the "main sequence" of Carpenter (Movements of the Eyes, 1988): a 15° saccade takes 54 ms,
//!   about 5 frames at 90 Hz, peaking near 440°/s.

use crate::foveation::{FoveationConfig, ImageGeometry};
use crate::scene::{Camera, CameraPose};
use serde::{Deserialize, Serialize};

/// A motion sequence's script. Frame `k` shows time `k / frame_rate_hz`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionScript {
    /// The display rate the sequence's time runs at (the Vive Pro Eye's 90 Hz): what the
    /// renderer would have to keep up with, not how fast the bench renders.
    pub frame_rate_hz: f64,
    /// Amplitude of the head's yaw and pitch sinusoids, degrees.
    pub head_yaw_deg: f64,
    pub head_pitch_deg: f64,
    /// Period of the yaw sinusoid, seconds (pitch: 1.5×, so the head's path is no line).
    pub head_period_s: f64,
    /// How long the eye rests on a target, saccade excluded, milliseconds.
    pub fixation_ms: f64,
    /// Fixation targets in turn, cycled: yaw (right) and pitch (up) in degrees from the scene
    /// camera's axis.
    pub targets_deg: Vec<[f64; 2]>,
}

/// Saccade duration, main sequence: a fixed part and a part per degree of amplitude.
const SACCADE_BASE_MS: f64 = 21.0;
const SACCADE_MS_PER_DEG: f64 = 2.2;

/// `--motion`: which script a motion run follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MotionChoice {
    /// Head turning and saccades between fixations ([`MotionScript::head_and_saccades`]).
    HeadAndSaccades,
    /// Head and gaze still: the convergence of a view held still.
    Still,
}

impl MotionChoice {
    pub fn script(self) -> MotionScript {
        match self {
            MotionChoice::HeadAndSaccades => MotionScript::head_and_saccades(),
            MotionChoice::Still => MotionScript::still(),
        }
    }
}

impl MotionScript {
    /// The default script: the head turning up to 31°/s, fixations of 250 ms on five targets
    /// spread over the central 30° (saccades of 10–23°).
    pub fn head_and_saccades() -> Self {
        Self {
            frame_rate_hz: 90.0,
            head_yaw_deg: 10.0,
            head_pitch_deg: 3.0,
            head_period_s: 2.0,
            fixation_ms: 250.0,
            targets_deg: vec![
                [0.0, 0.0],
                [12.0, -5.0],
                [-9.0, 6.0],
                [4.0, -10.0],
                [-14.0, -3.0],
            ],
        }
    }

    /// Head and gaze held still on the view axis.
    pub fn still() -> Self {
        Self {
            head_yaw_deg: 0.0,
            head_pitch_deg: 0.0,
            targets_deg: vec![[0.0, 0.0]],
            ..Self::head_and_saccades()
        }
    }

    /// Rejects scripts that cannot be followed, naming what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let finite = [
            self.frame_rate_hz,
            self.head_yaw_deg,
            self.head_pitch_deg,
            self.head_period_s,
            self.fixation_ms,
        ]
        .iter()
        .chain(self.targets_deg.iter().flatten())
        .all(|v| v.is_finite());
        if !finite || self.frame_rate_hz <= 0.0 || self.head_period_s <= 0.0 {
            return Err(
                "the motion script needs finite numbers, a positive frame rate and \
                        head period"
                    .into(),
            );
        }
        if self.targets_deg.is_empty() || self.fixation_ms <= 0.0 {
            return Err(
                "the motion script needs at least one fixation target and a positive \
                        fixation time"
                    .into(),
            );
        }
        if self.targets_deg.iter().flatten().any(|d| d.abs() >= 80.0) {
            return Err("fixation targets must lie within 80° of the view axis".into());
        }
        Ok(())
    }

    /// Seconds at frame `k`.
    pub fn time_s(&self, frame: u32) -> f64 {
        frame as f64 / self.frame_rate_hz
    }

    /// The head's turn from the scene camera at frame `k`.
    pub fn head_pose(&self, frame: u32) -> CameraPose {
        let t = self.time_s(frame);
        let tau = std::f64::consts::TAU;
        let yaw = self.head_yaw_deg * (tau * t / self.head_period_s).sin();
        let pitch = self.head_pitch_deg * (tau * t / (1.5 * self.head_period_s)).sin();
        CameraPose {
            offset: [0.0; 3],
            turn_deg: [yaw as f32, pitch as f32, 0.0],
        }
    }

    /// Where the eye looks at frame `k`: yaw and pitch in degrees from the scene camera's axis
    /// (a scene direction, not an image position), and whether it is mid-saccade.
    pub fn gaze_deg(&self, frame: u32) -> ([f64; 2], bool) {
        let mut t_ms = self.time_s(frame) * 1e3;
        let n = self.targets_deg.len();
        // Walk the cycle of fixation + saccade segments; it repeats after `n` of them.
        let segment = |i: usize| {
            let (a, b) = (self.targets_deg[i % n], self.targets_deg[(i + 1) % n]);
            let amplitude = (b[0] - a[0]).hypot(b[1] - a[1]);
            let saccade = if amplitude > 0.0 {
                SACCADE_BASE_MS + SACCADE_MS_PER_DEG * amplitude
            } else {
                0.0
            };
            (a, b, saccade)
        };
        let cycle_ms: f64 = (0..n).map(|i| self.fixation_ms + segment(i).2).sum();
        t_ms %= cycle_ms;
        for i in 0..n {
            let (a, b, saccade) = segment(i);
            if t_ms < self.fixation_ms {
                return (a, false);
            }
            t_ms -= self.fixation_ms;
            if t_ms < saccade {
                // Raised cosine: zero velocity at both ends, peak at the middle.
                let s = 0.5 - 0.5 * (std::f64::consts::PI * t_ms / saccade).cos();
                return ([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])], true);
            }
            t_ms -= saccade;
        }
        (self.targets_deg[0], false)
    }

    /// The eye's gaze at frame `k` as a continuous pixel of `image`, for an eye looking where
    /// `head` (the scene camera turned by [`Self::head_pose`]) looks; `scene_camera` is the
    /// unturned camera the targets are given against. Targets are far away: both eyes get the
    /// same direction. A gaze that leaves the image is clamped later like any other.
    pub fn gaze_pixel(
        &self,
        frame: u32,
        scene_camera: &Camera,
        head: &Camera,
        image: &ImageGeometry,
    ) -> [f64; 2] {
        let ([yaw, pitch], _) = self.gaze_deg(frame);
        let (yaw, pitch) = (yaw.to_radians(), pitch.to_radians());
        let (r, u, f) = scene_camera.basis();
        let world = r * (yaw.sin() * pitch.cos()) as f32
            + u * pitch.sin() as f32
            + f * (yaw.cos() * pitch.cos()) as f32;
        let (hr, hu, hf) = head.basis();
        let depth = world.dot(hf) as f64;
        image.pixel_of([world.dot(hr) as f64 / depth, world.dot(hu) as f64 / depth])
    }
}

/// One sequence a motion run renders: the plan's layers at `spp` per target pixel, with the
/// temporal history on or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sequence {
    pub temporal: bool,
    pub spp: u32,
}

impl Sequence {
    /// The plan's sequences: history off and on at the plan's spp, and off at twice the spp,
    /// which costs at least what the history's passes add, so that "on" can be judged
    /// against a frame of the same or more GPU time, not only against a cheaper one.
    pub fn all(spp: u32) -> [Sequence; 3] {
        [
            Sequence {
                temporal: false,
                spp,
            },
            Sequence {
                temporal: true,
                spp,
            },
            Sequence {
                temporal: false,
                spp: 2 * spp,
            },
        ]
    }

    pub fn name(&self) -> String {
        let history = if self.temporal { "on" } else { "off" };
        format!("temporal-{history}-{}spp", self.spp)
    }

    /// The plan's layers as this sequence renders them: at its spp, and without the
    /// periphery denoiser and the lattice filter when the history is off (both are guided by
    /// the history's surfaces, so a filtering config measures "off" as its layers
    /// unfiltered).
    pub fn config(&self, layers: &FoveationConfig) -> FoveationConfig {
        let config = layers.clone().with_spp(self.spp);
        match self.temporal {
            true => config,
            false => config.without_history_filters(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;
    use glam::Vec3;

    fn camera() -> Camera {
        Camera::look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 90.0, 1.0)
    }

    #[test]
    fn the_head_turns_at_a_realistic_speed() {
        let s = MotionScript::head_and_saccades();
        // Peak yaw speed at t = 0: 2π·A/T = 31.4°/s; one frame at 90 Hz turns 0.35°.
        let step = s.head_pose(1).turn_deg[0] as f64 - s.head_pose(0).turn_deg[0] as f64;
        assert!((step * 90.0 - 31.4).abs() < 0.5, "{}", step * 90.0);
        let most = (0..360)
            .map(|k| s.head_pose(k).turn_deg[0].abs())
            .fold(0.0f32, f32::max);
        assert!((most - 10.0).abs() < 0.05, "{most}");
        assert_eq!(MotionScript::still().head_pose(40), CameraPose::default());
    }

    #[test]
    fn saccades_follow_the_main_sequence_and_fixations_hold() {
        let s = MotionScript::head_and_saccades();
        // 250 ms fixation = frames 0..22 on the first target.
        for k in 0..=22 {
            assert_eq!(s.gaze_deg(k), ([0.0, 0.0], false), "frame {k}");
        }
        // The first saccade is 13° long: 21 + 2.2·13 = 49.6 ms (250 to 299.6 ms): frames 23–26.
        let moving: Vec<u32> = (0..40).filter(|&k| s.gaze_deg(k).1).collect();
        assert_eq!(moving, vec![23, 24, 25, 26], "{moving:?}");
        assert_eq!(s.gaze_deg(27), ([12.0, -5.0], false));
        // Mid-saccade the gaze lies between the targets, on the line joining them.
        let ([y, p], _) = s.gaze_deg(25);
        assert!(y > 0.0 && y < 12.0 && (p / y + 5.0 / 12.0).abs() < 1e-9);
        // The cycle visits every target.
        let seen: std::collections::BTreeSet<String> = (0..300)
            .map(|k| s.gaze_deg(k))
            .filter(|g| !g.1)
            .map(|g| format!("{:?}", g.0))
            .collect();
        assert_eq!(seen.len(), 5);
    }

    #[test]
    fn a_fixation_holds_a_scene_direction_while_the_head_turns() {
        let s = MotionScript::head_and_saccades();
        let scene = camera();
        let fov = EyeFov {
            left: -0.8,
            right: 0.8,
            up: 0.8,
            down: -0.8,
        };
        let image = ImageGeometry::new(200, 200, fov);
        let at = |k: u32| {
            let head = s.head_pose(k).apply(&scene);
            (head, s.gaze_pixel(k, &scene, &head, &image))
        };
        // Frame 0: head unturned, gaze on the axis.
        let (_, g0) = at(0);
        assert!((g0[0] - 100.0).abs() < 1e-3 && (g0[1] - 100.0).abs() < 1e-3);
        // Frame 20: the head has turned right and up; the eye stays on the same scene point,
        // so on the image the gaze moved left and down, by the turn's angle.
        let (head, g) = at(20);
        let turn = s.head_pose(20).turn_deg;
        assert!(turn[0] > 5.0 && turn[1] > 0.5);
        assert!(g[0] < 100.0 && g[1] > 100.0, "{g:?}");
        let t = image.tan_of(g[0], g[1]);
        let (r, u, f) = head.basis();
        let seen = (r * t[0] as f32 + u * t[1] as f32 + f).normalize();
        assert!(seen.angle_between(scene.forward) < 1e-4);
    }

    #[test]
    fn sequences_without_history_render_the_layers_unfiltered() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/assets/foveation/thesis-denoised.toml"
        );
        let denoised = FoveationConfig::from_arg(path).unwrap().unwrap();
        assert!(denoised.layers.iter().any(|l| l.denoise > 0));
        let [off, on, off_2x] = Sequence::all(4);
        assert_eq!(on.config(&denoised), denoised.clone().with_spp(4));
        for s in [off, off_2x] {
            let config = s.config(&denoised);
            assert!(config
                .layers
                .iter()
                .all(|l| l.denoise == 0 && l.spp == s.spp));
        }
        assert_eq!(
            [off, on, off_2x].map(|s| s.name()),
            ["temporal-off-4spp", "temporal-on-4spp", "temporal-off-8spp"]
        );
    }

    #[test]
    fn bad_scripts_are_rejected() {
        let a = MotionScript::head_and_saccades();
        assert!(a.validate().is_ok() && MotionScript::still().validate().is_ok());
        for bad in [
            MotionScript {
                targets_deg: vec![],
                ..a.clone()
            },
            MotionScript {
                frame_rate_hz: 0.0,
                ..a.clone()
            },
            MotionScript {
                targets_deg: vec![[90.0, 0.0]],
                ..a.clone()
            },
            MotionScript {
                head_yaw_deg: f64::NAN,
                ..a.clone()
            },
        ] {
            assert!(bad.validate().is_err());
        }
    }
}
