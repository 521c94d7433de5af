//! What `fovea gpu-report` measures: the scenes, the layer configs, the frames, the budgets
//! and the headset sessions. The full plan fits 8 minutes on a GPU, `--quick` 2.

use crate::foveation::{DisplayProfile, FoveationConfig};
use crate::render::TraceLanes;

/// One 90 Hz stereo frame's time, and 120 Hz's.
pub const BUDGETS_MS: [f64; 2] = [1000.0 / 90.0, 1000.0 / 120.0];

/// The shipped tuned layers (assets/foveation), built in so that the report needs no files.
const TUNED: [(&str, &str); 2] = [
    (
        "tuned-regular-1spp",
        include_str!("../../assets/foveation/vive-pro-eye-regular-1spp.toml"),
    ),
    (
        "tuned-quality",
        include_str!("../../assets/foveation/vive-pro-eye-quality.toml"),
    ),
];

/// A layer config under the name the report gives it.
#[derive(Clone, Debug)]
pub struct Mode {
    pub name: String,
    pub config: FoveationConfig,
}

#[derive(Clone, Debug)]
pub struct RealtimePlan {
    /// The headset whose eyes' fields of view the frames cover.
    pub display: DisplayProfile,
    /// One eye's image (the display's panel unless asked otherwise).
    pub width: u32,
    pub height: u32,
    pub scenes: Vec<String>,
    pub modes: Vec<Mode>,
    /// Untimed frames before each case's timed ones (pipelines, caches, clocks).
    pub warmup: u32,
    /// Timed frames per case (scene, mode, eyes, traversal).
    pub frames: u32,
    /// Frame-time budgets of a stereo frame for the fovea spp search.
    pub budgets_ms: Vec<f64>,
    /// The search's largest spp.
    pub max_spp: u32,
    /// Timed frames per spp the search probes (their median decides).
    pub search_frames: u32,
    /// Headset sessions: frames each, and the frames in flight of each.
    pub xr_frames: u32,
    pub frames_in_flight: Vec<u32>,
    pub xr_scene: String,
    pub quick: bool,
    /// Frames with the temporal history on (camera still), as the headset shows them; the
    /// denoiser and the lattice filter run only with it.
    pub history: bool,
    /// The trace's lanes; None: the device's (render::preferred_trace_lanes).
    pub trace_lanes: Option<TraceLanes>,
}

impl RealtimePlan {
    /// Everything, at `width`x`height` per eye (the headset's 1440x1600 by default).
    pub fn full(width: u32, height: u32) -> Self {
        Self {
            display: DisplayProfile::ViveProEye,
            width,
            height,
            scenes: crate::scene::builtin::BUILTIN_SCENES
                .iter()
                .map(|(name, _)| name.to_string())
                .collect(),
            modes: modes(&[1, 4]),
            warmup: 10,
            frames: 120,
            budgets_ms: BUDGETS_MS.to_vec(),
            max_spp: 1024,
            search_frames: 9,
            xr_frames: 270,
            frames_in_flight: vec![1, 2, 3],
            xr_scene: "cornell".into(),
            quick: false,
            history: false,
            trace_lanes: None,
        }
    }

    /// Every scene and session, fewer configs and frames (at least 60 timed per case).
    pub fn quick(width: u32, height: u32) -> Self {
        Self {
            modes: modes(&[1]),
            warmup: 3,
            frames: 60,
            search_frames: 5,
            xr_frames: 90,
            quick: true,
            ..Self::full(width, height)
        }
    }

    /// Adds `config` to the modes, under `name`.
    pub fn add_mode(&mut self, name: &str, config: FoveationConfig) {
        self.modes.push(Mode {
            name: name.to_string(),
            config,
        });
    }

    /// The config whose fovea spp the search varies: the thesis' layers, the innermost at
    /// `spp`, the others at their own 4 spp.
    pub fn fovea_config(spp: u32) -> FoveationConfig {
        let mut config = FoveationConfig::thesis();
        config.layers[0].spp = spp;
        config
    }
}

/// Regular rendering at each of `regular_spp`, the thesis' layers and the shipped tuned ones.
fn modes(regular_spp: &[u32]) -> Vec<Mode> {
    let mut modes: Vec<Mode> = regular_spp
        .iter()
        .map(|&spp| Mode {
            name: format!("regular-{spp}spp"),
            config: FoveationConfig::regular(spp),
        })
        .collect();
    modes.push(Mode {
        name: "thesis".into(),
        config: FoveationConfig::thesis(),
    });
    modes.extend(TUNED.iter().map(|(name, toml)| Mode {
        name: name.to_string(),
        config: FoveationConfig::from_toml_str(toml, name).expect("a shipped config parses"),
    }));
    modes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_configs_are_built_in_and_valid() {
        let plan = RealtimePlan::full(1440, 1600);
        let names: Vec<&str> = plan.modes.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "regular-1spp",
                "regular-4spp",
                "thesis",
                "tuned-regular-1spp",
                "tuned-quality"
            ]
        );
        for mode in &plan.modes {
            mode.config.validate().unwrap();
        }
        assert_eq!(plan.scenes.len(), 6);
        assert!(RealtimePlan::quick(64, 64).frames >= 60);
        assert_eq!(RealtimePlan::fovea_config(16).layers[0].spp, 16);
    }
}
