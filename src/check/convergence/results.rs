//! What a convergence measurement found, and its report lines.

use super::fit::LogLogFit;
use super::options::ConvergenceOptions;
use crate::render::Integrator;
use serde::Serialize;

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

/// Everything [`measure`](super::measure()) found on one scene.
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
