//! `fovea gpu-report` at a size where one config's lattice exceeds the device's limits in
//! stereo (as a wide fovea does at the Varjo XR-4's whole panel): the report records that case
//! with the renderer's reason and times every other case, the stereo frames after it too.

mod common;

use fovea::foveation::FoveationConfig;
use fovea::gpu::GpuContext;
use fovea::realtime::{self, RealtimePlan};
use std::sync::Arc;

/// Seven gaze-anchored layers, each wide enough that its lattice spans twice the image each
/// way (about 4 × width × height entries), and a background: about 29 lattice values per
/// pixel of each eye.
const WIDE: &str = "blend_deg = 1.0\n\
    [[layer]]\nradius_deg = 45.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nradius_deg = 50.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nradius_deg = 55.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nradius_deg = 60.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nradius_deg = 65.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nradius_deg = 70.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nradius_deg = 75.0\nspacing = 1\nspp = 1\n\
    [[layer]]\nspacing = 1\nspp = 1\n";

/// A quick report's plan on cornell at `side`² per eye timing `modes`, one frame each, with
/// no fovea spp search and no headset sessions.
fn plan_of(side: u32, modes: Vec<(&str, FoveationConfig)>) -> RealtimePlan {
    let mut plan = RealtimePlan::quick(side, side);
    plan.scenes = vec!["cornell".into()];
    plan.modes.clear();
    for (name, config) in modes {
        plan.add_mode(name, config);
    }
    (plan.warmup, plan.frames) = (0, 1);
    plan.budgets_ms.clear();
    plan.frames_in_flight.clear();
    plan
}

/// A quick report on cornell at `side`² per eye timing WIDE, then `also` if given, one frame
/// each, with no fovea spp search and no headset sessions: its report.json.
fn report_of(
    ctx: &Arc<GpuContext>,
    side: u32,
    also: Option<FoveationConfig>,
    name: &str,
) -> serde_json::Value {
    let wide = FoveationConfig::from_toml_str(WIDE, "wide").unwrap();
    let mut modes = vec![("wide", wide)];
    modes.extend(also.map(|config| ("regular", config)));
    let plan = plan_of(side, modes);
    let dir = common::test_dir(name);
    realtime::run(ctx, &plan, &dir, "test".into(), &mut |_| {}).expect("the report runs");
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("Cases this device cannot hold"), "{md}");
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

#[test]
fn a_case_over_the_devices_limits_is_recorded_and_the_report_goes_on() {
    let ctx = common::context();
    // The most lattice values (16 bytes each) one buffer may hold: lavapipe's 128 MiB storage
    // buffer range, NVIDIA's 2^27 texels. An image whose eye holds 3/4 of it fits mono, not
    // stereo.
    let limit = (ctx.info.max_storage_buffer_range / 16).min(ctx.info.max_texel_buffer_elements);
    let side = ((0.75 * limit as f64 / 29.0).sqrt() as u32).min(4096);
    let report = report_of(
        &ctx,
        side,
        Some(FoveationConfig::regular(1)),
        "gpu_report_limits",
    );
    let timed: Vec<(String, u64)> = report["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["mode"].as_str().unwrap().to_string(),
                f["eyes"].as_u64().unwrap(),
            )
        })
        .collect();
    let traversals = report["frames"].as_array().unwrap().len() / 3;
    assert!(traversals >= 1, "{timed:?}");
    for eyes in [1, 2] {
        assert!(timed.contains(&("regular".into(), eyes)), "{timed:?}");
    }
    assert!(
        timed.contains(&("wide".into(), 1)),
        "{timed:?} {}",
        report["over_limits"]
    );
    assert!(!timed.contains(&("wide".into(), 2)), "{timed:?}");

    let over = report["over_limits"].as_array().unwrap();
    assert_eq!(over.len(), traversals, "{over:?}");
    assert_eq!(over[0]["mode"], "wide");
    assert_eq!(over[0]["eyes"], 2);
    let why = over[0]["why"].as_str().unwrap();
    let names_the_limit =
        why.contains("maxStorageBufferRange") || why.contains("maxTexelBufferElements");
    assert!(why.contains("lattice values") && names_the_limit, "{why}");
    common::assert_no_validation_messages(&ctx);
}

#[test]
fn a_lattice_over_the_texel_limit_is_refused_before_anything_is_allocated() {
    let ctx = common::context();
    // An image whose eye needs more lattice values than one texel view holds, even in mono.
    let limit = ctx.info.max_texel_buffer_elements;
    let side = ((1.1 * limit as f64 / 29.0).sqrt() as u32).min(ctx.info.max_image_dimension_2d);
    let report = report_of(&ctx, side, None, "gpu_report_texel_limit");
    assert_eq!(report["frames"].as_array().unwrap().len(), 0);
    // Mono meets the lattice's limit; stereo may meet another first (lavapipe's 128 MiB
    // storage buffers hold fewer pixels of two eyes).
    let over = report["over_limits"].as_array().unwrap();
    let with = |eyes: u64| over.iter().filter(|o| o["eyes"] == eyes).count();
    assert!(with(1) >= 1 && with(1) == with(2), "{over:?}");
    let mono = over.iter().find(|o| o["eyes"] == 1).expect("mono recorded");
    let why = mono["why"].as_str().unwrap();
    assert!(
        why.contains("maxTexelBufferElements") && why.contains("radius_deg"),
        "{why}"
    );
    assert!(
        ctx.memory_peak() < 1 << 30,
        "{} bytes held: the check comes before the allocations",
        ctx.memory_peak()
    );
    common::assert_no_validation_messages(&ctx);
}

#[test]
fn a_config_that_cannot_run_as_asked_still_stops_the_report() {
    // Bad input, not a device limit: denoising needs the history, which this plan leaves off.
    let ctx = common::context();
    let denoised = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/foveation/thesis-denoised.toml");
    let plan = plan_of(
        32,
        vec![("denoised", FoveationConfig::load(&denoised).unwrap())],
    );
    let dir = common::test_dir("gpu_report_bad_config");
    let error = realtime::run(&ctx, &plan, &dir, "test".into(), &mut |_| {})
        .expect_err("a denoised config without history is refused");
    assert!(error.contains("temporal history"), "{error}");
}
