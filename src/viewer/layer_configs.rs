//! The layer configs `L` cycles through, their names, and the config of the next frame
//! (foveated or not, with the `+`/`-` sample count).

use super::app::App;
use crate::foveation::FoveationConfig;
use std::path::PathBuf;

/// Samples per pixel of a frame without foveation when none are given: `fovea render`'s.
const REGULAR_SPP: u32 = 16;

/// The layer configs `L` cycles through: the one given, the thesis', and the examples in
/// assets/foveation/ (when run from the repository), each once.
pub(super) fn layer_configs(given: Option<&FoveationConfig>) -> Vec<(String, FoveationConfig)> {
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

impl App {
    /// The layer config of the next frame.
    pub(super) fn foveation(&self) -> FoveationConfig {
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

    pub(super) fn foveation_name(&self) -> String {
        match self.foveated {
            true => self.configs[self.config].0.clone(),
            false => "off".into(),
        }
    }
}
