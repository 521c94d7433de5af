//! What a headset run is asked for.

use super::instance::RuntimeSource;
use crate::foveation::{DisplayProfile, FoveationConfig};
use crate::gpu::GpuOptions;
use crate::render::display::DisplayTransform;
use crate::render::{DebugView, RenderSettings, TemporalSettings};
use crate::scene::Scene;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

pub struct XrOptions {
    pub source: RuntimeSource,
    pub gpu: GpuOptions,
    pub scene: Scene,
    /// Per-eye image size; `None`: the runtime's recommended size.
    pub size: Option<[u32; 2]>,
    /// Seed, integrator and bounces (width and height come from the swapchains).
    pub settings: RenderSettings,
    pub foveation: FoveationChoice,
    pub debug: DebugView,
    /// End the session cleanly after this many rendered frames.
    pub frames: Option<u64>,
    /// Seconds a lost gaze is held before falling back to the centre.
    pub gaze_hold_s: f64,
    /// Use the runtime's visibility mask where offered.
    pub visibility_mask: bool,
    /// Render nothing: set everything up, submit empty frames until `frames`, and report
    /// what the runtime offers ([`XrSummary::probe`](super::XrSummary::probe)).
    pub probe: bool,
    /// Set (by a Ctrl+C or termination handler) to end the session as `frames` does: the
    /// runtime is asked to stop, and everything is torn down and recorded.
    pub stop: Arc<AtomicBool>,
    /// Frames submitted before the CPU waits for the oldest one's GPU work (1: each frame
    /// finished before the next is planned; at most MAX_FRAMES_IN_FLIGHT).
    pub frames_in_flight: usize,
    /// Temporal history (`Renderer::set_temporal`); None: off.
    pub temporal: Option<TemporalSettings>,
    /// What the swapchains show of the scene-referred frames (exposure, tone mapper).
    pub display: DisplayTransform,
}

/// Which foveation layers a headset session renders.
#[derive(Clone, Debug, PartialEq)]
pub enum FoveationChoice {
    /// These layers (`--foveation thesis|off|FILE.toml`).
    Given(FoveationConfig),
    /// The config fovea ships for the headset the runtime reports
    /// ([`DisplayProfile::recognise`], [`DisplayProfile::shipped_foveation`]), with every
    /// layer at `spp` if given; the thesis' layers for a headset without one.
    ForHeadset { spp: Option<u32> },
}

impl FoveationChoice {
    /// The layers for a runtime that reports `system_name` and a recommended per-eye size
    /// `eye_size`, and a line saying where they come from. Without `history` a shipped
    /// config's lattice filters and denoisers are left out (both follow the history's
    /// surfaces), and the line says so.
    pub fn resolve(
        &self,
        system_name: &str,
        eye_size: [u32; 2],
        history: bool,
    ) -> (FoveationConfig, String) {
        let spp = match self {
            FoveationChoice::Given(config) => return (config.clone(), "as given".into()),
            FoveationChoice::ForHeadset { spp } => *spp,
        };
        let profile = DisplayProfile::recognise(system_name, eye_size);
        let (mut config, mut source) = match profile.and_then(|p| Some((p, p.shipped_foveation()?)))
        {
            Some((p, (file, config))) => (
                config,
                format!("{file} (the runtime reports a {})", p.name()),
            ),
            None => (
                FoveationConfig::thesis(),
                format!(
                    "the thesis' layers (no shipped config for '{system_name}' at {}x{} per eye)",
                    eye_size[0], eye_size[1]
                ),
            ),
        };
        if let Some(spp) = spp {
            config = config.with_spp(spp);
        }
        if !history && config.needs_history() {
            config = config.without_history_filters();
            source += ", unfiltered: its filters need the temporal history";
        }
        (config, source)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_recognised_headset_gets_its_shipped_config_and_others_the_thesis() {
        let auto = FoveationChoice::ForHeadset { spp: None };
        let (config, source) = auto.resolve("Varjo XR-4", [2880, 2808], true);
        assert_eq!(
            source,
            "assets/foveation/varjo-xr-4.toml (the runtime reports a varjo-xr-4)"
        );
        assert!(config.needs_history() && !config.is_regular());
        let (config, source) = auto.resolve("Quest 3", [2064, 2208], true);
        assert_eq!(config, FoveationConfig::thesis());
        assert!(
            source.contains("no shipped config for 'Quest 3' at 2064x2208"),
            "{source}"
        );
    }
}
