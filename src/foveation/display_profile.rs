//! The headsets fovea renders for, as their makers' spec sheets give them: one eye's image size
//! and field of view, and the display's photometry, which FovVideoVDP needs to judge what the
//! eye sees (`--display`).

use super::view::EyeFov;
use super::FoveationConfig;
use crate::render::FovChoice;

/// A display's luminance range in cd/m²: what a display-encoded 1 and 0 emit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photometry {
    pub peak_cd_m2: f64,
    pub black_cd_m2: f64,
}

/// `--display`: a headset's eye image and display.
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
pub enum DisplayProfile {
    /// HTC Vive Pro Eye: 1440×1600 per eye over about 105°×111°, 133 cd/m² peak (about 14 px/°).
    #[default]
    ViveProEye,
    /// Varjo XR-4: 3840×3744 per eye over 120°×105°, 200 cd/m² peak, 10000:1 (32 px/°).
    #[value(name = "varjo-xr-4")]
    #[serde(rename = "varjo-xr-4")]
    VarjoXr4,
}

impl DisplayProfile {
    pub fn name(self) -> &'static str {
        match self {
            DisplayProfile::ViveProEye => "vive-pro-eye",
            DisplayProfile::VarjoXr4 => "varjo-xr-4",
        }
    }

    /// One eye's image size in pixels (width, height): the panel's.
    pub fn eye_size(self) -> (u32, u32) {
        match self {
            DisplayProfile::ViveProEye => EyeFov::VIVE_PRO_EYE_SIZE,
            DisplayProfile::VarjoXr4 => EyeFov::VARJO_XR_4_SIZE,
        }
    }

    /// The eyes' fields of view.
    pub fn fov(self) -> FovChoice {
        match self {
            DisplayProfile::ViveProEye => FovChoice::ViveProEye,
            DisplayProfile::VarjoXr4 => FovChoice::VarjoXr4,
        }
    }

    /// The left eye's field of view (the right mirrors it).
    pub fn left_eye_fov(self) -> EyeFov {
        match self {
            DisplayProfile::ViveProEye => EyeFov::VIVE_PRO_EYE_LEFT,
            DisplayProfile::VarjoXr4 => EyeFov::VARJO_XR_4,
        }
    }

    /// What FovVideoVDP is told of the display's luminance.
    pub fn photometry(self) -> Photometry {
        match self {
            // pyfvvdp's `htc_vive_pro` model (Mantiuk et al., from arXiv:1912.02913).
            DisplayProfile::ViveProEye => Photometry {
                peak_cd_m2: 133.3,
                black_cd_m2: 0.1,
            },
            // Varjo's XR-4 spec sheet: 200 nits, local-dimming contrast 10000:1.
            DisplayProfile::VarjoXr4 => Photometry {
                peak_cd_m2: 200.0,
                black_cd_m2: 0.02,
            },
        }
    }

    /// Where the numbers come from.
    pub fn source(self) -> &'static str {
        match self {
            DisplayProfile::ViveProEye => {
                "HTC's Vive Pro Eye panels (1440×1600 per eye); field of view as SteamVR \
                 reports it; photometry from pyfvvdp's htc_vive_pro (arXiv:1912.02913)"
            }
            DisplayProfile::VarjoXr4 => {
                "Varjo XR-4 spec sheet (varjo.com/products/xr-4): 3840×3744 per eye, 120°×105° \
                 field of view, 200 nits, 10000:1 contrast, 51 px/° at the lens centre"
            }
        }
    }

    /// The headset an OpenXR runtime reports: by its system name (XrSystemProperties), or
    /// failing that by its recommended per-eye image size being the panel's.
    pub fn recognise(system_name: &str, eye_size: [u32; 2]) -> Option<Self> {
        let name = system_name.to_lowercase();
        let all = [DisplayProfile::ViveProEye, DisplayProfile::VarjoXr4];
        let named = |p: &DisplayProfile| match p {
            DisplayProfile::ViveProEye => name.contains("vive pro eye"),
            DisplayProfile::VarjoXr4 => name.contains("xr-4") || name.contains("xr4"),
        };
        let sized = |p: &DisplayProfile| {
            let (w, h) = p.eye_size();
            eye_size == [w, h]
        };
        all.iter()
            .copied()
            .find(named)
            .or(all.into_iter().find(sized))
    }

    /// The foveation config fovea ships for this headset (`assets/foveation/NAME.toml`,
    /// built into the binary), which `fovea xr` uses unless told otherwise. Option, so that a
    /// profile added before its config has been measured can say so.
    pub fn shipped_foveation(self) -> Option<(&'static str, FoveationConfig)> {
        let (file, text) = match self {
            DisplayProfile::ViveProEye => (
                "assets/foveation/vive-pro-eye.toml",
                include_str!("../../assets/foveation/vive-pro-eye.toml"),
            ),
            DisplayProfile::VarjoXr4 => (
                "assets/foveation/varjo-xr-4.toml",
                include_str!("../../assets/foveation/varjo-xr-4.toml"),
            ),
        };
        let config = FoveationConfig::from_toml_str(text, file).expect("shipped configs are valid");
        Some((file, config))
    }

    /// One eye's mean horizontal density: its pixels over its horizontal field of view in
    /// degrees (the figure spec sheets and the "13 px/°" use). A flat image holds
    /// fewer pixels per degree at its centre than this, more at its edges.
    pub fn pixels_per_degree(self) -> f64 {
        let fov = self.left_eye_fov();
        let width_deg = (fov.right - fov.left) as f64 * 180.0 / std::f64::consts::PI;
        self.eye_size().0 as f64 / width_deg
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_profiles_densities_are_the_spec_sheets() {
        let vive = DisplayProfile::ViveProEye.pixels_per_degree();
        let varjo = DisplayProfile::VarjoXr4.pixels_per_degree();
        assert!((13.0..14.5).contains(&vive), "{vive}");
        assert!((varjo - 32.0).abs() < 0.01, "{varjo}");
    }

    #[test]
    fn a_runtime_is_recognised_by_name_then_by_size() {
        let vive = Some(DisplayProfile::ViveProEye);
        assert_eq!(
            DisplayProfile::recognise("HTC Vive Pro Eye", [2016, 2240]),
            vive
        );
        assert_eq!(
            DisplayProfile::recognise("SteamVR/OpenXR : lighthouse", [1440, 1600]),
            vive
        );
        let varjo = DisplayProfile::recognise("Varjo XR-4", [2880, 2808]);
        assert_eq!(varjo, Some(DisplayProfile::VarjoXr4));
        assert_eq!(DisplayProfile::recognise("Quest 3", [2064, 2208]), None);
    }

    #[test]
    fn the_shipped_configs_are_valid_and_foveated() {
        for profile in [DisplayProfile::ViveProEye, DisplayProfile::VarjoXr4] {
            let (file, config) = profile.shipped_foveation().unwrap();
            assert_eq!(file, format!("assets/foveation/{}.toml", profile.name()));
            assert!(config.validate().is_ok() && !config.is_regular(), "{file}");
        }
    }
}
