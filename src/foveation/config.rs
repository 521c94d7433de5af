//! Foveation configuration: the layers around the gaze, their lattice spacing and samples per
//! pixel, the blend band between layers and the optional occlusion mask.
//!
//! A config comes from code ([`FoveationConfig::thesis`], [`FoveationConfig::regular`]), from a
//! TOML file ([`FoveationConfig::load`], see `assets/foveation/`), or from the `--foveation` CLI
//! value ([`FoveationConfig::from_arg`]). Every path into a config validates it, so the renderer
//! can rely on the rules in [`FoveationConfig::validate`].

use super::fraction::FRACTIONS;
use std::path::{Path, PathBuf};

mod limits;
use limits::{DEFAULT_BLEND_DEG, DEFAULT_SPP};
pub use limits::{
    DEFAULT_DENOISE_SIGMA, DENOISE_SIGMA_RANGE, MAX_DENOISE, MAX_FILTER_MAR, MAX_FILTER_PX,
    MAX_LAYERS, MAX_LAYER_SPP, MAX_SPACING, THESIS_OCCLUSION_DEG,
};

mod serde_fields;
use serde_fields::{
    default_blend_deg, default_denoise_sigma, default_spp, deserialize_spacing, deserialize_spp,
    is_default_denoise_sigma, is_one, is_zero, is_zero_f32, one,
};

/// What `--foveation` accepts, for error messages.
const ACCEPTED_ARGS: &str = "'off' (regular rendering), 'thesis' (the thesis' evaluation config) \
     or the path of a foveation TOML file (examples in assets/foveation/)";

/// One foveation layer: target pixels on a lattice of `spacing` pixels, `spp` samples each.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    /// Angular radius around the gaze in degrees; `None` = the background layer (covers the rest of the screen).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_deg: Option<f32>,
    /// Lattice spacing in pixels: one target pixel per `spacing` x `spacing` block.
    #[serde(deserialize_with = "deserialize_spacing")]
    pub spacing: u32,
    /// Samples per target pixel.
    #[serde(default = "default_spp", deserialize_with = "deserialize_spp")]
    pub spp: u32,
    /// Iterations of the edge-aware denoiser over the pixels shown from this layer (0, the
    /// default: none; each doubles the filter's reach: 1 → 5 px, 2 → 13, 3 → 29). It is
    /// guided by the temporal history's surfaces, so it needs history on.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub denoise: u32,
    /// The denoiser's width limit, in minimum angles of resolution of the eye at the pixel's
    /// eccentricity (Guenter et al. 2012's acuity line; 0, the default: no limit): an
    /// iteration runs at a pixel only while the filter's width (each iteration widens it,
    /// 1 → 2.2 → 4.6 → 9.2 px) stays within it, so the blur is finer than the eye resolves
    /// there and the fovea stays sharp.
    #[serde(default, skip_serializing_if = "is_zero_f32")]
    pub denoise_mar: f32,
    /// The denoiser's luminance edge-stop, in standard deviations of the local noise (4, the
    /// default, SVGF's): a tap whose luminance differs from the pixel's by this much counts e
    /// times less. Tighter keeps more of what differs — detail the eye resolves where it
    /// looks — and removes less noise: at 0.5 in a 20° 4-spp fovea (the Vive's shipped config),
    /// bunny-high's shading finer than a pixel stays and cornell's flat walls are still
    /// smoothed (reports/tune-motion-window-lavapipe/sigma-0.125/fovea-for-all/).
    #[serde(
        default = "default_denoise_sigma",
        skip_serializing_if = "is_default_denoise_sigma"
    )]
    pub denoise_sigma: f32,
    /// The lattice filter's width, in minimum angles of resolution of the eye at the lattice
    /// point's eccentricity (Guenter et al. 2012's acuity line; 0, the default: none). The
    /// filter (glsl/lattice_filter.comp) smooths the layer's traced points on their lattice,
    /// before resolve, within the surface each point sees; it needs history on, whose
    /// surfaces guide it.
    #[serde(default, skip_serializing_if = "is_zero_f32")]
    pub filter_mar: f32,
    /// The lattice filter's width at least, in pixels, wherever the eye looks (0, the
    /// default: none): the uniform filter, for regular frames to compare with.
    #[serde(default, skip_serializing_if = "is_zero_f32")]
    pub filter_px: f32,
    /// The layer traces 1 in `fraction` of its lattice points per frame (1, the default:
    /// every point; 2: a checkerboard; 4: one of every 2×2 block), a different pattern each
    /// frame while history is on (foveation/fraction.rs); the others are filled from their
    /// traced neighbours. A full-resolution layer so costs half or a quarter of 1 spp.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub fraction: u32,
}

impl Layer {
    /// Whether the layer asks for the lattice filter.
    pub fn filters(&self) -> bool {
        self.filter_mar > 0.0 || self.filter_px > 0.0
    }

    /// The denoiser's settings' rules (see [`FoveationConfig::validate`]); `n` is the layer's
    /// 1-based number, for the message.
    fn check_denoiser(&self, n: usize) -> Result<(), String> {
        if self.denoise > MAX_DENOISE {
            return Err(format!(
                "layer {n}: denoise = {} must be in 0..={MAX_DENOISE} iterations",
                self.denoise
            ));
        }
        if !(0.0..=MAX_FILTER_MAR).contains(&self.denoise_mar) {
            return Err(format!(
                "layer {n}: denoise_mar = {} must be in 0..={MAX_FILTER_MAR} minimum angles \
                 of resolution (0: no limit to the denoiser's width)",
                self.denoise_mar
            ));
        }
        if !DENOISE_SIGMA_RANGE.contains(&self.denoise_sigma) {
            return Err(format!(
                "layer {n}: denoise_sigma = {} must be in {}..={} standard deviations of \
                 the local noise (the denoiser's luminance edge-stop; {DEFAULT_DENOISE_SIGMA} \
                 when left out)",
                self.denoise_sigma,
                DENOISE_SIGMA_RANGE.start(),
                DENOISE_SIGMA_RANGE.end()
            ));
        }
        Ok(())
    }
}

/// A complete foveation setup: layers from the gaze outward, blend band and occlusion mask.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FoveationConfig {
    /// Innermost first; the last one is the background layer (radius None).
    pub layers: Vec<Layer>,
    /// Width in degrees of the linear blend band just inside each finite layer radius (thesis eq. 3.18).
    pub blend_deg: f32,
    /// Optional occlusion mask: pixels more than this many degrees from the view axis are neither traced nor shown (black). None = no mask.
    pub occlusion_deg: Option<f32>,
}

/// The TOML file layout. Kept apart from [`FoveationConfig`] so the file's table name (`layer`,
/// singular, as each `[[layer]]` reads) and defaults do not leak into the in-memory type.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfigFile {
    #[serde(default = "default_blend_deg")]
    blend_deg: f32,
    #[serde(default)]
    occlusion_deg: Option<f32>,
    // Defaulted so that a file without layers reaches `validate`, whose message says what to add.
    #[serde(default)]
    layer: Vec<Layer>,
}

/// Why a foveation config was rejected. Every message says what was wrong and what to do.
#[derive(Debug, thiserror::Error)]
pub enum FoveationError {
    /// The `--foveation` value is neither a keyword nor an existing file.
    #[error("--foveation '{arg}': no such file; use {ACCEPTED_ARGS}")]
    UnknownArg { arg: String },
    /// The config file could not be read.
    #[error("cannot read foveation config '{}': {source}; check the path and its permissions", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The text is not TOML of the expected layout (syntax error, wrong type, unknown field).
    #[error("cannot parse foveation config '{origin}': {message}\n(see assets/foveation/thesis.toml for the format)")]
    Parse { origin: String, message: String },
    /// The config breaks a rule of [`FoveationConfig::validate`].
    #[error("invalid foveation config: {problem}")]
    Invalid { problem: String },
    /// A config read from `origin` breaks a rule of [`FoveationConfig::validate`].
    #[error("invalid foveation config '{origin}': {problem}")]
    InvalidIn { origin: String, problem: String },
}

impl FoveationConfig {
    /// The thesis' evaluation config (Axblad 2020 §3.1.2): radii 6°, 10°, 20° + background; spacings 1, 2, 3, 4; 4 spp per target pixel; blend 1° (our choice: the thesis shows blend bands but never gives their width); an occlusion mask of 56° around the view axis. The thesis masks with layer zero's radius (§3.2.1) without giving it; 56° is the Vive Pro Eye's vertical half-field rounded up, a circle that keeps every edge midpoint and hides the image corners its lens does not show. It changes nothing at the built-in scenes' desktop fields of view (under 56° from the axis everywhere).
    pub fn thesis() -> Self {
        let layer = |radius_deg, spacing| Layer {
            radius_deg,
            spacing,
            spp: DEFAULT_SPP,
            denoise: 0,
            filter_mar: 0.0,
            filter_px: 0.0,
            denoise_mar: 0.0,
            denoise_sigma: DEFAULT_DENOISE_SIGMA,
            fraction: 1,
        };
        Self {
            layers: vec![
                layer(Some(6.0), 1),
                layer(Some(10.0), 2),
                layer(Some(20.0), 3),
                layer(None, 4),
            ],
            blend_deg: DEFAULT_BLEND_DEG,
            occlusion_deg: Some(THESIS_OCCLUSION_DEG),
        }
    }

    /// Regular (non-foveated) rendering as a config: one background layer, spacing 1, `spp` samples.
    pub fn regular(spp: u32) -> Self {
        Self {
            layers: vec![Layer {
                radius_deg: None,
                spacing: 1,
                spp,
                denoise: 0,
                filter_mar: 0.0,
                filter_px: 0.0,
                denoise_mar: 0.0,
                denoise_sigma: DEFAULT_DENOISE_SIGMA,
                fraction: 1,
            }],
            // No finite radius, so there is no band to blend; 0 keeps the value meaningful.
            blend_deg: 0.0,
            occlusion_deg: None,
        }
    }

    /// The same config with every layer's spp replaced.
    pub fn with_spp(mut self, spp: u32) -> Self {
        for layer in &mut self.layers {
            layer.spp = spp;
        }
        self
    }

    /// The same layers without what follows the temporal history's surfaces (the denoiser
    /// and the lattice filter): what a config renders as when the history is off.
    pub fn without_history_filters(mut self) -> Self {
        for layer in &mut self.layers {
            (layer.denoise, layer.denoise_mar) = (0, 0.0);
            layer.denoise_sigma = DEFAULT_DENOISE_SIGMA;
            (layer.filter_mar, layer.filter_px) = (0.0, 0.0);
        }
        self
    }

    /// Whether a layer denoises or filters its lattice, which need the history.
    pub fn needs_history(&self) -> bool {
        self.filters() || self.denoise_iterations() > 0
    }

    /// True for exactly one layer with spacing 1 that traces every point (what `regular`
    /// builds).
    pub fn is_regular(&self) -> bool {
        matches!(self.layers.as_slice(), [only] if only.spacing == 1 && only.fraction == 1)
    }

    /// Whether a layer traces only a fraction of its points per frame (the frame then fills
    /// the rest).
    pub fn fractional(&self) -> bool {
        self.layers.iter().any(|l| l.fraction > 1)
    }

    /// The most denoiser iterations any layer asks for (0: no denoising).
    pub fn denoise_iterations(&self) -> u32 {
        self.layers.iter().map(|l| l.denoise).max().unwrap_or(0)
    }

    /// Whether a layer asks for the lattice filter.
    pub fn filters(&self) -> bool {
        self.layers.iter().any(Layer::filters)
    }

    /// Checks every rule the renderer relies on; the error names the layer (1-based) and field.
    ///
    /// Rules: 1..=[`MAX_LAYERS`] layers; exactly the last layer has no radius (the background
    /// layer, so the whole screen is covered); finite radii in (0, 180) degrees, strictly growing
    /// outward; `blend_deg` finite and >= 0, and no blend band overlapping the previous one or
    /// the gaze point; spacing in 1..=[`MAX_SPACING`], never decreasing outward; spp in
    /// 1..=[`MAX_LAYER_SPP`]; denoise up to [`MAX_DENOISE`], denoise_sigma in
    /// [`DENOISE_SIGMA_RANGE`]; filter_mar and filter_px in
    /// 0..=[`MAX_FILTER_MAR`] and 0..=[`MAX_FILTER_PX`]; `occlusion_deg`, if given, finite in
    /// (0, 180].
    pub fn validate(&self) -> Result<(), FoveationError> {
        self.check()
            .map_err(|problem| FoveationError::Invalid { problem })
    }

    /// The rules of [`Self::validate`], returning the bare problem so callers can add the origin.
    fn check(&self) -> Result<(), String> {
        let count = self.layers.len();
        if count == 0 {
            return Err(
                "no layers: add at least one [[layer]]; the last one, without radius_deg, \
                 is the background layer covering the rest of the screen"
                    .to_owned(),
            );
        }
        if count > MAX_LAYERS {
            return Err(format!(
                "{count} layers, at most {MAX_LAYERS} are supported: merge some layers"
            ));
        }

        // Fields of each layer on its own.
        for (index, layer) in self.layers.iter().enumerate() {
            let n = index + 1;
            let is_last = n == count;
            match layer.radius_deg {
                None if !is_last => {
                    return Err(format!(
                        "layer {n} has no radius_deg but is not the last layer: only the last \
                         layer (the background layer) may leave out radius_deg; give layer {n} \
                         a radius_deg or move it last"
                    ));
                }
                Some(radius) if is_last => {
                    return Err(format!(
                        "the last layer (layer {n}) has radius_deg = {radius}, so nothing covers \
                         the screen beyond {radius} degrees: add a background layer without \
                         radius_deg after it, or remove its radius_deg"
                    ));
                }
                Some(radius) if !(radius.is_finite() && radius > 0.0 && radius < 180.0) => {
                    return Err(format!(
                        "layer {n}: radius_deg = {radius} must be a finite angle greater than 0 \
                         and less than 180 degrees"
                    ));
                }
                _ => {}
            }
            if !(1..=MAX_SPACING).contains(&layer.spacing) {
                return Err(format!(
                    "layer {n}: spacing = {} must be in 1..={MAX_SPACING} pixels",
                    layer.spacing
                ));
            }
            layer.check_denoiser(n)?;
            if !(0.0..=MAX_FILTER_MAR).contains(&layer.filter_mar) {
                return Err(format!(
                    "layer {n}: filter_mar = {} must be in 0..={MAX_FILTER_MAR} minimum angles \
                     of resolution (0: no lattice filter)",
                    layer.filter_mar
                ));
            }
            if !(0.0..=MAX_FILTER_PX).contains(&layer.filter_px) {
                return Err(format!(
                    "layer {n}: filter_px = {} must be in 0..={MAX_FILTER_PX} pixels (0: no \
                     lattice filter)",
                    layer.filter_px
                ));
            }
            if !FRACTIONS.contains(&layer.fraction) {
                return Err(format!(
                    "layer {n}: fraction = {} must be one of {FRACTIONS:?} (the layer traces 1 \
                     in `fraction` of its lattice points per frame)",
                    layer.fraction
                ));
            }
            if layer.fraction > 1 && layer.filters() {
                return Err(format!(
                    "layer {n}: the lattice filter (filter_mar, filter_px) smooths traced \
                     points only, and fraction = {} leaves points to fill: remove one of them",
                    layer.fraction
                ));
            }
            if !(1..=MAX_LAYER_SPP).contains(&layer.spp) {
                return Err(format!(
                    "layer {n}: spp = {} must be in 1..={MAX_LAYER_SPP} samples per target pixel",
                    layer.spp
                ));
            }
        }

        // Relations between neighbouring layers.
        for (index, pair) in self.layers.windows(2).enumerate() {
            let (inner, outer) = (&pair[0], &pair[1]);
            let (p, n) = (index + 1, index + 2);
            if let (Some(inner_r), Some(outer_r)) = (inner.radius_deg, outer.radius_deg) {
                if outer_r <= inner_r {
                    return Err(format!(
                        "layer {n}: radius_deg = {outer_r} must be larger than layer {p}'s \
                         radius_deg = {inner_r}: list layers innermost first with growing radii"
                    ));
                }
            }
            if outer.spacing < inner.spacing {
                return Err(format!(
                    "layer {n}: spacing = {} is finer than layer {p}'s spacing = {}: spacing must \
                     not decrease outward (a coarser inner layer makes no sense); raise layer \
                     {n}'s spacing or lower layer {p}'s",
                    outer.spacing, inner.spacing
                ));
            }
        }

        let blend = self.blend_deg;
        if !(blend.is_finite() && blend >= 0.0) {
            return Err(format!(
                "blend_deg = {blend} must be a finite width of 0 degrees or more (0 turns \
                 blending off)"
            ));
        }
        // Each band lies just inside its layer's radius, so it needs that much room inward.
        let mut previous: Option<f32> = None;
        for (index, layer) in self.layers.iter().enumerate() {
            let n = index + 1;
            let Some(radius) = layer.radius_deg else {
                continue;
            };
            match previous {
                None if radius < blend => {
                    return Err(format!(
                        "layer {n}: radius_deg = {radius} is smaller than blend_deg = {blend}, so \
                         its blend band would reach past the gaze point: raise radius_deg or \
                         lower blend_deg"
                    ));
                }
                Some(prev) if radius - prev < blend => {
                    return Err(format!(
                        "layer {n}: radius_deg = {radius} is only {} degrees beyond layer {}'s \
                         radius_deg = {prev}, less than blend_deg = {blend}, so the blend bands \
                         would overlap: widen the gap between the radii or lower blend_deg",
                        radius - prev,
                        index
                    ));
                }
                _ => {}
            }
            previous = Some(radius);
        }

        if let Some(occlusion) = self.occlusion_deg {
            if !(occlusion.is_finite() && occlusion > 0.0 && occlusion <= 180.0) {
                return Err(format!(
                    "occlusion_deg = {occlusion} must be a finite angle greater than 0 and at \
                     most 180 degrees; leave it out for no occlusion mask"
                ));
            }
        }
        Ok(())
    }

    /// Parses TOML text (format below), then validates. `origin` names the source in error messages (a path or `"<inline>"`).
    ///
    /// ```toml
    /// blend_deg = 1.0          # optional, default 1.0
    /// occlusion_deg = 55.0     # optional, default: no mask
    /// [[layer]]
    /// radius_deg = 6.0
    /// spacing = 1
    /// spp = 4                  # optional, default 4
    /// [[layer]]                # no radius_deg: the background layer
    /// spacing = 4
    /// ```
    ///
    /// Unknown fields are errors, so a misspelt field is reported rather than silently ignored.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, FoveationError> {
        let file: ConfigFile = toml::from_str(text).map_err(|error| FoveationError::Parse {
            origin: origin.to_owned(),
            message: error.to_string().trim_end().to_owned(),
        })?;
        let config = Self {
            layers: file.layer,
            blend_deg: file.blend_deg,
            occlusion_deg: file.occlusion_deg,
        };
        config
            .check()
            .map_err(|problem| FoveationError::InvalidIn {
                origin: origin.to_owned(),
                problem,
            })?;
        Ok(config)
    }

    /// Reads and parses a TOML file; the error names the path.
    pub fn load(path: &Path) -> Result<Self, FoveationError> {
        let text = std::fs::read_to_string(path).map_err(|source| FoveationError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// The CLI value of `--foveation`: "off" → None (regular rendering), "thesis" → Some(thesis()), anything else is a TOML file path → Some(load(path)). A path that does not exist gives an error that lists the accepted values.
    pub fn from_arg(arg: &str) -> Result<Option<Self>, FoveationError> {
        match arg {
            "off" => Ok(None),
            "thesis" => Ok(Some(Self::thesis())),
            path => {
                let path = Path::new(path);
                // A typo such as "thesiss" lands here; listing the keywords helps more than an
                // io "not found".
                if !path.exists() {
                    return Err(FoveationError::UnknownArg {
                        arg: arg.to_owned(),
                    });
                }
                Self::load(path).map(Some)
            }
        }
    }

    /// TOML text for this config (round-trips through from_toml_str).
    ///
    /// Written by hand rather than through `toml::to_string` so it cannot fail and keeps the
    /// field order and comments of the files in `assets/foveation/`.
    pub fn to_toml(&self) -> String {
        let mut lines = vec![
            "# fovea foveation config (format: see assets/foveation/thesis.toml)".to_owned(),
            format!("blend_deg = {}", toml_float(self.blend_deg)),
        ];
        match self.occlusion_deg {
            Some(occlusion) => lines.push(format!("occlusion_deg = {}", toml_float(occlusion))),
            None => lines.push("# no occlusion_deg: no occlusion mask".to_owned()),
        }
        for layer in &self.layers {
            lines.push(String::new());
            lines.push("[[layer]]".to_owned());
            match layer.radius_deg {
                Some(radius) => lines.push(format!("radius_deg = {}", toml_float(radius))),
                None => lines.push("# no radius_deg: the background layer".to_owned()),
            }
            lines.push(format!("spacing = {}", layer.spacing));
            lines.push(format!("spp = {}", layer.spp));
            if layer.fraction > 1 {
                lines.push(format!("fraction = {}", layer.fraction));
            }
            // What follows the history's surfaces, where the layer asks for it.
            if layer.denoise > 0 {
                lines.push(format!("denoise = {}", layer.denoise));
            }
            let widths = [
                ("denoise_mar", layer.denoise_mar),
                ("filter_mar", layer.filter_mar),
                ("filter_px", layer.filter_px),
            ];
            for (name, value) in widths.into_iter().filter(|&(_, v)| v != 0.0) {
                lines.push(format!("{name} = {}", toml_float(value)));
            }
            if layer.denoise_sigma != DEFAULT_DENOISE_SIGMA {
                lines.push(format!(
                    "denoise_sigma = {}",
                    toml_float(layer.denoise_sigma)
                ));
            }
        }
        lines.push(String::new());
        lines.join("\n")
    }
}

/// An `f32` as a TOML float that parses back to the same value.
///
/// `{:?}` prints the shortest text that round-trips and always marks a float ("6.0", "1e-7"),
/// which TOML accepts; only the non-finite spellings differ between Rust and TOML.
fn toml_float(value: f32) -> String {
    if value.is_nan() {
        "nan".to_owned()
    } else if value.is_infinite() {
        if value > 0.0 { "inf" } else { "-inf" }.to_owned()
    } else {
        format!("{value:?}")
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod denoise_tests;

#[cfg(test)]
mod fraction_tests;
