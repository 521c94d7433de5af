//! `--sampler`: where a path's random numbers come from (glsl/sampler.glsl), and the choice
//! the command line made for the whole process.

use crate::shader_layout::{SAMPLER_INDEPENDENT, SAMPLER_ZSOBOL};
use std::sync::OnceLock;

/// Where a path's random numbers come from (glsl/sampler.glsl).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Sampler {
    /// Owen-scrambled Sobol points in Morton order over the screen (Ahmed & Wonka 2020): the
    /// error of neighbouring pixels is blue noise, and lower.
    #[default]
    Zsobol,
    /// A PCG32 stream per pixel and sample: white-noise error (fovea's first sampler).
    Independent,
}

static SAMPLER_CHOICE: OnceLock<Sampler> = OnceLock::new();

impl Sampler {
    pub fn id(self) -> u32 {
        match self {
            Sampler::Zsobol => SAMPLER_ZSOBOL,
            Sampler::Independent => SAMPLER_INDEPENDENT,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Sampler::Zsobol => "zsobol",
            Sampler::Independent => "independent",
        }
    }

    /// `--sampler`: the sampler of every frame this process renders from now on. Returns false
    /// when one was set already (the first stays).
    pub fn choose_for_process(choice: Sampler) -> bool {
        SAMPLER_CHOICE.set(choice).is_ok()
    }

    /// `--resume`: the run continues with the sampler it began with. Refuses another one given
    /// on the command line.
    pub fn adopt(planned: Sampler) -> Result<(), String> {
        match SAMPLER_CHOICE.get() {
            Some(given) if *given != planned => Err(format!(
                "this run began with --sampler {}; --resume continues with it: drop --sampler {}",
                planned.name(),
                given.name()
            )),
            _ => {
                let _ = SAMPLER_CHOICE.set(planned);
                Ok(())
            }
        }
    }

    /// What a plan written before `--sampler` existed ran with.
    pub fn before_the_flag() -> Sampler {
        Sampler::Independent
    }

    /// The process's `--sampler`, or the default.
    pub fn chosen() -> Sampler {
        SAMPLER_CHOICE.get().copied().unwrap_or_default()
    }
}
