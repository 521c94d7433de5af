//! Convergence of both integrators: root-mean-square error against a converged reference as
//! the sample count grows, for `pt` and `seed` on one scene.
//!
//! An unbiased Monte Carlo estimator's error falls as `spp^(-1/2)`, a line of slope −1/2 on a
//! log-log plot; a flatter line means bias (a floor), heavy tails (fireflies that few samples
//! miss) or correlated samples. Between the integrators, `pt` should have the lower error both
//! at equal samples per pixel and at equal GPU time.
//!
//! Which reference for which number:
//! - **Slopes** are about each estimator's variance, so each integrator is measured against its
//!   *own* converged reference: a bias of `seed` (if any) would otherwise show as a floor that
//!   bends its line, and mix two questions into one number.
//! - **pt/seed ratios** are against the physically correct answer, `pt`'s reference, for both
//!   integrators: an error `seed` makes by converging to a different image is error.
//! - The difference between the two references is reported as `seed`'s **bias**
//!   ([`ReferenceBias`]), never hidden.
//!
//! References are the mean of several renders of [`REFERENCE_CHUNK_SPP`] samples with their own
//! seeds, like `bench::quality`'s. Their spread gives each pixel's variance of the reference
//! mean, and that variance is subtracted from every MSE: for a test image `x` independent of
//! the reference `r`, `E[(x − r)²] = E[(x − μ)²] + Var(r)`, so the corrected figure estimates
//! the error against the exact image and a finite reference does not flatten the slope at the
//! high-spp end. The uncorrected RMSE is kept beside it.

use crate::bench::stats::median;
use crate::gpu::GpuContext;
use crate::metrics;
use crate::render::{Integrator, RenderError, RenderSettings, Renderer};
use crate::scene::Scene;
use serde::Serialize;
use std::sync::Arc;

/// Samples per pixel of one reference render (as `bench::quality`'s): no single dispatch runs
/// long enough to trip a GPU watchdog, and the chunks' spread measures the reference's noise.
pub const REFERENCE_CHUNK_SPP: u32 = 32;

/// Seeds of reference renders are this xor [`ConvergenceOptions::seed`] plus the chunk index,
/// far from those of the measured renders (`seed + point · seeds + repeat`), so that no
/// reference shares random numbers with an image it judges.
const REFERENCE_SEED_BASE: u32 = 0x5eed_0000;

/// What to measure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConvergenceOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the measured points, e.g. 1, 2, 4, …, 64; at least two distinct.
    pub spp: Vec<u32>,
    /// Independent renders (distinct seeds) per point; their MSEs are averaged.
    pub seeds: u32,
    /// Samples per pixel of each integrator's reference, rendered in chunks of
    /// [`REFERENCE_CHUNK_SPP`] (rounded up to whole chunks, at least two). At least 8 × the
    /// largest point's spp, so that the reference's noise is a small correction.
    pub reference_spp: u32,
    pub max_bounces: u32,
    /// First seed of the measured renders; another value gives an independent measurement.
    pub seed: u32,
}

impl Default for ConvergenceOptions {
    fn default() -> Self {
        Self {
            width: 64,
            height: 64,
            spp: (0..7).map(|k| 1 << k).collect(),
            seeds: 4,
            reference_spp: 2048,
            max_bounces: 8,
            seed: 1,
        }
    }
}

impl ConvergenceOptions {
    /// Rejects option sets that cannot give a fit or a trustworthy reference.
    pub fn validate(&self) -> Result<(), String> {
        let mut distinct = self.spp.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 2 || distinct[0] == 0 {
            return Err(format!(
                "convergence needs at least two distinct positive spp values to fit a slope, got {:?}",
                self.spp
            ));
        }
        if self.seeds == 0 {
            return Err("convergence needs at least one seed per point".into());
        }
        let largest = *distinct.last().expect("two values");
        if (self.reference_spp as u64) < 8 * largest as u64 {
            return Err(format!(
                "reference spp {} is less than 8 x the largest point's {largest} spp: the \
                 reference would be as noisy as the images it judges",
                self.reference_spp
            ));
        }
        RenderSettings {
            width: self.width,
            height: self.height,
            spp: largest.max(REFERENCE_CHUNK_SPP),
            max_bounces: self.max_bounces,
            ..RenderSettings::default()
        }
        .validate()
    }

    /// Chunks of the reference and samples per chunk.
    fn reference_chunks(&self) -> (u32, u32) {
        let chunks = self.reference_spp.div_ceil(REFERENCE_CHUNK_SPP).max(2);
        (chunks, self.reference_spp.div_ceil(chunks))
    }
}

/// A least-squares line `ln y = intercept + slope · ln x`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LogLogFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination of the fit in log-log space (1 = every point on the line).
    pub r2: f64,
}

impl LogLogFit {
    /// Fits the points with positive, finite `x` and `y`; `None` with fewer than two distinct
    /// `x`.
    pub fn fit(points: &[(f64, f64)]) -> Option<Self> {
        let logs: Vec<(f64, f64)> = points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
            .map(|(x, y)| (x.ln(), y.ln()))
            .collect();
        let n = logs.len() as f64;
        let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
        let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let syy: f64 = logs.iter().map(|p| (p.1 - my).powi(2)).sum();
        if logs.len() < 2 || sxx <= 0.0 {
            return None;
        }
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let r2 = if syy > 0.0 {
            sxy * sxy / (sxx * syy)
        } else {
            1.0
        };
        Some(Self {
            slope,
            intercept,
            r2,
        })
    }

    /// The fitted `y` at `x`.
    pub fn at(&self, x: f64) -> f64 {
        (self.intercept + self.slope * x.ln()).exp()
    }
}

/// One measured sample count of one integrator.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ConvergencePoint {
    pub spp: u32,
    /// RMSE against this integrator's own reference: the root of the MSE averaged over the
    /// seeds (the quadratic mean of their RMSEs, as MSE is what adds up), less the
    /// reference's own variance (see the module docs).
    pub rmse: f64,
    /// The same without subtracting the reference's variance.
    pub rmse_raw: f64,
    /// RMSE against `pt`'s reference (the physically correct image), corrected the same way;
    /// equal to `rmse` for `pt`.
    pub rmse_vs_pt: f64,
    /// Median over the seeds of the frame's GPU time (every pass, from timestamp queries).
    pub gpu_ms: f64,
}

/// How one integrator converges.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IntegratorConvergence {
    pub integrator: Integrator,
    pub points: Vec<ConvergencePoint>,
    /// `ln rmse` against `ln spp` (own reference): slope −1/2 for an unbiased estimator.
    pub fit_spp: Option<LogLogFit>,
    /// `ln rmse_vs_pt` against `ln spp`: the same against `pt`'s reference, which bends
    /// away from −1/2 toward a floor if this integrator converges to another image.
    pub fit_spp_vs_pt: Option<LogLogFit>,
    /// `ln rmse_vs_pt` against `ln gpu_ms`: the error bought per unit of GPU time.
    pub fit_time: Option<LogLogFit>,
    /// Samples per pixel of the reference as rendered (whole chunks).
    pub reference_spp: u32,
    /// Root of the reference's estimated variance (mean over pixels and channels): the noise
    /// subtracted from every MSE.
    pub reference_noise_rmse: f64,
    /// GPU time of the reference's chunks per sample per pixel, median over the chunks.
    pub reference_ms_per_spp: f64,
}

/// How far `seed`'s converged image is from `pt`'s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReferenceBias {
    /// RMSE between the two references as rendered.
    pub rmse_raw: f64,
    /// What the references' noise alone would give: the root of the sum of their variances.
    pub noise_rmse: f64,
    /// The root of `rmse_raw² − noise_rmse²` (0 when that is negative): the per-pixel
    /// difference that noise does not explain.
    pub bias_rmse: f64,
    /// Image mean of `seed`'s reference over `pt`'s, per channel.
    pub mean_ratio: [f64; 3],
    /// That difference of means in standard errors (from the spread of the chunks' means),
    /// per channel; beyond ±4 it is not noise.
    pub mean_z: [f64; 3],
}

/// Everything [`measure`] found on one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Convergence {
    pub scene: String,
    pub options: ConvergenceOptions,
    /// `pt` first, then `seed`.
    pub integrators: Vec<IntegratorConvergence>,
    /// Error of `pt` over error of `seed` at equal spp, both against `pt`'s reference: the
    /// geometric mean over the spp list of `rmse_vs_pt(pt) / rmse_vs_pt(seed)`. Below 1: `pt`
    /// is better.
    pub ratio_equal_spp: f64,
    /// Error of `pt` over error of `seed` at equal GPU time: each integrator's
    /// [`IntegratorConvergence::fit_time`] evaluated at `equal_time_ms`, the geometric mean of
    /// the ends of the GPU time range the two integrators' points share (of all their points
    /// when the ranges do not overlap, then `equal_time_extrapolated` is set). With both
    /// slopes −1/2 the ratio does not depend on that time.
    pub ratio_equal_time: f64,
    pub equal_time_ms: f64,
    pub equal_time_extrapolated: bool,
    pub seed_bias: ReferenceBias,
    /// Over every render, references included.
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
    pub renders: u64,
}

/// Running per-float sums of equal-spp chunk images: their mean and the variance of that mean.
struct Accumulator {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    chunk_means: Vec<[f64; 3]>,
}

impl Accumulator {
    fn new(len: usize) -> Self {
        Self {
            sum: vec![0.0; len],
            sum_sq: vec![0.0; len],
            chunk_means: Vec::new(),
        }
    }
    fn add(&mut self, rgb: &[f32]) {
        for ((s, q), &v) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(rgb) {
            *s += v as f64;
            *q += v as f64 * v as f64;
        }
        self.chunk_means.push(channel_means(rgb));
    }
    fn k(&self) -> f64 {
        self.chunk_means.len() as f64
    }
    fn mean(&self) -> Vec<f32> {
        self.sum.iter().map(|s| (s / self.k()) as f32).collect()
    }
    /// Mean over floats of the estimated variance of the per-float mean.
    fn noise_mse(&self) -> f64 {
        let k = self.k();
        let total: f64 = self
            .sum
            .iter()
            .zip(&self.sum_sq)
            .map(|(s, q)| ((q - s * s / k) / (k - 1.0)).max(0.0) / k)
            .sum();
        total / self.sum.len() as f64
    }
    /// Per channel: the image mean and the variance of that mean, from the chunks' means.
    fn image_mean(&self) -> [(f64, f64); 3] {
        let k = self.k();
        std::array::from_fn(|c| {
            let m = self.chunk_means.iter().map(|v| v[c]).sum::<f64>() / k;
            let var = self
                .chunk_means
                .iter()
                .map(|v| (v[c] - m).powi(2))
                .sum::<f64>()
                / (k - 1.0);
            (m, var / k)
        })
    }
}

fn channel_means(rgb: &[f32]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for p in rgb.chunks_exact(3) {
        for c in 0..3 {
            sum[c] += p[c] as f64;
        }
    }
    let n = (rgb.len() / 3).max(1) as f64;
    sum.map(|s| s / n)
}

/// Counts over every render of a measurement.
#[derive(Default)]
struct Tally {
    nonfinite_samples: u64,
    stack_overflows: u64,
    renders: u64,
}

/// Renders each integrator's reference, then every point of `options.spp` with
/// `options.seeds` seeds for each integrator (the integrators alternating), and fits the
/// results. `scene` must have been built for the aspect `width / height`.
/// `progress(done, total)` hears about every render.
///
/// Errors: invalid options ([`RenderError::Settings`]) and anything a render fails with.
pub fn measure(
    ctx: &Arc<GpuContext>,
    scene: &Scene,
    options: &ConvergenceOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Convergence, RenderError> {
    options.validate().map_err(RenderError::Settings)?;
    let mut renderer = Renderer::new(ctx, scene)?;
    let integrators = [Integrator::Pt, Integrator::Seed];
    let (chunks, chunk_spp) = options.reference_chunks();
    let total = integrators.len() as u64
        * (chunks as u64 + options.spp.len() as u64 * options.seeds as u64);
    let mut tally = Tally::default();
    let mut render = |integrator, spp, seed, tally: &mut Tally| {
        let settings = RenderSettings {
            width: options.width,
            height: options.height,
            spp,
            seed,
            integrator,
            max_bounces: options.max_bounces,
        };
        let frame = renderer.render(&scene.camera, &settings)?;
        tally.nonfinite_samples += frame.stats.nonfinite_samples;
        tally.stack_overflows += frame.stats.stack_overflows;
        tally.renders += 1;
        progress(tally.renders, total);
        Ok::<_, RenderError>(frame)
    };
    let len = (options.width * options.height * 3) as usize;
    let mse = |reference: &[f32], test: &[f32]| {
        metrics::image_error(reference, test, options.width, options.height, None)
            .map(|e| e.mse)
            .map_err(|e| RenderError::Settings(e.to_string()))
    };

    // The two integrators alternate render by render, references first (they also warm up
    // both pipelines before any point is timed): a change of load on the device (lavapipe
    // shares the CPU) then falls on both alike instead of on whichever ran at the time.
    let mut references: Vec<Accumulator> =
        integrators.iter().map(|_| Accumulator::new(len)).collect();
    let mut reference_ms = vec![Vec::new(); integrators.len()];
    for chunk in 0..chunks {
        let seed = (REFERENCE_SEED_BASE ^ options.seed).wrapping_add(chunk);
        for (i, &integrator) in integrators.iter().enumerate() {
            let frame = render(integrator, chunk_spp, seed, &mut tally)?;
            reference_ms[i].push(frame.stats.gpu_ms() / chunk_spp as f64);
            references[i].add(&frame.rgb);
        }
    }
    let means: Vec<Vec<f32>> = references.iter().map(Accumulator::mean).collect();
    let noise: Vec<f64> = references.iter().map(Accumulator::noise_mse).collect();
    let (pt_reference, pt_noise) = (&means[0], noise[0]);

    let mut points = vec![Vec::new(); integrators.len()];
    for (p, &spp) in options.spp.iter().enumerate() {
        let mut own = vec![0.0; integrators.len()];
        let mut vs_pt = vec![0.0; integrators.len()];
        let mut ms = vec![Vec::new(); integrators.len()];
        for s in 0..options.seeds {
            let seed = options.seed.wrapping_add(p as u32 * options.seeds + s);
            for (i, &integrator) in integrators.iter().enumerate() {
                let frame = render(integrator, spp, seed, &mut tally)?;
                own[i] += mse(&means[i], &frame.rgb)?;
                vs_pt[i] += mse(pt_reference, &frame.rgb)?;
                ms[i].push(frame.stats.gpu_ms());
            }
        }
        let n = options.seeds as f64;
        for i in 0..integrators.len() {
            let (own, vs_pt) = (own[i] / n, vs_pt[i] / n);
            points[i].push(ConvergencePoint {
                spp,
                rmse: (own - noise[i]).max(0.0).sqrt(),
                rmse_raw: own.sqrt(),
                rmse_vs_pt: (vs_pt - pt_noise).max(0.0).sqrt(),
                gpu_ms: median(&ms[i]),
            });
        }
    }

    let fit = |points: &[ConvergencePoint], xy: fn(&ConvergencePoint) -> (f64, f64)| {
        LogLogFit::fit(&points.iter().map(xy).collect::<Vec<_>>())
    };
    let results: Vec<IntegratorConvergence> = integrators
        .iter()
        .zip(points)
        .enumerate()
        .map(|(i, (&integrator, points))| IntegratorConvergence {
            integrator,
            fit_spp: fit(&points, |p| (p.spp as f64, p.rmse)),
            fit_spp_vs_pt: fit(&points, |p| (p.spp as f64, p.rmse_vs_pt)),
            fit_time: fit(&points, |p| (p.gpu_ms, p.rmse_vs_pt)),
            points,
            reference_spp: chunks * chunk_spp,
            reference_noise_rmse: noise[i].sqrt(),
            reference_ms_per_spp: median(&reference_ms[i]),
        })
        .collect();

    let (pt, seed) = (&results[0], &results[1]);
    let log_ratios: Vec<f64> = pt
        .points
        .iter()
        .zip(&seed.points)
        .map(|(a, b)| (a.rmse_vs_pt / b.rmse_vs_pt).ln())
        .collect();
    let ratio_equal_spp = (log_ratios.iter().sum::<f64>() / log_ratios.len() as f64).exp();
    let (equal_time_ms, equal_time_extrapolated) = common_time(pt, seed);
    let ratio_equal_time = match (pt.fit_time, seed.fit_time) {
        (Some(a), Some(b)) => a.at(equal_time_ms) / b.at(equal_time_ms),
        _ => f64::NAN,
    };

    let seed_bias = {
        let (a, b) = (&references[0], &references[1]);
        let raw = mse(pt_reference, &means[1])?;
        let noise = pt_noise + b.noise_mse();
        let (ma, mb) = (a.image_mean(), b.image_mean());
        ReferenceBias {
            rmse_raw: raw.sqrt(),
            noise_rmse: noise.sqrt(),
            bias_rmse: (raw - noise).max(0.0).sqrt(),
            mean_ratio: std::array::from_fn(|c| mb[c].0 / ma[c].0),
            mean_z: std::array::from_fn(|c| (mb[c].0 - ma[c].0) / (ma[c].1 + mb[c].1).sqrt()),
        }
    };

    Ok(Convergence {
        scene: scene.name.clone(),
        options: options.clone(),
        integrators: results,
        ratio_equal_spp,
        ratio_equal_time,
        equal_time_ms,
        equal_time_extrapolated,
        seed_bias,
        nonfinite_samples: tally.nonfinite_samples,
        stack_overflows: tally.stack_overflows,
        renders: tally.renders,
    })
}

/// The time at which the two integrators' error fits are compared: the geometric mean of the
/// ends of the GPU time range both cover, or of all their times when the ranges are disjoint
/// (flagged as extrapolated).
fn common_time(a: &IntegratorConvergence, b: &IntegratorConvergence) -> (f64, bool) {
    let range = |c: &IntegratorConvergence| {
        c.points
            .iter()
            .map(|p| p.gpu_ms)
            .filter(|t| t.is_finite() && *t > 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), t| {
                (lo.min(t), hi.max(t))
            })
    };
    let ((alo, ahi), (blo, bhi)) = (range(a), range(b));
    let (lo, hi) = (alo.max(blo), ahi.min(bhi));
    if lo <= hi {
        ((lo * hi).sqrt(), false)
    } else {
        ((alo.min(blo) * ahi.max(bhi)).sqrt(), true)
    }
}

impl Convergence {
    /// The integrator's results, if it was measured.
    pub fn integrator(&self, integrator: Integrator) -> Option<&IntegratorConvergence> {
        self.integrators.iter().find(|c| c.integrator == integrator)
    }

    /// A human-readable summary, one line per entry.
    pub fn report_lines(&self) -> Vec<String> {
        let o = &self.options;
        let mut lines = vec![format!(
            "convergence on {} ({}x{}, max {} bounces, {} seeds per point, references of {} spp)",
            self.scene,
            o.width,
            o.height,
            o.max_bounces,
            o.seeds,
            self.integrators.first().map_or(0, |c| c.reference_spp)
        )];
        for c in &self.integrators {
            let name = match c.integrator {
                Integrator::Pt => "pt",
                Integrator::Seed => "seed",
            };
            let fit = |f: Option<LogLogFit>| {
                f.map_or("no fit".to_string(), |f| {
                    format!("slope {:+.3} (R² {:.4})", f.slope, f.r2)
                })
            };
            lines.push(format!(
                "  {name:<4}  RMSE vs spp: {} (against pt's reference: {}); vs GPU time: {}; reference noise RMSE {:.2e}, {:.3} GPU ms/spp",
                fit(c.fit_spp),
                fit(c.fit_spp_vs_pt),
                fit(c.fit_time),
                c.reference_noise_rmse,
                c.reference_ms_per_spp
            ));
            for p in &c.points {
                lines.push(format!(
                    "        {:>5} spp  RMSE {:.4e} (raw {:.4e}, vs pt reference {:.4e})  {:.3} GPU ms",
                    p.spp, p.rmse, p.rmse_raw, p.rmse_vs_pt, p.gpu_ms
                ));
            }
        }
        lines.push(format!(
            "  pt/seed error ratio (against pt's reference): {:.3} at equal spp, {:.3} at equal GPU time ({:.3} ms{})",
            self.ratio_equal_spp,
            self.ratio_equal_time,
            self.equal_time_ms,
            if self.equal_time_extrapolated {
                ", extrapolated: the time ranges do not overlap"
            } else {
                ""
            }
        ));
        let b = &self.seed_bias;
        lines.push(format!(
            "  seed's reference vs pt's: RMSE {:.3e} (noise alone {:.3e}, unexplained {:.3e}); mean ratio {:.4}/{:.4}/{:.4} (z {:+.1}/{:+.1}/{:+.1})",
            b.rmse_raw,
            b.noise_rmse,
            b.bias_rmse,
            b.mean_ratio[0],
            b.mean_ratio[1],
            b.mean_ratio[2],
            b.mean_z[0],
            b.mean_z[1],
            b.mean_z[2]
        ));
        lines.push(format!(
            "  {} renders: {} non-finite samples, {} BVH stack overflows",
            self.renders, self.nonfinite_samples, self.stack_overflows
        ));
        lines
    }
}

impl std::fmt::Display for Convergence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for line in self.report_lines() {
            writeln!(f, "{line}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_fits_exactly() {
        let points: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(-0.5)))
            .collect();
        let f = LogLogFit::fit(&points).unwrap();
        assert!((f.slope + 0.5).abs() < 1e-12, "{f:?}");
        assert!((f.r2 - 1.0).abs() < 1e-12, "{f:?}");
        assert!((f.at(16.0) - 0.75).abs() < 1e-12, "{f:?}");
        assert!(LogLogFit::fit(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
        assert!(LogLogFit::fit(&[(1.0, 1.0), (2.0, 0.0)]).is_none());
    }

    #[test]
    fn reference_noise_is_the_variance_of_the_mean() {
        // Two chunks per float: 1 and 3 → variance 2, variance of the mean 1.
        let mut acc = Accumulator::new(3);
        acc.add(&[1.0, 1.0, 1.0]);
        acc.add(&[3.0, 3.0, 3.0]);
        assert_eq!(acc.mean(), vec![2.0; 3]);
        assert!((acc.noise_mse() - 1.0).abs() < 1e-12);
        let [(m, v), _, _] = acc.image_mean();
        assert_eq!((m, v), (2.0, 1.0));
    }

    #[test]
    fn options_need_a_slope_and_a_quiet_reference() {
        assert!(ConvergenceOptions::default().validate().is_ok());
        let one = ConvergenceOptions {
            spp: vec![4, 4],
            ..Default::default()
        };
        assert!(one.validate().unwrap_err().contains("two distinct"));
        let noisy = ConvergenceOptions {
            reference_spp: 256,
            ..Default::default()
        };
        assert!(noisy.validate().unwrap_err().contains("8 x"));
        assert_eq!(ConvergenceOptions::default().reference_chunks(), (64, 32));
        let small = ConvergenceOptions {
            spp: vec![1, 2],
            reference_spp: 16,
            ..Default::default()
        };
        assert_eq!(small.reference_chunks(), (2, 8));
    }
}
