//! Convergence (issue 7, item 4): RMSE against a converged reference falls as spp^(-1/2) for
//! both integrators, and `pt` has the lower error at equal spp and at equal GPU time, on
//! `cornell` and `mirror-room`. Every measurement is one `check::convergence::measure` call
//! at 48x48, spp 1..64, 4 seeds per point, references of 1024 spp; the module docs say which
//! reference each number is against.
//!
//! Measured on lavapipe (5 independent seed bases, 48x48): slopes of `pt` −0.48..−0.52 on
//! cornell, −0.498..−0.502 on mirror-room; of `seed` −0.47..−0.53 on cornell. pt/seed error
//! ratio 0.32..0.36 at equal spp and 0.31..0.42 at equal GPU time on cornell, 0.17..0.22 and
//! 0.21..0.36 on mirror-room.

mod common;

use fovea::check::convergence::{measure, Convergence, ConvergenceOptions};
use fovea::render::Integrator;
use fovea::scene::builtin::builtin;
use fovea::scene::Scene;

fn options() -> ConvergenceOptions {
    ConvergenceOptions {
        width: 48,
        height: 48,
        spp: vec![1, 2, 4, 8, 16, 32, 64],
        seeds: 4,
        reference_spp: 1024,
        max_bounces: 8,
        seed: 1,
    }
}

/// Measures `scene`, prints the report, and checks what holds for every scene: no broken
/// samples, no validation messages.
fn run(scene: &Scene) -> Convergence {
    let ctx = common::context();
    let c = measure(&ctx, scene, &options(), &mut |_, _| {}).expect("convergence measurement");
    common::assert_no_validation_messages(&ctx);
    eprintln!("{c}");
    assert_eq!(c.nonfinite_samples, 0, "non-finite samples in {}", c.scene);
    assert_eq!(c.stack_overflows, 0, "BVH stack overflows in {}", c.scene);
    assert_eq!(c.renders, 2 * (1024 / 32 + 7 * 4));
    c
}

/// The slope of `ln rmse` against `ln spp` (own reference) is −1/2 ± 0.1, on a clean line.
fn assert_monte_carlo_rate(c: &Convergence, integrator: Integrator) {
    let fit = c
        .integrator(integrator)
        .and_then(|i| i.fit_spp)
        .expect("a fit");
    assert!(
        (fit.slope + 0.5).abs() <= 0.1 && fit.r2 > 0.9,
        "{integrator:?} on {}: RMSE falls with slope {:.3} (R² {:.3}), not −1/2",
        c.scene,
        fit.slope,
        fit.r2
    );
}

/// `pt` has the lower error at equal spp and at equal GPU time.
///
/// Equal GPU time is asserted too although lavapipe's timestamps are CPU wall time on a
/// shared machine (a point's GPU ms varied by up to 2x between runs): the equal-time ratio
/// is the equal-spp ratio times the square root of the cost ratio, so with an equal-spp
/// ratio near 0.3 the timings would have to be wrong by a factor (1/0.3)² ≈ 11 in `seed`'s
/// favour to flip it, and the integrators alternate render by render, so load changes fall
/// on both alike.
fn assert_pt_wins(c: &Convergence) {
    assert!(
        c.ratio_equal_spp < 1.0,
        "{}: pt/seed error ratio at equal spp is {:.3}",
        c.scene,
        c.ratio_equal_spp
    );
    assert!(
        c.ratio_equal_time < 1.0,
        "{}: pt/seed error ratio at equal GPU time is {:.3}",
        c.scene,
        c.ratio_equal_time
    );
}

#[test]
fn cornell_converges_at_the_monte_carlo_rate_and_pt_has_less_error() {
    let c = run(&builtin("cornell", 1.0).unwrap());
    assert_monte_carlo_rate(&c, Integrator::Pt);
    assert_monte_carlo_rate(&c, Integrator::Seed);
    assert_pt_wins(&c);
    // All diffuse, where the thesis' estimator is unbiased: both references agree within
    // their noise (measured |z| ≤ 1.7).
    for (channel, z) in c.seed_bias.mean_z.iter().enumerate() {
        assert!(
            z.abs() < 5.0,
            "cornell channel {channel}: seed's converged mean differs from pt's by {z:.1} standard errors"
        );
    }
}

/// `seed`'s slope on mirror-room is not asserted: its error is heavy-tailed. It samples the
/// glossy sphere's α = 200 Phong lobe uniformly, so a bounce there weighs up to
/// k_s(α+2)/p_S ≈ 170 with a probability of order 1/400, compounded through the mirrors. Its
/// variance is finite but carried by paths so rare that 48x48 pixels x 1..64 spp mostly miss
/// them: the measured slope wanders (−0.40..−0.54, R² 0.44..0.99, over 6 seed bases and
/// sizes), and the reference's own variance is as large as the 64-spp error. The test
/// below shows that the lobe is the cause.
#[test]
fn mirror_room_pt_converges_at_the_monte_carlo_rate_and_has_less_error() {
    let c = run(&builtin("mirror-room", 1.0).unwrap());
    assert_monte_carlo_rate(&c, Integrator::Pt);
    assert_pt_wins(&c);
}

/// mirror-room with its glossy sphere made Lambertian (same k_d, no Phong lobe): `seed`
/// converges at −1/2 again (measured −0.499, R² 0.9997), so its heavy tail on the real scene
/// comes from the uniformly sampled lobe.
///
/// `pt` is not asserted to win here: on this variant its error is about 2x `seed`'s
/// (measured 2.03 at equal spp). With `max_bounces` 3 (below where Russian roulette starts)
/// `pt` wins again (0.70), so the likely cause is roulette on the chains of emissive mirrors,
/// where `seed`'s paths are deterministic and `pt`'s are cut at random.
#[test]
fn mirror_room_without_the_glossy_lobe_seed_converges_at_the_monte_carlo_rate() {
    let mut scene = builtin("mirror-room", 1.0).unwrap();
    let mut glossy = 0;
    for m in &mut scene.materials {
        if let fovea::scene::Material::Thesis(m) = m {
            if m.ks.max_element() > 0.0 && m.alpha.is_finite() {
                m.ks = glam::Vec3::ZERO;
                glossy += 1;
            }
        }
    }
    assert_eq!(glossy, 1, "mirror-room has one glossy material");
    let c = run(&scene);
    assert_monte_carlo_rate(&c, Integrator::Pt);
    assert_monte_carlo_rate(&c, Integrator::Seed);
}
