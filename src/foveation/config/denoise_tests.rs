use super::*;

#[test]
fn denoise_is_read_per_layer_defaults_to_none_and_is_bounded() {
    let text = "[[layer]]\nradius_deg = 5.0\nspacing = 1\n[[layer]]\nspacing = 2\ndenoise = 3\n";
    let config = FoveationConfig::from_toml_str(text, "t.toml").unwrap();
    assert_eq!(config.layers[0].denoise, 0);
    assert_eq!(config.layers[1].denoise, 3);
    assert_eq!(config.denoise_iterations(), 3);
    assert_eq!(FoveationConfig::thesis().denoise_iterations(), 0);
    let too_many = text.replace("denoise = 3", "denoise = 6");
    let err = FoveationConfig::from_toml_str(&too_many, "t.toml").unwrap_err();
    assert!(
        err.to_string().contains("denoise = 6 must be in 0..=5"),
        "{err}"
    );
}

#[test]
fn the_lattice_filter_is_read_per_layer_defaults_to_none_and_is_bounded() {
    let text =
        "[[layer]]\nradius_deg = 5.0\nspacing = 1\n[[layer]]\nspacing = 2\nfilter_mar = 1.5\n";
    let config = FoveationConfig::from_toml_str(text, "t.toml").unwrap();
    assert_eq!(config.layers[0].filter_mar, 0.0);
    assert_eq!(config.layers[1].filter_mar, 1.5);
    assert!(config.filters() && !config.layers[0].filters());
    assert!(!FoveationConfig::thesis().filters());
    // A config without a filter writes no filter fields (older plans read the same).
    let written = toml::to_string(&FoveationConfig::thesis()).unwrap();
    assert!(!written.contains("filter"), "{written}");
    for (bad, says) in [
        ("filter_mar = -1.0", "filter_mar = -1 must be in 0..=16"),
        ("filter_mar = nan", "filter_mar = NaN must be in 0..=16"),
        (
            "filter_px = 65.0",
            "filter_px = 65 must be in 0..=64 pixels",
        ),
    ] {
        let text = text.replace("filter_mar = 1.5", bad);
        let err = FoveationConfig::from_toml_str(&text, "t.toml").unwrap_err();
        assert!(err.to_string().contains(says), "{bad}: {err}");
    }
}

#[test]
fn the_denoisers_acuity_limit_is_read_per_layer_defaults_to_none_and_is_bounded() {
    let text = "[[layer]]\nradius_deg = 5.0\nspacing = 1\n[[layer]]\nspacing = 1\ndenoise = 3\n\
                denoise_mar = 2.0\n";
    let config = FoveationConfig::from_toml_str(text, "t.toml").unwrap();
    assert_eq!(config.layers[0].denoise_mar, 0.0);
    assert_eq!(config.layers[1].denoise_mar, 2.0);
    let written = toml::to_string(&FoveationConfig::thesis()).unwrap();
    assert!(!written.contains("denoise_mar"), "{written}");
    let round_trip = FoveationConfig::from_toml_str(&config.to_toml(), "t.toml");
    assert_eq!(round_trip.unwrap(), config);
    // Without history a config renders without the denoiser, its limit too.
    assert_eq!(config.without_history_filters().layers[1].denoise_mar, 0.0);
    for (bad, says) in [
        ("denoise_mar = -1.0", "denoise_mar = -1 must be in 0..=16"),
        ("denoise_mar = inf", "denoise_mar = inf must be in 0..=16"),
    ] {
        let text = text.replace("denoise_mar = 2.0", bad);
        let err = FoveationConfig::from_toml_str(&text, "t.toml").unwrap_err();
        assert!(err.to_string().contains(says), "{bad}: {err}");
    }
}

#[test]
fn the_denoisers_edge_stop_is_read_per_layer_defaults_to_4_and_is_bounded() {
    let text = "[[layer]]\nradius_deg = 20.0\nspacing = 1\nspp = 4\ndenoise = 3\n\
                denoise_sigma = 1.0\n[[layer]]\nspacing = 1\nspp = 1\ndenoise = 3\n";
    let config = FoveationConfig::from_toml_str(text, "t.toml").unwrap();
    assert_eq!(config.layers[0].denoise_sigma, 1.0);
    assert_eq!(config.layers[1].denoise_sigma, DEFAULT_DENOISE_SIGMA);
    // The default is not written (older files read the same); another value is, and reads back.
    let written = config.to_toml();
    assert_eq!(written.matches("denoise_sigma").count(), 1, "{written}");
    let round_trip = FoveationConfig::from_toml_str(&written, "t.toml");
    assert_eq!(round_trip.unwrap(), config);
    let serde_written = toml::to_string(&FoveationConfig::thesis()).unwrap();
    assert!(!serde_written.contains("denoise_sigma"), "{serde_written}");
    // Without history a config renders without the denoiser, its edge-stop too.
    let without = config.without_history_filters();
    assert!(without
        .layers
        .iter()
        .all(|l| l.denoise_sigma == DEFAULT_DENOISE_SIGMA));
    for (bad, says) in [
        (
            "denoise_sigma = 0.0",
            "denoise_sigma = 0 must be in 0.25..=16 standard deviations",
        ),
        (
            "denoise_sigma = 17.0",
            "denoise_sigma = 17 must be in 0.25..=16",
        ),
        (
            "denoise_sigma = nan",
            "denoise_sigma = NaN must be in 0.25..=16",
        ),
    ] {
        let text = text.replace("denoise_sigma = 1.0", bad);
        let err = FoveationConfig::from_toml_str(&text, "t.toml").unwrap_err();
        assert!(err.to_string().contains(says), "{bad}: {err}");
    }
}
