//! An environment as the shaders read it (shared.h's BINDING_ENVIRONMENT): per texel, its
//! radiance and the probability of choosing it, then where it starts in its row's and its
//! row in the map's cumulative distribution. Next-event estimation inverts the two (a row by
//! one coordinate of a 2-D sample, a column in it by the other) and keeps each coordinate's
//! remainder as the position inside the texel: one stratified pair of numbers becomes one
//! stratified set of directions (a blue-noise sampler's pair stays a pair), where an alias
//! table's buckets scatter neighbouring numbers over the map. Texel k of a W × H map at polar
//! angle θ covers 2π²/(W·H) · sin θ of solid angle, so a direction in it has density
//! pmf[k] · W·H / (2π² sin θ).

use super::env_map::{EnvSampling, EnvironmentLight};
use super::lights::luminance;

/// A scene's environment as the GPU layout takes it: texels (empty without one), size and turn.
pub struct GpuEnvironment {
    pub texels: Vec<[u32; 4]>,
    pub width: u32,
    pub height: u32,
    pub rotate_deg: f32,
}

impl GpuEnvironment {
    pub fn of(env: Option<&EnvironmentLight>) -> Self {
        let Some(env) = env else {
            return Self {
                texels: Vec::new(),
                width: 0,
                height: 0,
                rotate_deg: 0.0,
            };
        };
        let started = std::time::Instant::now();
        let texels = environment_texels(env);
        tracing::info!(
            "environment {} × {}: radiance and sampling table built in {:.1} ms",
            env.map.width,
            env.map.height,
            started.elapsed().as_secs_f64() * 1e3
        );
        Self {
            texels,
            width: env.map.width,
            height: env.map.height,
            rotate_deg: env.rotate_deg,
        }
    }
}

/// The GPU's texels of `env`: two per environment texel, rows from the top. First
/// (r, g, b, pmf) as float bits, the radiance × `env.intensity`; then (the row's cumulative
/// probability before this texel, given the row; the map's cumulative probability before
/// this texel's row; 0, 0), as float bits.
pub fn environment_texels(env: &EnvironmentLight) -> Vec<[u32; 4]> {
    let map = &env.map;
    let (w, h) = (map.width as usize, map.height as usize);
    let filtered = match env.sampling {
        EnvSampling::Importance => bilinear_texel_means(map),
        EnvSampling::Uniform => vec![1.0; w * h],
    };
    let weights: Vec<f64> = (0..w * h)
        .map(|i| {
            let theta = ((i / w) as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            filtered[i] * theta.sin()
        })
        .collect();
    let rows: Vec<f64> = weights.chunks(w).map(|r| r.iter().sum()).collect();
    let total: f64 = rows.iter().sum();
    let mut texels = Vec::with_capacity(2 * w * h);
    let mut before_row = 0.0;
    for (row, row_sum) in rows.iter().enumerate() {
        let mut before_texel = 0.0;
        for col in 0..w {
            let i = row * w + col;
            let l = map.texels[i] * env.intensity;
            let pmf = (weights[i] / total) as f32;
            texels.push([l.x.to_bits(), l.y.to_bits(), l.z.to_bits(), pmf.to_bits()]);
            // A row of zero weight is never chosen; its columns' starts are spread evenly.
            let conditional = match *row_sum > 0.0 {
                true => before_texel / row_sum,
                false => col as f64 / w as f64,
            };
            let marginal = before_row / total;
            texels.push([
                (conditional as f32).to_bits(),
                (marginal as f32).to_bits(),
                0,
                0,
            ]);
            before_texel += weights[i];
        }
        before_row += row_sum;
    }
    texels
}

/// Per texel, the mean luminance of the bilinear radiance the shaders read over the texel's
/// area: its neighbours' luminance weighted (1/8, 3/4, 1/8) along each axis (columns wrap,
/// rows clamp at the poles). Sampling by the texel's own value instead would give the texels
/// around a one-texel sun, into which bilinear filtering spreads a quarter of its light, the
/// density of their dim selves: fireflies of thousands where a path finds them otherwise.
fn bilinear_texel_means(map: &super::EnvironmentMap) -> Vec<f64> {
    let (w, h) = (map.width as usize, map.height as usize);
    let lum: Vec<f64> = map.texels.iter().map(|t| luminance(*t) as f64).collect();
    let tent = [(-1i64, 0.125), (0, 0.75), (1, 0.125)];
    let mut out = vec![0.0; w * h];
    for row in 0..h {
        for col in 0..w {
            let mut sum = 0.0;
            for (dy, wy) in tent {
                let r = (row as i64 + dy).clamp(0, h as i64 - 1) as usize;
                for (dx, wx) in tent {
                    let c = (col as i64 + dx).rem_euclid(w as i64) as usize;
                    sum += wx * wy * lum[r * w + c];
                }
            }
            out[row * w + col] = sum;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::env_map::EnvironmentMap;
    use glam::Vec3;
    use std::sync::Arc;

    fn env(texels: Vec<Vec3>, w: u32, sampling: EnvSampling) -> EnvironmentLight {
        let map = EnvironmentMap::from_texels("t.exr".as_ref(), w, w / 2, texels).unwrap();
        EnvironmentLight {
            map: Arc::new(map),
            rotate_deg: 0.0,
            intensity: 2.0,
            sampling,
        }
    }

    #[test]
    fn a_bright_texel_is_chosen_in_proportion_to_the_light_filtering_gives_it() {
        let mut texels = vec![Vec3::splat(1.0); 8];
        texels[5] = Vec3::splat(7.0); // row 1 (of 2): the same sin θ as row 0
        let gpu = environment_texels(&env(texels, 4, EnvSampling::Importance));
        let pmf = |i: usize| f32::from_bits(gpu[2 * i][3]);
        // Texel 5's bilinear mean: 1 + 6 × (3/4 along x) × (7/8 along y, its row clamped).
        let mean = |extra: f32| 1.0 + 6.0 * extra;
        let total = 8.0 + 6.0; // the bright texel's excess spreads but is not created
        assert!(
            (pmf(5) - mean(0.75 * 0.875) / total).abs() < 1e-6,
            "{}",
            pmf(5)
        );
        // Texel 0 (column 0, row 0) is its diagonal neighbour; texel 3 (column 3) is not.
        assert!(
            (pmf(0) - mean(0.125 * 0.125) / total).abs() < 1e-6,
            "{}",
            pmf(0)
        );
        assert!((pmf(3) - 1.0 / total).abs() < 1e-6, "{}", pmf(3));
        // Radiance × intensity.
        assert_eq!(f32::from_bits(gpu[10][0]), 14.0);
        let uniform = environment_texels(&env(vec![Vec3::ONE; 8], 4, EnvSampling::Uniform));
        assert!((f32::from_bits(uniform[10][3]) - 1.0 / 8.0).abs() < 1e-6);
    }

    #[test]
    fn each_texel_knows_where_it_and_its_row_start_in_the_distribution() {
        let starts = |gpu: &[[u32; 4]], i: usize| {
            let t = gpu[2 * i + 1];
            (f32::from_bits(t[0]), f32::from_bits(t[1]))
        };
        let pmf = |gpu: &[[u32; 4]], i: usize| f32::from_bits(gpu[2 * i][3]);
        // 4 × 2, uniform: every texel weighs its sin θ, the same in both rows.
        let gpu = environment_texels(&env(vec![Vec3::ONE; 8], 4, EnvSampling::Uniform));
        assert_eq!(starts(&gpu, 0), (0.0, 0.0));
        assert_eq!(starts(&gpu, 3), (0.75, 0.0));
        assert_eq!(starts(&gpu, 4), (0.0, 0.5));
        assert_eq!(starts(&gpu, 6), (0.5, 0.5));
        // A bright texel in row 1 widens its row's interval of the map and its own of the row:
        // each interval is the probability of what it holds.
        let texels = (0..8)
            .map(|i| Vec3::splat(if i == 6 { 5.0 } else { 1.0 }))
            .collect();
        let gpu = environment_texels(&env(texels, 4, EnvSampling::Importance));
        let row_0: f32 = (0..4).map(|i| pmf(&gpu, i)).sum();
        assert!((starts(&gpu, 4).1 - row_0).abs() < 1e-6 && row_0 < 0.5);
        for i in 4..7 {
            let interval = starts(&gpu, i + 1).0 - starts(&gpu, i).0;
            assert!(
                (interval - pmf(&gpu, i) / (1.0 - row_0)).abs() < 1e-6,
                "texel {i}"
            );
        }
    }
}
