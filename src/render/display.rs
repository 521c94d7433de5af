//! What a display shows of scene-referred radiance: an exposure (a power of two) and a tone
//! mapper into [0, 1], before the sRGB encoding of an 8-bit PNG. EXR files stay linear and
//! scene-referred; only what is shown goes through this.
//!
//! `clamp` is what fovea always did (built-in scenes keep it, so their PNGs are unchanged);
//! `pbr-neutral` is the Khronos PBR Neutral tone mapper (2024), the default for glTF scenes,
//! whose sunlit highlights would otherwise burn out to white.

/// How radiance past the display's white is brought into range.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Tonemap {
    /// Clip each channel to [0, 1] (fovea's behaviour before tone mapping existed).
    Clamp,
    /// Khronos PBR Neutral: exact below 0.76, highlights compressed and desaturated.
    PbrNeutral,
}

/// What the command line asked of the display (`--exposure`, `--tonemap`): each scene's
/// transform follows from it ([`DisplayChoice::transform`]). Kept in bench and tune plans, so
/// a resumed run scores as the first part did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DisplayChoice {
    pub exposure: f32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tonemap: Option<Tonemap>,
}

impl DisplayChoice {
    /// The transform for a scene named on the command line.
    pub fn transform(&self, scene: &str) -> DisplayTransform {
        DisplayTransform::for_scene(scene, self.exposure, self.tonemap)
    }

    /// No exposure and each scene's default tone mapper (what plans without a choice mean).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// Exposure and tone mapper, as a display applies them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayTransform {
    /// Stops: radiance is multiplied by 2^exposure before tone mapping.
    pub exposure: f32,
    pub tonemap: Tonemap,
}

impl DisplayTransform {
    /// Today's display: no exposure change, clipped.
    pub const CLAMP: Self = Self {
        exposure: 0.0,
        tonemap: Tonemap::Clamp,
    };

    /// The transform for a scene named on the command line: `tonemap` when given, else clamp
    /// for a built-in scene and PBR Neutral for a glTF file.
    pub fn for_scene(scene: &str, exposure: f32, tonemap: Option<Tonemap>) -> Self {
        let file = crate::scene::is_scene_file(scene);
        let default = if file {
            Tonemap::PbrNeutral
        } else {
            Tonemap::Clamp
        };
        Self {
            exposure,
            tonemap: tonemap.unwrap_or(default),
        }
    }

    /// The display-referred linear colour in [0, 1] of scene-referred `rgb`.
    pub fn apply(&self, rgb: [f32; 3]) -> [f32; 3] {
        let scale = self.exposure.exp2();
        // A NaN or infinite sample shows as black, as the clamped encoding always did.
        let rgb = rgb.map(|c| {
            if c.is_finite() {
                (c * scale).max(0.0)
            } else {
                0.0
            }
        });
        match self.tonemap {
            Tonemap::Clamp => rgb.map(|c| c.min(1.0)),
            Tonemap::PbrNeutral => pbr_neutral(rgb).map(|c| c.clamp(0.0, 1.0)),
        }
    }

    /// The 8-bit sRGB bytes a PNG stores for linear RGB triples.
    pub fn srgb8(&self, rgb: &[f32]) -> Vec<u8> {
        rgb.chunks_exact(3)
            .flat_map(|p| self.apply([p[0], p[1], p[2]]))
            .map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8)
            .collect()
    }
}

/// Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral/README.md): subtract a small
/// offset f from dark colours, and past a peak of K_s = 0.76 compress the peak towards 1 and
/// desaturate towards white. Input non-negative linear Rec. 709, output in [0, 1].
pub fn pbr_neutral(rgb: [f32; 3]) -> [f32; 3] {
    const F90: f32 = 0.04;
    const START: f32 = 0.8 - F90;
    const DESATURATION: f32 = 0.15;
    let x = rgb[0].min(rgb[1]).min(rgb[2]);
    let offset = if x < 2.0 * F90 {
        x - x * x / (4.0 * F90)
    } else {
        F90
    };
    let c = rgb.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < START {
        return c;
    }
    let d = 1.0 - START;
    let new_peak = 1.0 - d * d / (peak + d - START);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.map(|v| v * new_peak / peak * (1.0 - g) + new_peak * g)
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1].
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The 8-bit sRGB encoding of linear values, as our PNGs store them (and as FLIP and the
/// bench's pictures see them).
pub fn linear_to_srgb8(linear: &[f32]) -> Vec<u8> {
    linear
        .iter()
        .map(|&v| (linear_to_srgb(v) * 255.0 + 0.5) as u8)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The specification's form of the mapping (f, p, p_n, g and the two cases), written
    /// separately from the implementation's, in f64.
    fn specification(c: [f64; 3]) -> [f64; 3] {
        let (f90, ks, kd) = (0.04, 0.8 - 0.04, 0.15);
        let x = c[0].min(c[1]).min(c[2]);
        let f = if x <= 2.0 * f90 {
            x - x * x / (4.0 * f90)
        } else {
            f90
        };
        let p = (c[0] - f).max(c[1] - f).max(c[2] - f);
        if p <= ks {
            return c.map(|v| v - f);
        }
        let pn = 1.0 - (1.0 - ks) * (1.0 - ks) / (p + 1.0 - 2.0 * ks);
        let g = 1.0 / (kd * (p - pn) + 1.0);
        c.map(|v| (v - f) * pn / p * g + pn * (1.0 - g))
    }

    #[test]
    fn pbr_neutral_matches_the_specification_on_a_ramp() {
        let mut worst = 0.0f64;
        for i in 0..=400 {
            let t = i as f32 / 400.0;
            // A grey ramp to 20, a saturated one and a dim bluish one.
            for rgb in [
                [20.0 * t * t; 3],
                [8.0 * t, 2.0 * t, 0.5 * t],
                [0.05 * t, 0.1 * t, 0.3 * t],
            ] {
                let ours = pbr_neutral(rgb);
                let spec = specification(rgb.map(f64::from));
                for k in 0..3 {
                    worst = worst.max((ours[k] as f64 - spec[k]).abs());
                }
                assert!(
                    ours.iter().all(|&c| (-1e-6..=1.0).contains(&c)),
                    "{rgb:?} → {ours:?}"
                );
            }
        }
        assert!(worst < 1e-5, "largest difference {worst}");
    }

    #[test]
    fn pbr_neutral_keeps_mid_colours_less_the_offset_and_compresses_highlights() {
        // The specification's guarantee: 0.08 ≤ every channel ≤ 0.8 comes out as c − 0.04.
        let out = pbr_neutral([0.5, 0.2, 0.1]);
        for (o, i) in out.iter().zip([0.5, 0.2, 0.1]) {
            assert!((o - (i - 0.04)).abs() < 1e-6, "{out:?}");
        }
        // Brighter input never comes out darker, and approaches white.
        let ramp: Vec<f32> = (0..100)
            .map(|i| pbr_neutral([i as f32 * 0.5; 3])[0])
            .collect();
        assert!(ramp.windows(2).all(|w| w[1] >= w[0]), "{ramp:?}");
        assert!(ramp[99] > 0.99 && ramp[99] <= 1.0);
    }

    #[test]
    fn clamp_encodes_as_the_pngs_always_did_and_exposure_doubles_per_stop() {
        let values = [
            0.0,
            0.001,
            0.2,
            0.5,
            1.0,
            3.0,
            -1.0,
            f32::NAN,
            f32::INFINITY,
        ];
        let rgb: Vec<f32> = values.iter().flat_map(|&v| [v; 3]).collect();
        let old: Vec<u8> = rgb
            .iter()
            .map(|&v| (linear_to_srgb(v) * 255.0 + 0.5) as u8)
            .collect();
        assert_eq!(DisplayTransform::CLAMP.srgb8(&rgb), old);
        let up = DisplayTransform {
            exposure: 1.0,
            ..DisplayTransform::CLAMP
        };
        assert_eq!(up.apply([0.2, 0.3, 0.7]), [0.4, 0.6, 1.0]);
    }

    #[test]
    fn gltf_files_default_to_pbr_neutral_and_built_in_scenes_to_clamp() {
        let t = |scene: &str, choice| DisplayTransform::for_scene(scene, 0.0, choice).tonemap;
        assert_eq!(t("cornell", None), Tonemap::Clamp);
        assert_eq!(t("assets/gltf/alpha-card.glb", None), Tonemap::PbrNeutral);
        assert_eq!(t("Model.GLTF", None), Tonemap::PbrNeutral);
        assert_eq!(t("model.glb", Some(Tonemap::Clamp)), Tonemap::Clamp);
        assert_eq!(t("cornell", Some(Tonemap::PbrNeutral)), Tonemap::PbrNeutral);
    }
}
