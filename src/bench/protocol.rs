//! What a bench run measures: the thesis' protocol (§3.1) as data. Scenes × modes (regular,
//! forward gaze, corner gaze) × frames × repeats, both eyes, plus the quality sweep. A run's
//! plan is written to `plan.json` first, so `--resume` repeats it exactly.

use super::motion::script::MotionScript;
use crate::foveation::FoveationConfig;
use crate::render::display::DisplayChoice;
use crate::render::{FovChoice, Integrator, Traversal};
use crate::scene::env_choice::EnvChoice;
use serde::{Deserialize, Serialize};

/// The thesis' five scenes (§3.1.1–3.1.4), in its order.
pub const THESIS_SCENES: [&str; 5] = [
    "control",
    "bunny-low",
    "bunny-high",
    "cubes-441",
    "mirror-room",
];

/// How a frame is rendered: the thesis' three test types.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Every pixel traced (one layer of spacing 1, same spp).
    #[default]
    Regular,
    /// Foveated, gaze on the view axis.
    Forward,
    /// Foveated, gaze on the top-left corner.
    Corner,
    /// Foveated around the headset's eye gaze: a `fovea xr --session` recording, never
    /// part of a bench run (not in [`Mode::ALL`]).
    Headset,
    /// Foveated, gaze replayed from `--gaze-trace` (frame k of a repeat takes row k); in a
    /// run only when the plan has a trace (see [`BenchPlan::modes`]).
    Trace,
}

impl Mode {
    pub const ALL: [Mode; 3] = [Mode::Regular, Mode::Forward, Mode::Corner];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Regular => "regular",
            Mode::Forward => "forward",
            Mode::Corner => "corner",
            Mode::Headset => "headset",
            Mode::Trace => "trace",
        }
    }

    pub fn parse(s: &str) -> Option<Mode> {
        Mode::ALL.into_iter().find(|m| m.name() == s)
    }
}

/// Every parameter of a run. Serialized into plan.json and summary.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchPlan {
    pub scenes: Vec<String>,
    /// Measured frames per repeat.
    pub frames: u32,
    /// Repeats of the foveated modes (the thesis: 10).
    pub repeats_foveated: u32,
    /// Repeats of regular rendering (the thesis: 1).
    pub repeats_regular: u32,
    /// Per-eye image size; both eyes are always rendered, side by side.
    pub width: u32,
    pub height: u32,
    pub fov: FovChoice,
    /// Samples per target pixel of every layer, and of regular rendering.
    pub spp: u32,
    pub foveation: FoveationConfig,
    pub integrator: Integrator,
    pub max_bounces: u32,
    pub seed: u32,
    /// Samples per pixel of the converged reference each image is compared with.
    pub reference_spp: u32,
    /// Samples per pixel of the run-time-against-error sweep.
    pub sweep_spp: Vec<u32>,
    /// Frames timed per point of the sweep (the median is used).
    pub sweep_frames: u32,
    /// `--gaze-trace`: a gaze trace (absolute path) that drives the `trace` mode. Absent from
    /// plan.json without one, so earlier plans still read and compare equal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gaze_trace: Option<std::path::PathBuf>,
    /// The traversal that traces every frame (`--traversal`, resolved on the device the run
    /// started on). Plans written before it existed were software.
    #[serde(default)]
    pub traversal: Traversal,
    /// `--motion`: the run measures sequences that follow this script (temporal history on
    /// and off, error per frame against per-frame references, flicker) instead of the still
    /// protocol. Absent from plan.json for still runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionScript>,
    /// `--exposure` and `--tonemap`: what FovVideoVDP is shown of each scene. Absent from
    /// plan.json when neither was given (each scene's default tone mapper).
    #[serde(default, skip_serializing_if = "DisplayChoice::is_default")]
    pub display: DisplayChoice,
    /// `--env` and its options: the environment every scene is lit by. Absent from plan.json
    /// without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvChoice>,
    /// `--display`: the headset whose photometry FovVideoVDP judges on (its image size and
    /// field of view are `width`, `height`, `fov`). Absent from older plans: the Vive Pro Eye.
    #[serde(default)]
    pub profile: crate::foveation::DisplayProfile,
    /// `--sampler`. Plans written before the flag ran with the independent sampler.
    #[serde(default = "crate::render::Sampler::before_the_flag")]
    pub sampler: crate::render::Sampler,
}

/// A block of measurements that runs its modes interleaved frame by frame: one repeat of one
/// scene. Interleaving puts every mode under the same machine state, so the ratios between
/// them hold even where the machine's speed drifts (the thesis ran them one after another).
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    pub scene: String,
    pub repeat: u32,
    pub modes: Vec<Mode>,
}

/// One timed frame's identity; each has a row per eye in frames.csv.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrameKey {
    pub scene: String,
    pub mode: Mode,
    pub repeat: u32,
    pub frame: u32,
}

/// Eyes per frame: the bench always renders both, as a headset does.
pub const EYES: u32 = 2;

impl BenchPlan {
    /// The thesis' protocol at the headset's size: its five scenes, 100 frames, 10 repeats
    /// foveated and 1 regular, 4 spp, its layer config, at the Vive Pro Eye's per-eye size and
    /// field of view.
    pub fn thesis() -> Self {
        Self {
            sampler: crate::render::Sampler::chosen(),
            profile: Default::default(),
            scenes: THESIS_SCENES.iter().map(|s| s.to_string()).collect(),
            frames: 100,
            repeats_foveated: 10,
            repeats_regular: 1,
            width: 1440,
            height: 1600,
            fov: FovChoice::ViveProEye,
            spp: 4,
            foveation: FoveationConfig::thesis(),
            integrator: Integrator::Pt,
            max_bounces: 8,
            seed: 1,
            reference_spp: 1024,
            sweep_spp: vec![1, 2, 4, 8, 16],
            sweep_frames: 3,
            gaze_trace: None,
            traversal: Traversal::Software,
            motion: None,
            display: DisplayChoice::default(),
            environment: None,
        }
    }

    /// A small preset that finishes in a few minutes on lavapipe: every scene and mode, a
    /// quarter of the headset's size per side, 10 frames × 2 repeats.
    pub fn quick() -> Self {
        Self {
            frames: 10,
            repeats_foveated: 2,
            width: 360,
            height: 400,
            reference_spp: 256,
            sweep_frames: 2,
            ..Self::thesis()
        }
    }

    /// Rejects plans that cannot run or would measure nothing, saying which value to change.
    pub fn validate(&self) -> Result<(), String> {
        if self.scenes.is_empty() {
            return Err("no scenes to measure; give --scenes with at least one name".into());
        }
        if self.frames == 0 {
            return Err("--frames must be at least 1".into());
        }
        if self.repeats_foveated == 0 || self.repeats_regular == 0 {
            return Err("--repeats and --regular-repeats must be at least 1".into());
        }
        if self.spp == 0 || self.reference_spp == 0 || self.sweep_frames == 0 {
            return Err("--spp, --reference-spp and --sweep-frames must be at least 1".into());
        }
        if self.reference_spp < 4 * self.sweep_spp.iter().copied().max().unwrap_or(self.spp) {
            return Err(format!(
                "--reference-spp {} is not converged enough to judge images of up to {} spp; \
                 give at least 4x the largest --sweep-spp",
                self.reference_spp,
                self.sweep_spp.iter().copied().max().unwrap_or(self.spp)
            ));
        }
        if self.sweep_spp.contains(&0) {
            return Err("--sweep-spp values must be at least 1".into());
        }
        if let Some(script) = &self.motion {
            script.validate()?;
            if self.frames < 2 {
                return Err(
                    "--motion needs --frames of at least 2 (flicker compares a frame \
                            with the one before)"
                        .into(),
                );
            }
            if self.gaze_trace.is_some() {
                return Err("--motion follows its own gaze script; drop --gaze-trace".into());
            }
        }
        if self.foveation.is_regular() {
            return Err(
                "the bench compares foveated with regular rendering; --foveation off leaves \
                 nothing to compare (use `fovea render --bench` to time regular rendering)"
                    .into(),
            );
        }
        self.foveation.validate().map_err(|e| e.to_string())
    }

    /// The modes the run measures: the thesis' three, then `trace` when there is a trace.
    pub fn modes(&self) -> Vec<Mode> {
        let mut modes = Mode::ALL.to_vec();
        if self.gaze_trace.is_some() {
            modes.push(Mode::Trace);
        }
        modes
    }

    pub fn repeats(&self, mode: Mode) -> u32 {
        match mode {
            Mode::Regular => self.repeats_regular,
            _ => self.repeats_foveated,
        }
    }

    /// The foveation config a mode renders with at `spp` samples per (target) pixel.
    pub fn config(&self, mode: Mode, spp: u32) -> FoveationConfig {
        match mode {
            Mode::Regular => FoveationConfig::regular(spp),
            _ => self.foveation.clone().with_spp(spp),
        }
    }

    /// The timing blocks in the order they run: per scene, repeat 0 holds every mode, later
    /// repeats the modes that still have repeats left.
    pub fn units(&self) -> Vec<Unit> {
        let most = self.repeats_foveated.max(self.repeats_regular);
        let mut units = Vec::new();
        for scene in &self.scenes {
            for repeat in 0..most {
                let modes: Vec<Mode> = self
                    .modes()
                    .into_iter()
                    .filter(|&m| repeat < self.repeats(m))
                    .collect();
                units.push(Unit {
                    scene: scene.clone(),
                    repeat,
                    modes,
                });
            }
        }
        units
    }

    /// Every frame the run times, in order.
    pub fn frame_keys(&self) -> Vec<FrameKey> {
        let mut keys = Vec::new();
        for unit in self.units() {
            for frame in 0..self.frames {
                for &mode in &unit.modes {
                    keys.push(FrameKey {
                        scene: unit.scene.clone(),
                        mode,
                        repeat: unit.repeat,
                        frame,
                    });
                }
            }
        }
        keys
    }

    /// Rows frames.csv holds when the run is complete: scenes × modes × repeats × frames × eyes.
    pub fn expected_frame_rows(&self) -> u64 {
        let per_scene: u64 = self.modes().iter().map(|&m| self.repeats(m) as u64).sum();
        self.scenes.len() as u64 * per_scene * self.frames as u64 * EYES as u64
    }

    /// The sweep's spp values, sorted, with the protocol's own spp among them (the quality
    /// table reports that one).
    pub fn sweep(&self) -> Vec<u32> {
        let mut spp = self.sweep_spp.clone();
        spp.push(self.spp);
        spp.sort_unstable();
        spp.dedup();
        spp
    }
}

/// How a run is carried out, beside what it measures (not in plan.json).
pub struct RunOptions {
    /// Where converged references are cached, shared between runs.
    pub reference_cache: std::path::PathBuf,
    /// Abort the process, as a kill would, after this many measured frames (tests resume).
    pub abort_after_frames: Option<u64>,
    /// The command line, recorded in summary.json.
    pub command_line: String,
}

/// A value as its command-line spelling (the serde name, e.g. "vive-pro-eye").
pub fn flag_value<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_thesis_protocol_has_fifteen_test_types_and_its_frame_count() {
        let plan = BenchPlan::thesis();
        assert!(plan.validate().is_ok());
        // 5 scenes × (1 regular + 2 × 10 foveated) runs of 100 frames, two eyes each.
        assert_eq!(plan.expected_frame_rows(), 5 * 21 * 100 * 2);
        assert_eq!(
            plan.frame_keys().len() as u64 * 2,
            plan.expected_frame_rows()
        );
        let units = plan.units();
        assert_eq!(units.len(), 5 * 10);
        assert_eq!(units[0].modes, Mode::ALL.to_vec());
        assert_eq!(units[1].modes, vec![Mode::Forward, Mode::Corner]);
    }

    #[test]
    fn frame_keys_are_unique_and_interleave_modes() {
        let plan = BenchPlan {
            scenes: vec!["control".into(), "cubes-441".into()],
            frames: 3,
            repeats_foveated: 2,
            repeats_regular: 3,
            ..BenchPlan::quick()
        };
        let keys = plan.frame_keys();
        let unique: std::collections::HashSet<_> = keys.iter().collect();
        assert_eq!(unique.len(), keys.len());
        assert_eq!(keys.len() as u64 * 2, plan.expected_frame_rows());
        assert_eq!(keys[0].mode, Mode::Regular);
        assert_eq!(keys[1].mode, Mode::Forward);
        assert_eq!(keys[2].mode, Mode::Corner);
        // Repeat 2 has only regular left.
        assert!(keys
            .iter()
            .filter(|k| k.repeat == 2)
            .all(|k| k.mode == Mode::Regular));
    }

    #[test]
    fn nonsense_plans_are_rejected_with_the_flag_to_change() {
        let bad = [
            BenchPlan {
                frames: 0,
                ..BenchPlan::quick()
            },
            BenchPlan {
                scenes: vec![],
                ..BenchPlan::quick()
            },
            BenchPlan {
                reference_spp: 8,
                ..BenchPlan::quick()
            },
            BenchPlan {
                sweep_spp: vec![0, 1],
                ..BenchPlan::quick()
            },
            BenchPlan {
                foveation: FoveationConfig::regular(4),
                ..BenchPlan::quick()
            },
        ];
        for plan in bad {
            let e = plan.validate().unwrap_err();
            assert!(e.contains("--"), "{e}");
        }
    }

    #[test]
    fn the_sweep_includes_the_protocol_spp() {
        let plan = BenchPlan {
            spp: 3,
            sweep_spp: vec![8, 1, 2],
            ..BenchPlan::quick()
        };
        assert_eq!(plan.sweep(), vec![1, 2, 3, 8]);
    }

    #[test]
    fn a_gaze_trace_adds_the_trace_mode_to_every_repeat() {
        let plan = BenchPlan {
            scenes: vec!["control".into()],
            frames: 2,
            repeats_foveated: 2,
            gaze_trace: Some("/tmp/gaze.csv".into()),
            ..BenchPlan::quick()
        };
        assert_eq!(plan.modes().last(), Some(&Mode::Trace));
        let units = plan.units();
        assert_eq!(units[0].modes.len(), 4);
        assert_eq!(
            units[1].modes,
            vec![Mode::Forward, Mode::Corner, Mode::Trace]
        );
        // (1 regular + 3 foveated × 2 repeats) runs × 2 frames × 2 eyes.
        assert_eq!(plan.expected_frame_rows(), 7 * 2 * 2);
        assert_eq!(
            plan.frame_keys().len() as u64 * 2,
            plan.expected_frame_rows()
        );
        let json = serde_json::to_string(&plan).unwrap();
        assert_eq!(serde_json::from_str::<BenchPlan>(&json).unwrap(), plan);
        // Without a trace the plan's JSON has no such field: earlier plans compare equal.
        let json = serde_json::to_string(&BenchPlan::quick()).unwrap();
        assert!(!json.contains("gaze_trace"), "{json}");
    }

    #[test]
    fn plans_survive_json() {
        let plan = BenchPlan::quick();
        let json = serde_json::to_string(&plan).unwrap();
        let back: BenchPlan = serde_json::from_str(&json).unwrap();
        assert_eq!(back, plan);
    }
}
