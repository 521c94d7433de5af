//! The measurement: each integrator's reference, then every point, the integrators
//! alternating render by render, then the fits and the comparisons.

use super::chunks::Accumulator;
use super::fit::LogLogFit;
use super::options::ConvergenceOptions;
use super::results::{Convergence, ConvergencePoint, IntegratorConvergence, ReferenceBias};
use crate::bench::stats::median;
use crate::gpu::GpuContext;
use crate::metrics;
use crate::render::regular_frame;
use crate::render::{Frame, Integrator, RenderError, RenderSettings, Renderer};
use crate::scene::Scene;
use std::sync::Arc;

/// Seeds of reference renders are this xor [`ConvergenceOptions::seed`] plus the chunk index,
/// far from those of the measured renders (`seed + point · seeds + repeat`), so that no
/// reference shares random numbers with an image it judges.
const REFERENCE_SEED_BASE: u32 = 0x5eed_0000;

/// The integrators measured, `pt` first (its reference is the physically correct one).
const INTEGRATORS: [Integrator; 2] = [Integrator::Pt, Integrator::Seed];

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
    let renderer = Renderer::new(ctx, scene)?;
    let (chunks, chunk_spp) = options.reference_chunks();
    let total = INTEGRATORS.len() as u64
        * (chunks as u64 + options.spp.len() as u64 * options.seeds as u64);
    let mut renders = Renders {
        renderer,
        scene,
        options,
        progress,
        total,
        tally: Tally::default(),
    };
    let references = render_references(&mut renders, chunks, chunk_spp)?;
    let points = measure_points(&mut renders, &references)?;
    let results = fit_integrators(points, &references, chunks * chunk_spp);
    let (pt, seed) = (&results[0], &results[1]);
    let ratio_equal_spp = ratio_equal_spp(pt, seed);
    let (equal_time_ms, equal_time_extrapolated) = common_time(pt, seed);
    let ratio_equal_time = match (pt.fit_time, seed.fit_time) {
        (Some(a), Some(b)) => a.at(equal_time_ms) / b.at(equal_time_ms),
        _ => f64::NAN,
    };
    let seed_bias = seed_bias(options, &references)?;
    let tally = renders.tally;
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

/// Counts over every render of a measurement.
#[derive(Default)]
struct Tally {
    nonfinite_samples: u64,
    stack_overflows: u64,
    renders: u64,
}

/// Renders of the scene's camera at the measurement's size, each counted and reported.
struct Renders<'a> {
    renderer: Renderer,
    scene: &'a Scene,
    options: &'a ConvergenceOptions,
    progress: &'a mut dyn FnMut(u64, u64),
    /// Renders of the whole measurement, for `progress`.
    total: u64,
    tally: Tally,
}

impl Renders<'_> {
    fn render(
        &mut self,
        integrator: Integrator,
        spp: u32,
        seed: u32,
    ) -> Result<Frame, RenderError> {
        let settings = RenderSettings {
            // The −1/2 slope is a property of independent samples: a quasi-Monte Carlo sampler
            // falls faster (zsobol: about −0.8 on cornell), which is not what this measures.
            sampler: crate::render::Sampler::Independent,
            width: self.options.width,
            height: self.options.height,
            spp,
            seed,
            integrator,
            max_bounces: self.options.max_bounces,
        };
        let frame = regular_frame(&mut self.renderer, &self.scene.camera, &settings)?;
        self.tally.nonfinite_samples += frame.stats.nonfinite_samples;
        self.tally.stack_overflows += frame.stats.stack_overflows;
        self.tally.renders += 1;
        (self.progress)(self.tally.renders, self.total);
        Ok(frame)
    }
}

/// MSE of `test` against `reference`, over the whole image.
fn mse(options: &ConvergenceOptions, reference: &[f32], test: &[f32]) -> Result<f64, RenderError> {
    metrics::image_error(reference, test, options.width, options.height, None)
        .map(|e| e.mse)
        .map_err(|e| RenderError::Settings(e.to_string()))
}

/// Each integrator's reference (in [`INTEGRATORS`]' order).
struct References {
    chunks: Vec<Accumulator>,
    means: Vec<Vec<f32>>,
    /// The variance of each mean (see the module docs).
    noise: Vec<f64>,
    /// GPU ms per spp of each chunk.
    ms_per_spp: Vec<Vec<f64>>,
}

/// Renders both references chunk by chunk. The two integrators alternate render by render,
/// references first (they also warm up both pipelines before any point is timed): a change
/// of load on the device (lavapipe shares the CPU) then falls on both alike instead of on
/// whichever ran at the time.
fn render_references(
    renders: &mut Renders,
    chunks: u32,
    chunk_spp: u32,
) -> Result<References, RenderError> {
    let options = renders.options;
    let len = (options.width * options.height * 3) as usize;
    let mut accumulators: Vec<Accumulator> =
        INTEGRATORS.iter().map(|_| Accumulator::new(len)).collect();
    let mut ms_per_spp = vec![Vec::new(); INTEGRATORS.len()];
    for chunk in 0..chunks {
        let seed = (REFERENCE_SEED_BASE ^ options.seed).wrapping_add(chunk);
        for (i, &integrator) in INTEGRATORS.iter().enumerate() {
            let frame = renders.render(integrator, chunk_spp, seed)?;
            ms_per_spp[i].push(frame.stats.gpu_ms() / chunk_spp as f64);
            accumulators[i].add(&frame.rgb);
        }
    }
    Ok(References {
        means: accumulators.iter().map(Accumulator::mean).collect(),
        noise: accumulators.iter().map(Accumulator::noise_mse).collect(),
        chunks: accumulators,
        ms_per_spp,
    })
}

/// Every point of `options.spp`, per integrator: its error against its own reference and
/// against `pt`'s (each less that reference's noise), and its median GPU time.
fn measure_points(
    renders: &mut Renders,
    references: &References,
) -> Result<Vec<Vec<ConvergencePoint>>, RenderError> {
    let options = renders.options;
    let (pt_reference, pt_noise) = (&references.means[0], references.noise[0]);
    let mut points = vec![Vec::new(); INTEGRATORS.len()];
    for (p, &spp) in options.spp.iter().enumerate() {
        let mut own = vec![0.0; INTEGRATORS.len()];
        let mut vs_pt = vec![0.0; INTEGRATORS.len()];
        let mut ms = vec![Vec::new(); INTEGRATORS.len()];
        for s in 0..options.seeds {
            let seed = options.seed.wrapping_add(p as u32 * options.seeds + s);
            for (i, &integrator) in INTEGRATORS.iter().enumerate() {
                let frame = renders.render(integrator, spp, seed)?;
                own[i] += mse(options, &references.means[i], &frame.rgb)?;
                vs_pt[i] += mse(options, pt_reference, &frame.rgb)?;
                ms[i].push(frame.stats.gpu_ms());
            }
        }
        let n = options.seeds as f64;
        for i in 0..INTEGRATORS.len() {
            let (own, vs_pt) = (own[i] / n, vs_pt[i] / n);
            points[i].push(ConvergencePoint {
                spp,
                rmse: (own - references.noise[i]).max(0.0).sqrt(),
                rmse_raw: own.sqrt(),
                rmse_vs_pt: (vs_pt - pt_noise).max(0.0).sqrt(),
                gpu_ms: median(&ms[i]),
            });
        }
    }
    Ok(points)
}

/// Each integrator's points with their fits against spp and GPU time.
fn fit_integrators(
    points: Vec<Vec<ConvergencePoint>>,
    references: &References,
    reference_spp: u32,
) -> Vec<IntegratorConvergence> {
    let fit = |points: &[ConvergencePoint], xy: fn(&ConvergencePoint) -> (f64, f64)| {
        LogLogFit::fit(&points.iter().map(xy).collect::<Vec<_>>())
    };
    INTEGRATORS
        .iter()
        .zip(points)
        .enumerate()
        .map(|(i, (&integrator, points))| IntegratorConvergence {
            integrator,
            fit_spp: fit(&points, |p| (p.spp as f64, p.rmse)),
            fit_spp_vs_pt: fit(&points, |p| (p.spp as f64, p.rmse_vs_pt)),
            fit_time: fit(&points, |p| (p.gpu_ms, p.rmse_vs_pt)),
            points,
            reference_spp,
            reference_noise_rmse: references.noise[i].sqrt(),
            reference_ms_per_spp: median(&references.ms_per_spp[i]),
        })
        .collect()
}

/// `pt`'s error over `seed`'s at equal spp, both against `pt`'s reference: the geometric
/// mean over the points.
fn ratio_equal_spp(pt: &IntegratorConvergence, seed: &IntegratorConvergence) -> f64 {
    let log_ratios: Vec<f64> = pt
        .points
        .iter()
        .zip(&seed.points)
        .map(|(a, b)| (a.rmse_vs_pt / b.rmse_vs_pt).ln())
        .collect();
    (log_ratios.iter().sum::<f64>() / log_ratios.len() as f64).exp()
}

/// How far `seed`'s reference is from `pt`'s, beyond what their noise explains.
fn seed_bias(
    options: &ConvergenceOptions,
    references: &References,
) -> Result<ReferenceBias, RenderError> {
    let (a, b) = (&references.chunks[0], &references.chunks[1]);
    let raw = mse(options, &references.means[0], &references.means[1])?;
    let noise = references.noise[0] + b.noise_mse();
    let (ma, mb) = (a.image_mean(), b.image_mean());
    Ok(ReferenceBias {
        rmse_raw: raw.sqrt(),
        noise_rmse: noise.sqrt(),
        bias_rmse: (raw - noise).max(0.0).sqrt(),
        mean_ratio: std::array::from_fn(|c| mb[c].0 / ma[c].0),
        mean_z: std::array::from_fn(|c| (mb[c].0 - ma[c].0) / (ma[c].1 + mb[c].1).sqrt()),
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
