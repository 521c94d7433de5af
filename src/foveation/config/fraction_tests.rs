use super::*;

#[test]
fn fraction_is_read_per_layer_defaults_to_every_point_and_is_checked() {
    let text = "[[layer]]\nradius_deg = 5.0\nspacing = 1\nfraction = 2\n[[layer]]\nspacing = 2\n";
    let config = FoveationConfig::from_toml_str(text, "t.toml").unwrap();
    assert_eq!(
        (config.layers[0].fraction, config.layers[1].fraction),
        (2, 1)
    );
    assert!(config.fractional() && !FoveationConfig::thesis().fractional());
    // A config tracing every point writes no fraction (older plans read the same).
    let written = toml::to_string(&FoveationConfig::thesis()).unwrap();
    assert!(!written.contains("fraction"), "{written}");
    // One full-resolution layer that traces half its pixels is not regular rendering.
    let mut half = FoveationConfig::regular(4);
    half.layers[0].fraction = 2;
    assert!(half.validate().is_ok() && !half.is_regular());
    for (bad, says) in [
        ("fraction = 3", "fraction = 3 must be one of [1, 2, 4]"),
        ("fraction = 0", "fraction = 0 must be one of [1, 2, 4]"),
        (
            "fraction = 2\nfilter_px = 1.0",
            "the lattice filter (filter_mar, filter_px) smooths",
        ),
    ] {
        let text = text.replace("fraction = 2", bad);
        let err = FoveationConfig::from_toml_str(&text, "t.toml").unwrap_err();
        assert!(err.to_string().contains(says), "{bad}: {err}");
    }
}
