//! Every built-in scene renders cleanly on the device, and rendering is reproducible.

mod common;

use fovea::render::Integrator;
use fovea::scene::builtin::{builtin, BUILTIN_SCENES};

#[test]
fn every_builtin_scene_renders_at_64x64_without_validation_messages_or_bad_samples() {
    let ctx = common::context();
    for integrator in [Integrator::Pt, Integrator::Seed] {
        for (name, _) in BUILTIN_SCENES {
            let scene = builtin(name, 1.0).unwrap();
            let frame = common::render(&ctx, &scene, &common::settings(64, 64, 2, 7, integrator));
            assert!(
                frame.rgb.iter().all(|v| v.is_finite() && *v >= 0.0),
                "{name}: bad pixel values"
            );
            let mean = frame.mean();
            assert!(
                mean.iter().any(|&m| m > 1e-3),
                "{name} ({integrator:?}) rendered black: {mean:?}"
            );
            assert!(
                frame
                    .stats
                    .pass_ms
                    .iter()
                    .any(|(p, ms)| p == "trace" && *ms > 0.0),
                "no trace timing"
            );
        }
    }
}

#[test]
fn same_seed_gives_identical_image_and_another_seed_a_different_one() {
    let ctx = common::context();
    let scene = builtin("cornell", 1.0).unwrap();
    let a = common::render(
        &ctx,
        &scene,
        &common::settings(32, 32, 4, 11, Integrator::Pt),
    );
    let b = common::render(
        &ctx,
        &scene,
        &common::settings(32, 32, 4, 11, Integrator::Pt),
    );
    let c = common::render(
        &ctx,
        &scene,
        &common::settings(32, 32, 4, 12, Integrator::Pt),
    );
    let bits = |f: &fovea::render::Frame| f.rgb.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b), "same seed must be bit-identical");
    let differing = a.rgb.iter().zip(&c.rgb).filter(|(x, y)| x != y).count();
    assert!(
        differing > a.rgb.len() / 2,
        "another seed changed only {differing} values"
    );
}

#[test]
fn destroying_everything_leaves_the_validation_layer_silent() {
    // Leaked Vulkan objects are reported while the device is destroyed, after every
    // resource's owner is gone: read the log once the context itself has been dropped.
    let ctx = common::context();
    let log = ctx.validation_log();
    let scene = builtin("mirror-room", 1.0).unwrap();
    common::render(
        &ctx,
        &scene,
        &common::settings(16, 16, 1, 1, Integrator::Pt),
    );
    assert_eq!(
        std::sync::Arc::strong_count(&ctx),
        1,
        "a resource still holds the context"
    );
    drop(ctx);
    let messages = log.take();
    assert!(
        messages.is_empty(),
        "validation messages at exit:\n{}",
        messages.join("\n")
    );
}
