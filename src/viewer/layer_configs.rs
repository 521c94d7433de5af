//! The layer configs `L` cycles through, their names, and the config of the next frame
//! (foveated or not, with the `+`/`-` sample count).

use crate::foveation::FoveationConfig;
use std::path::PathBuf;

/// Samples per pixel of a frame without foveation when none are given: `fovea render`'s.
const REGULAR_SPP: u32 = 16;

/// What the next frame's layer config is made of: the configs `L` cycles through, the one it
/// is at, whether foveation is on (`F`) and the samples `+`/`-` set.
pub(super) struct LayerConfigs {
    /// Each with its name, for the window's title.
    configs: Vec<(String, FoveationConfig)>,
    current: usize,
    pub(super) foveated: bool,
    /// `+`/`-` or `--spp`: every layer's spp; None keeps each layer's own.
    pub(super) spp: Option<u32>,
    /// The viewer started with a layer config (else with foveation off).
    started_foveated: bool,
}

impl LayerConfigs {
    /// At the `given` config (foveated) or with foveation off without one; `spp` is `--spp`.
    pub(super) fn new(given: Option<&FoveationConfig>, spp: Option<u32>) -> Self {
        Self {
            configs: layer_configs(given),
            current: 0,
            foveated: given.is_some(),
            spp,
            started_foveated: given.is_some(),
        }
    }

    /// On to the next config (`L`), foveated.
    pub(super) fn next(&mut self) {
        self.current = (self.current + 1) % self.configs.len();
        self.foveated = true;
    }

    /// The layer config of the next frame.
    pub(super) fn frame_config(&self) -> FoveationConfig {
        if self.foveated {
            let c = self.configs[self.current].1.clone();
            match self.spp {
                Some(spp) => c.with_spp(spp),
                None => c,
            }
        } else {
            let spp = match (self.spp, self.started_foveated) {
                (Some(spp), _) => spp,
                // Started without foveation: `fovea render`'s default.
                (None, false) => REGULAR_SPP,
                // Foveation switched off: the fovea's samples everywhere.
                (None, true) => self.configs[self.current].1.layers[0].spp,
            };
            FoveationConfig::regular(spp)
        }
    }

    /// The current config's name, or "off".
    pub(super) fn name(&self) -> String {
        match self.foveated {
            true => self.configs[self.current].0.clone(),
            false => "off".into(),
        }
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
