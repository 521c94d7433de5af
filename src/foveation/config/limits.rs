//! The limits and defaults of a foveation config: what `validate` allows, what a TOML file
//! leaves out.

/// The most layers a config may have; the GPU side sizes its per-layer tables by this.
pub const MAX_LAYERS: usize = 8;
/// The thesis config's occlusion radius in degrees (see `FoveationConfig::thesis`).
pub const THESIS_OCCLUSION_DEG: f32 = 56.0;
/// The coarsest lattice spacing, in pixels, a layer may use.
pub const MAX_SPACING: u32 = 64;
/// The most samples per target pixel a layer may take.
pub const MAX_LAYER_SPP: u32 = 1 << 20;

/// Samples per target pixel when a TOML layer leaves out `spp` (the thesis' value).
pub(super) const DEFAULT_SPP: u32 = 4;
/// Blend band width when a TOML file leaves out `blend_deg` (the same as `FoveationConfig::thesis`).
pub(super) const DEFAULT_BLEND_DEG: f32 = 1.0;

/// The widest lattice filter a layer may ask for, in minimum angles of resolution and in
/// pixels (the filter reaches two lattice steps, so wider ones only flatten its Gaussian).
pub const MAX_FILTER_MAR: f32 = 16.0;
pub const MAX_FILTER_PX: f32 = 64.0;

/// The most denoiser iterations a layer may ask for (a reach of 125 pixels).
pub const MAX_DENOISE: u32 = 5;

/// The denoiser's luminance edge-stop when a layer leaves out `denoise_sigma`: a tap whose
/// luminance differs from the pixel's by 4 standard deviations of the local noise counts e
/// times less (SVGF's, Schied et al. 2017).
pub const DEFAULT_DENOISE_SIGMA: f32 = 4.0;
/// The edge-stop's range: tighter than a quarter of the noise filters nearly nothing, looser
/// than 16 stops nothing a 5x5 tap could tell apart.
pub const DENOISE_SIGMA_RANGE: std::ops::RangeInclusive<f32> = 0.25..=16.0;
