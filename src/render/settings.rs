//! What one frame is asked to compute, validated before any GPU work.

pub use super::sampler::Sampler;
use crate::shader_layout::{INTEGRATOR_PT, INTEGRATOR_SEED};

/// Which estimator traces the paths.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Integrator {
    /// Cosine/Phong importance sampling, next-event estimation with MIS, Russian roulette.
    Pt,
    /// The thesis' estimator (eqs. 3.4–3.16): uniform hemisphere, BRDF picked by p_S.
    Seed,
}

impl Integrator {
    pub fn id(self) -> u32 {
        match self {
            Integrator::Pt => INTEGRATOR_PT,
            Integrator::Seed => INTEGRATOR_SEED,
        }
    }
}

/// How the trace finds what a ray hits: the same scene, the same shaders, two traversals.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Traversal {
    /// fovea's own two-level CWBVH traversal (glsl/bvh.glsl): runs on every device.
    #[default]
    Software,
    /// VK_KHR_ray_query through the driver's acceleration structures (glsl/ray_query.glsl):
    /// the GPU's ray-tracing hardware where it has some. Written as `--traversal` names it.
    #[serde(rename = "rayquery")]
    RayQuery,
}

impl Traversal {
    /// The traversal a renderer on `ctx` starts with: ray queries where the context prefers
    /// them (GpuContext::prefers_ray_queries), else software.
    pub fn preferred(ctx: &crate::gpu::GpuContext) -> Traversal {
        match ctx.prefers_ray_queries() {
            true => Traversal::RayQuery,
            false => Traversal::Software,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Traversal::Software => "software",
            Traversal::RayQuery => "rayquery",
        }
    }
}

/// `--traversal`: one of the traversals, or the best the device has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TraversalChoice {
    Software,
    Rayquery,
    /// Ray queries on a GPU that has them; software elsewhere (on a CPU driver such as
    /// lavapipe the driver's ray queries are slower than fovea's own traversal).
    #[default]
    Auto,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u32,
    pub integrator: Integrator,
    pub max_bounces: u32,
    pub sampler: Sampler,
}

/// Largest image side: 16384 is the minimum maxImageDimension2D guaranteed by Vulkan devices
/// that fovea targets.
pub const MAX_SIDE: u32 = 16384;
/// More samples per pixel than this in one frame is almost certainly a typo (and would run
/// for hours on lavapipe).
pub const MAX_SPP: u32 = 1 << 20;
/// Paths longer than this contribute nothing measurable and only cost time.
pub const MAX_BOUNCES: u32 = 64;

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            spp: 16,
            seed: 1,
            integrator: Integrator::Pt,
            max_bounces: 8,
            sampler: Sampler::chosen(),
        }
    }
}

impl RenderSettings {
    /// [`MAX_SPP`], for callers outside this module (the CLI's messages).
    pub const MAX_SPP: u32 = MAX_SPP;
    /// [`MAX_BOUNCES`], for callers outside this module (the CLI's messages).
    pub const MAX_BOUNCES: u32 = MAX_BOUNCES;

    /// Rejects sizes, sample counts and depths that cannot make a sensible image.
    pub fn validate(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 || self.width > MAX_SIDE || self.height > MAX_SIDE {
            return Err(format!(
                "image size {}x{} is out of range: width and height must be between 1 and {MAX_SIDE}",
                self.width, self.height
            ));
        }
        if self.spp == 0 || self.spp > MAX_SPP {
            return Err(format!(
                "--spp {} is out of range: use 1 to {MAX_SPP} samples per pixel",
                self.spp
            ));
        }
        if self.max_bounces > MAX_BOUNCES {
            return Err(format!(
                "--max-bounces {} is out of range: use 0 to {MAX_BOUNCES}",
                self.max_bounces
            ));
        }
        Ok(())
    }
}
