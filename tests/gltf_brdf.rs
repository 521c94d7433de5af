//! glTF's metallic-roughness BRDF on the GPU (glsl/gltf_brdf.glsl): its sampler draws the
//! density it reports (chi-square, as Mitsuba's and pbrt's tests do), its values are the
//! specification's (against an independent CPU implementation) and reciprocal, a white
//! furnace shows exactly its albedo. (`pt` and `seed` agreeing on a scene of glTF
//! materials, which checks MIS, is in tests/integrators_agree.rs.)

mod common;

use fovea::check::brdf_sampling::{
    evaluation_test, probe_renderer, sampling_test, sampling_test_against,
};
use fovea::check::gltf_brdf::GltfBrdf;
use fovea::check::gltf_furnace::gltf_furnace;
use fovea::scene::{Coverage, MetallicRoughness};
use glam::Vec3;

fn materials() -> Vec<MetallicRoughness> {
    let mut out = Vec::new();
    for roughness in [0.4, 0.7, 1.0] {
        out.push(MetallicRoughness {
            base_color: Vec3::new(0.9, 0.6, 0.3),
            metallic: 1.0,
            roughness,
            emission: Vec3::ZERO,
            textures: Default::default(),
            coverage: Coverage::SOLID,
        });
        out.push(MetallicRoughness {
            base_color: Vec3::new(0.2, 0.5, 0.8),
            metallic: 0.0,
            roughness,
            emission: Vec3::ZERO,
            textures: Default::default(),
            coverage: Coverage::SOLID,
        });
    }
    out
}

#[test]
fn the_samplers_directions_follow_its_density() {
    let ctx = common::context();
    let materials = materials();
    let mut renderer = probe_renderer(&ctx, &materials).unwrap();
    let angles = [10.0, 50.0, 80.0];
    let tests = materials.len() * angles.len();
    // 1% for the whole family, Šidák-corrected per test.
    let per_test = 1.0 - 0.99f64.powf(1.0 / tests as f64);
    let mut failures = Vec::new();
    for (index, m) in materials.iter().enumerate() {
        for (k, &theta) in angles.iter().enumerate() {
            let seed = (index * angles.len() + k) as u64;
            let t = sampling_test(&mut renderer, index as u32, theta, 100_000, seed).unwrap();
            eprintln!(
                "{m:?} at {theta}°: chi² {:.1} ({} dof), p {:.3}, density integral {:.4}, \
                 absorbed {}",
                t.chi_square.statistic,
                t.chi_square.degrees_of_freedom,
                t.chi_square.p_value,
                t.density_integral,
                t.absorbed
            );
            // The density is a density: it integrates to at most 1 (the rest is what the
            // sampler sends below the surface).
            assert!(t.density_integral <= 1.0 + 2e-3, "{m:?} at {theta}°: {t:?}");
            if t.chi_square.p_value < per_test {
                failures.push(format!("{m:?} at {theta}°: {t:?}"));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "rejected at {per_test:.1e}: {failures:#?}"
    );
    common::assert_no_validation_messages(&ctx);
}

#[test]
fn a_sampler_that_draws_another_density_is_rejected() {
    // The test has power: directions drawn for roughness 0.7 fail against roughness 1's
    // density, a difference a renderer would show as a visibly wrong highlight.
    let ctx = common::context();
    let materials = materials();
    let mut renderer = probe_renderer(&ctx, &materials).unwrap();
    let (glossy, rough) = (2, 4); // metals at roughness 0.7 and 1.0
    let wrong = sampling_test_against(&mut renderer, glossy, rough, 50.0, 100_000, 1).unwrap();
    assert!(wrong.chi_square.p_value < 1e-9, "{wrong:?}");
}

#[test]
fn its_values_are_the_specifications_and_reciprocal() {
    let ctx = common::context();
    let materials = materials();
    let mut renderer = probe_renderer(&ctx, &materials).unwrap();
    for (index, m) in materials.iter().enumerate() {
        let reference = GltfBrdf {
            base_color: m.base_color.as_dvec3(),
            metallic: m.metallic as f64,
            roughness: m.roughness as f64,
        };
        let t = evaluation_test(&mut renderer, index as u32, &reference, 20_000, 5).unwrap();
        eprintln!("{m:?}: {t:?}");
        assert!(t.worst_relative_error < 2e-3, "{m:?}: {t:?}");
        assert!(t.worst_reciprocity_error < 1e-4, "{m:?}: {t:?}");
    }
}

#[test]
fn a_white_furnace_shows_exactly_the_albedo() {
    let ctx = common::context();
    let results = gltf_furnace(&ctx, 32, 256).unwrap();
    for r in &results {
        eprintln!(
            "{} {:?}: {:.4} ± {:.4}, expected {:.4}",
            r.material, r.integrator, r.mean, r.std_error, r.expected
        );
    }
    for r in results {
        assert_eq!(r.nonfinite_samples, 0, "{r:?}");
        // Within 4 standard errors, plus 0.5% for the quadrature and for pixel centres
        // standing in for the pixels' footprints.
        let tolerance = 4.0 * r.std_error + 0.005 * r.expected;
        assert!((r.mean - r.expected).abs() < tolerance, "{r:?}");
        // A white metal reflects at most what it receives: single-scattering GGX loses the
        // light that would scatter again among the microfacets. (glTF's white dielectric may
        // not: the specification mixes its Lambertian base by 1 − F(v·h), which at roughness
        // 0.5 reflects 0.7% more than it receives, by the CPU reference too.)
        if r.material.contains("metallic=1") {
            assert!(r.mean < 1.0 + 4.0 * r.std_error, "creates energy: {r:?}");
        }
    }
    common::assert_no_validation_messages(&ctx);
}
