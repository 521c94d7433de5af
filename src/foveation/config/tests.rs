use super::*;

const THESIS_TOML: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/foveation/thesis.toml");
const WIDE_TOML: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/foveation/wide-fovea.toml"
);

/// The validation problem of `config`, as text; panics if it validates.
fn problem(config: &FoveationConfig) -> String {
    match config.validate() {
        Ok(()) => panic!("config should be rejected: {config:?}"),
        Err(error) => error.to_string(),
    }
}

/// Asserts that `config` is rejected with a message containing every one of `needles`.
fn assert_rejected(config: &FoveationConfig, needles: &[&str]) {
    let message = problem(config);
    for needle in needles {
        assert!(
            message.contains(needle),
            "message {message:?} lacks {needle:?}"
        );
    }
}

#[test]
fn thesis_values() {
    let config = FoveationConfig::thesis();
    let radii: Vec<_> = config.layers.iter().map(|l| l.radius_deg).collect();
    assert_eq!(radii, [Some(6.0), Some(10.0), Some(20.0), None]);
    let spacings: Vec<_> = config.layers.iter().map(|l| l.spacing).collect();
    assert_eq!(spacings, [1, 2, 3, 4]);
    assert!(config.layers.iter().all(|l| l.spp == 4));
    assert_eq!(config.blend_deg, 1.0);
    assert_eq!(config.occlusion_deg, Some(56.0));
    assert!(!config.is_regular());
}

#[test]
fn thesis_validates() {
    FoveationConfig::thesis().validate().unwrap();
}

#[test]
fn regular_validates_and_is_regular() {
    let config = FoveationConfig::regular(4);
    config.validate().unwrap();
    assert!(config.is_regular());
    assert_eq!(
        config.layers,
        [Layer {
            radius_deg: None,
            spacing: 1,
            spp: 4,
            denoise: 0,
            filter_mar: 0.0,
            filter_px: 0.0,
            denoise_mar: 0.0,
            denoise_sigma: DEFAULT_DENOISE_SIGMA,
            fraction: 1,
        }]
    );
    // One layer that is coarser than 1 is not regular rendering.
    let mut coarse = config;
    coarse.layers[0].spacing = 2;
    assert!(!coarse.is_regular());
}

#[test]
fn with_spp_replaces_every_layer() {
    let config = FoveationConfig::thesis().with_spp(16);
    assert!(config.layers.iter().all(|l| l.spp == 16));
    let spacings: Vec<_> = config.layers.iter().map(|l| l.spacing).collect();
    assert_eq!(spacings, [1, 2, 3, 4]);
    assert_eq!(FoveationConfig::regular(4).with_spp(1).layers[0].spp, 1);
}

#[test]
fn thesis_asset_is_thesis() {
    let config = FoveationConfig::load(Path::new(THESIS_TOML)).unwrap();
    assert_eq!(config, FoveationConfig::thesis());
}

#[test]
fn wide_fovea_asset_parses() {
    let config = FoveationConfig::load(Path::new(WIDE_TOML)).unwrap();
    config.validate().unwrap();
    let radii: Vec<_> = config.layers.iter().map(|l| l.radius_deg).collect();
    assert_eq!(radii, [Some(10.0), Some(20.0), Some(30.0), None]);
    let spacings: Vec<_> = config.layers.iter().map(|l| l.spacing).collect();
    assert_eq!(spacings, [1, 2, 3, 4]);
    assert!(config.layers.iter().all(|l| l.spp == 4));
    assert_eq!(config.blend_deg, 2.0);
    assert_eq!(config.occlusion_deg, Some(60.0));
}

#[test]
fn to_toml_round_trips() {
    let mut odd = FoveationConfig::thesis().with_spp(7);
    odd.blend_deg = 0.1;
    odd.occlusion_deg = Some(55.3);
    odd.layers[0].radius_deg = Some(1.0e-1 + 6.0);
    // What follows the history (a tuned config may ask for any of it) is written too.
    (odd.layers[1].denoise, odd.layers[1].denoise_mar) = (2, 1.5);
    (odd.layers[2].filter_mar, odd.layers[3].filter_px) = (0.5, 2.0);
    odd.layers[0].fraction = 4;
    for config in [
        FoveationConfig::thesis(),
        FoveationConfig::regular(1),
        FoveationConfig::load(Path::new(WIDE_TOML)).unwrap(),
        odd,
    ] {
        let text = config.to_toml();
        let back = FoveationConfig::from_toml_str(&text, "<inline>").unwrap();
        assert_eq!(back, config, "round trip through:\n{text}");
    }
}

#[test]
fn toml_defaults_and_integer_angles() {
    let config = FoveationConfig::from_toml_str(
        "[[layer]]\nradius_deg = 6\nspacing = 1\n[[layer]]\nspacing = 2\n",
        "<inline>",
    )
    .unwrap();
    assert_eq!(config.blend_deg, 1.0);
    assert_eq!(config.occlusion_deg, None);
    assert_eq!(config.layers[0].radius_deg, Some(6.0));
    assert!(config.layers.iter().all(|l| l.spp == 4));
}

#[test]
fn rejects_layer_count() {
    let mut empty = FoveationConfig::thesis();
    empty.layers.clear();
    assert_rejected(&empty, &["layer"]);

    let mut many = FoveationConfig::regular(1);
    many.blend_deg = 0.0;
    many.layers = (1..=MAX_LAYERS)
        .map(|i| Layer {
            radius_deg: Some(i as f32),
            spacing: 1,
            spp: 1,
            denoise: 0,
            filter_mar: 0.0,
            filter_px: 0.0,
            denoise_mar: 0.0,
            denoise_sigma: DEFAULT_DENOISE_SIGMA,
            fraction: 1,
        })
        .collect();
    many.layers.push(Layer {
        radius_deg: None,
        spacing: 1,
        spp: 1,
        denoise: 0,
        filter_mar: 0.0,
        filter_px: 0.0,
        denoise_mar: 0.0,
        denoise_sigma: DEFAULT_DENOISE_SIGMA,
        fraction: 1,
    });
    assert_rejected(&many, &["9 layers", "8"]);
    // Exactly MAX_LAYERS is fine.
    many.layers.remove(0);
    many.validate().unwrap();
}

#[test]
fn rejects_missing_background_layer() {
    let mut config = FoveationConfig::thesis();
    config.layers.pop();
    assert_rejected(&config, &["layer 3", "radius_deg", "background"]);
}

#[test]
fn rejects_background_layer_not_last() {
    let mut config = FoveationConfig::thesis();
    config.layers.swap(2, 3);
    assert_rejected(&config, &["layer 3", "radius_deg", "last"]);
}

#[test]
fn rejects_bad_radius() {
    for bad in [0.0, -1.0, 180.0, 400.0, f32::NAN, f32::INFINITY] {
        let mut config = FoveationConfig::thesis();
        config.layers[2].radius_deg = Some(bad);
        assert_rejected(&config, &["layer 3", "radius_deg"]);
    }
}

#[test]
fn rejects_radii_not_growing() {
    let mut config = FoveationConfig::thesis();
    config.layers[1].radius_deg = Some(6.0);
    assert_rejected(&config, &["layer 2", "radius_deg", "larger"]);
    config.layers[1].radius_deg = Some(3.0);
    assert_rejected(&config, &["layer 2", "radius_deg"]);
}

#[test]
fn rejects_bad_blend() {
    for bad in [-0.5, f32::NAN, f32::INFINITY] {
        let mut config = FoveationConfig::thesis();
        config.blend_deg = bad;
        assert_rejected(&config, &["blend_deg"]);
    }
}

#[test]
fn rejects_overlapping_blend_bands() {
    // Innermost radius smaller than the band.
    let mut config = FoveationConfig::thesis();
    config.blend_deg = 4.0;
    config.layers[0].radius_deg = Some(3.0);
    assert_rejected(&config, &["layer 1", "radius_deg", "blend_deg"]);
    // Gap 6 -> 10 is 4 degrees, less than a 5 degree band.
    let mut config = FoveationConfig::thesis();
    config.blend_deg = 5.0;
    assert_rejected(&config, &["layer 2", "blend_deg", "overlap"]);
    // A gap exactly as wide as the band is allowed.
    config.blend_deg = 4.0;
    config.validate().unwrap();
}

#[test]
fn rejects_bad_spacing() {
    for bad in [0, MAX_SPACING + 1] {
        let mut config = FoveationConfig::thesis();
        config.layers[3].spacing = bad;
        assert_rejected(&config, &["layer 4", "spacing"]);
    }
}

#[test]
fn rejects_spacing_decreasing_outward() {
    let mut config = FoveationConfig::thesis();
    config.layers[0].spacing = 3;
    assert_rejected(&config, &["layer 2", "spacing", "decrease"]);
    // Equal spacings are fine.
    config.layers[0].spacing = 2;
    config.validate().unwrap();
}

#[test]
fn rejects_bad_spp() {
    for bad in [0, MAX_LAYER_SPP + 1] {
        let mut config = FoveationConfig::thesis();
        config.layers[1].spp = bad;
        assert_rejected(&config, &["layer 2", "spp"]);
    }
    FoveationConfig::thesis()
        .with_spp(MAX_LAYER_SPP)
        .validate()
        .unwrap();
}

#[test]
fn rejects_bad_occlusion() {
    for bad in [0.0, -10.0, 180.5, f32::NAN, f32::INFINITY] {
        let mut config = FoveationConfig::thesis();
        config.occlusion_deg = Some(bad);
        assert_rejected(&config, &["occlusion_deg"]);
    }
    let mut config = FoveationConfig::thesis();
    config.occlusion_deg = Some(180.0);
    config.validate().unwrap();
}

#[test]
fn invalid_toml_names_origin() {
    let error =
        FoveationConfig::from_toml_str("[[layer]]\nradius_deg = 6.0\nspacing = 1\n", "my.toml")
            .unwrap_err()
            .to_string();
    assert!(error.contains("my.toml"), "{error}");
    assert!(error.contains("background"), "{error}");
}

#[test]
fn rejects_unknown_field() {
    let error = FoveationConfig::from_toml_str(
        "[[layer]]\nradius = 6.0\nspacing = 1\n[[layer]]\nspacing = 2\n",
        "<inline>",
    )
    .unwrap_err()
    .to_string();
    assert!(error.contains("radius"), "{error}");
    assert!(error.contains("unknown field"), "{error}");

    let error = FoveationConfig::from_toml_str("blend = 1.0\n[[layer]]\nspacing = 1\n", "top.toml")
        .unwrap_err()
        .to_string();
    assert!(error.contains("`blend`"), "{error}");
    assert!(error.contains("top.toml"), "{error}");
}

#[test]
fn bad_whole_numbers_say_what_the_field_takes() {
    for (text, needles) in [
        (
            "spacing = -1",
            &["`-1`", "whole number of pixels from 1 to 64"][..],
        ),
        ("spacing = 1.5", &["1.5", "whole number of pixels"][..]),
        ("spacing = \"a\"", &["whole number of pixels"][..]),
        (
            "spacing = 1\nspp = 99999999999",
            &["99999999999", "samples per target pixel"][..],
        ),
        (
            "spacing = 1\nspp = -4",
            &["`-4`", "samples per target pixel"][..],
        ),
    ] {
        let error = FoveationConfig::from_toml_str(&format!("[[layer]]\n{text}\n"), "n.toml")
            .unwrap_err()
            .to_string();
        for needle in needles {
            assert!(error.contains(needle), "{text}: {error} lacks {needle}");
        }
    }
}

#[test]
fn from_arg_keywords() {
    assert_eq!(FoveationConfig::from_arg("off").unwrap(), None);
    assert_eq!(
        FoveationConfig::from_arg("thesis").unwrap(),
        Some(FoveationConfig::thesis())
    );
    assert_eq!(
        FoveationConfig::from_arg(WIDE_TOML).unwrap(),
        Some(FoveationConfig::load(Path::new(WIDE_TOML)).unwrap())
    );
}

#[test]
fn from_arg_missing_path_lists_accepted_values() {
    let error = FoveationConfig::from_arg("/no/such/foveation.toml")
        .unwrap_err()
        .to_string();
    assert!(error.contains("/no/such/foveation.toml"), "{error}");
    assert!(error.contains("'off'"), "{error}");
    assert!(error.contains("'thesis'"), "{error}");
}

#[test]
fn load_error_names_path() {
    // A directory exists, so from_arg goes on to read it and fails there.
    let dir = env!("CARGO_MANIFEST_DIR");
    let error = FoveationConfig::from_arg(dir).unwrap_err().to_string();
    assert!(error.contains(dir), "{error}");
}
