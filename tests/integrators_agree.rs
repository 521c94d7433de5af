//! `pt` and `seed` estimate the same integral on `cornell` (all diffuse, where the thesis'
//! estimator is unbiased): their image means agree within the noise both carry.

mod common;

use fovea::render::Integrator;
use fovea::scene::builtin::builtin;

/// Mean and standard error of the image mean per channel and per 8x8 block, estimated from
/// two renders with independent seeds (their difference measures the noise).
fn block_means(rgb: &[f32], w: usize, block: usize) -> Vec<[f64; 3]> {
    let h = rgb.len() / 3 / w;
    let mut out = Vec::new();
    for by in (0..h).step_by(block) {
        for bx in (0..w).step_by(block) {
            let mut sum = [0.0f64; 3];
            for y in by..by + block {
                for x in bx..bx + block {
                    for c in 0..3 {
                        sum[c] += rgb[3 * (y * w + x) + c] as f64;
                    }
                }
            }
            out.push(sum.map(|s| s / (block * block) as f64));
        }
    }
    out
}

#[test]
fn pt_and_seed_agree_on_cornell_at_high_spp() {
    let ctx = common::context();
    let scene = builtin("cornell", 1.0).unwrap();
    let (w, block) = (32usize, 16usize);
    let run = |integrator, spp, seed| {
        let f = common::render(&ctx, &scene, &common::settings(w as u32, w as u32, spp, seed, integrator));
        block_means(&f.rgb, w, block)
    };
    let pt = [run(Integrator::Pt, 256, 1), run(Integrator::Pt, 256, 2)];
    let seed = [run(Integrator::Seed, 1024, 3), run(Integrator::Seed, 1024, 4)];
    let mut worst_z = 0.0f64;
    for b in 0..pt[0].len() {
        for c in 0..3 {
            let mean = |r: &[Vec<[f64; 3]>; 2]| 0.5 * (r[0][b][c] + r[1][b][c]);
            // Var of the mean of two runs = (x1 − x2)² / 4 in expectation (unbiased for one pair).
            let var = |r: &[Vec<[f64; 3]>; 2]| (r[0][b][c] - r[1][b][c]).powi(2) / 4.0;
            // Floor the noise estimate at 0.5% of the value: a single pair can be close by chance.
            let floor = (0.005 * mean(&pt)).powi(2);
            let se = (var(&pt) + var(&seed) + floor).sqrt();
            let z = (mean(&pt) - mean(&seed)).abs() / se;
            worst_z = worst_z.max(z);
            assert!(z < 5.0, "block {b} channel {c}: pt {} vs seed {} (z = {z:.1})", mean(&pt), mean(&seed));
        }
    }
    eprintln!("pt vs seed on cornell: worst block z-score {worst_z:.2}");
}
