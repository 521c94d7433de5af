//! The stress report `fovea check` prints and writes as JSON: every section's measurements,
//! the totals that must be zero, and the failures judged against the tolerances stated here.

use super::convergence::Convergence;
use super::gltf_furnace::GltfFurnaceResult;
use super::materials::{EmissionScaling, FurnaceResult};
use super::scale::{Lighting, PlaneRadiance, ScaledScene};
use super::watertight::MeshWatertightness;
use crate::render::Integrator;

/// Plane radiance: 1.5% of the exact value (≥ 6 standard errors at 32² pixels × 64 spp).
pub const PLANE_TOLERANCE: f64 = 0.015;
/// A scaled scene's image mean: within 1% of scale 1.
pub const SCALED_MEAN_TOLERANCE: f64 = 0.01;
/// A scaled scene's RMSE from scale 1 at the same seed, over the noise between two seeds.
pub const SCALED_RMSE_OVER_NOISE: f64 = 0.5;
/// Standard errors the furnace mean may lie above 1 before it counts as creating energy.
pub const FURNACE_SIGMAS: f64 = 4.0;
/// A glTF furnace mean may miss the CPU's prediction by FURNACE_SIGMAS standard errors plus
/// this share of it (the albedo quadrature and pixel centres standing in for pixels).
pub const GLTF_FURNACE_TOLERANCE: f64 = 0.005;
/// Relative deviation from linearity of an image under scaled emission.
pub const EMISSION_TOLERANCE: f64 = 1e-3;
/// Error against spp must fall as spp^(−1/2) within this.
pub const SLOPE_TOLERANCE: f64 = 0.1;

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct CheckReport {
    pub device: String,
    pub watertight: Vec<MeshWatertightness>,
    pub plane: Vec<PlaneRadiance>,
    pub scaled: Vec<ScaledScene>,
    pub furnace: Vec<FurnaceResult>,
    pub gltf_furnace: Vec<GltfFurnaceResult>,
    pub emission: Vec<EmissionScaling>,
    pub convergence: Vec<Convergence>,
}

/// The counts that must all be zero.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    pub rays_tried: u64,
    pub escapes: u64,
    pub overshoots: u64,
    pub nonfinite_samples: u64,
    pub nonfinite_pixels: u64,
    pub stack_overflows: u64,
}

impl CheckReport {
    pub fn counts(&self) -> Counts {
        let mut c = Counts::default();
        for w in &self.watertight {
            c.rays_tried += w.rays;
            c.escapes += w.escapes;
            c.overshoots += w.overshoots.unwrap_or(0);
            c.stack_overflows += w.stack_overflows;
        }
        for p in &self.plane {
            c.nonfinite_samples += p.nonfinite_samples;
            c.stack_overflows += p.stack_overflows;
        }
        for s in &self.scaled {
            c.nonfinite_samples += s.nonfinite_samples;
            c.stack_overflows += s.stack_overflows;
        }
        for f in &self.furnace {
            c.nonfinite_samples += f.nonfinite_samples;
            c.nonfinite_pixels += f.nonfinite_pixels;
            c.stack_overflows += f.stack_overflows;
        }
        for g in &self.gltf_furnace {
            c.nonfinite_samples += g.nonfinite_samples;
        }
        for e in &self.emission {
            c.nonfinite_samples += e.nonfinite_samples;
            c.nonfinite_pixels += e.nonfinite_pixels;
        }
        for v in &self.convergence {
            c.nonfinite_samples += v.nonfinite_samples;
            c.stack_overflows += v.stack_overflows;
        }
        c
    }

    /// The glTF furnace section of the report, if it ran.
    fn gltf_furnace_lines(&self) -> Vec<String> {
        if self.gltf_furnace.is_empty() {
            return Vec::new();
        }
        let mut out = vec![
            "white furnace, glTF's BRDF (mean over the object against the CPU's albedo):".into(),
        ];
        for g in &self.gltf_furnace {
            out.push(format!(
                "  {:<38} {:<4}  {:.4} ± {:.4}  expected {:.4}",
                g.material,
                format!("{:?}", g.integrator),
                g.mean,
                g.std_error,
                g.expected
            ));
        }
        out
    }

    /// The glTF furnace results off the CPU's prediction.
    fn gltf_furnace_failures(&self) -> Vec<String> {
        let off = |g: &GltfFurnaceResult| {
            (g.mean - g.expected).abs()
                > FURNACE_SIGMAS * g.std_error + GLTF_FURNACE_TOLERANCE * g.expected
        };
        (self.gltf_furnace.iter().filter(|g| off(g)))
            .map(|g| {
                format!(
                    "white furnace {} ({:?}) reflects {:.4} ± {:.4}, the CPU reference {:.4}",
                    g.material, g.integrator, g.mean, g.std_error, g.expected
                )
            })
            .collect()
    }

    /// Every measurement outside its tolerance, one line each; empty when all passed.
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        let c = self.counts();
        for (what, n) in [
            ("rays escaped a closed mesh", c.escapes),
            ("rays passed the surface point they aimed at", c.overshoots),
            ("non-finite samples", c.nonfinite_samples),
            ("non-finite pixels", c.nonfinite_pixels),
            ("BVH stack overflows", c.stack_overflows),
        ] {
            if n > 0 {
                out.push(format!("{n} {what}"));
            }
        }
        for p in &self.plane {
            let zero_variance = p.integrator == Integrator::Pt && p.lighting == Lighting::Sky;
            if p.relative_error > PLANE_TOLERANCE || (zero_variance && p.pixels_off > 0) {
                out.push(format!(
                    "lit plane at scale {:e} offset {:e} ({:?}, {:?}): radiance {:.4} for {:.4}, {} pixels off",
                    p.scale, p.offset, p.lighting, p.integrator, p.mean, p.expected, p.pixels_off
                ));
            }
        }
        for s in &self.scaled {
            if (s.mean_ratio - 1.0).abs() > SCALED_MEAN_TOLERANCE
                || s.rmse_over_noise > SCALED_RMSE_OVER_NOISE
            {
                out.push(format!(
                    "{} at scale {:e}: mean ratio {:.4}, RMSE/noise {:.3}",
                    s.scene, s.scale, s.mean_ratio, s.rmse_over_noise
                ));
            }
        }
        for f in &self.furnace {
            if f.excess_sigmas() > FURNACE_SIGMAS {
                out.push(format!(
                    "white furnace {} on {} ({:?}) reflects {:.4} ± {:.4} > 1",
                    f.material, f.shape, f.integrator, f.mean, f.std_error
                ));
            }
        }
        out.extend(self.gltf_furnace_failures());
        for e in &self.emission {
            if (e.ratio - 1.0).abs() > EMISSION_TOLERANCE {
                out.push(format!(
                    "{} with emission x{:e}: image scaled by {:.6} of that",
                    e.scene, e.factor, e.ratio
                ));
            }
        }
        for v in &self.convergence {
            for c in &v.integrators {
                let Some(fit) = c.fit_spp else {
                    out.push(format!(
                        "{} {:?}: no slope could be fitted",
                        v.scene, c.integrator
                    ));
                    continue;
                };
                if (fit.slope + 0.5).abs() > SLOPE_TOLERANCE && judged_slope(v, c.integrator) {
                    out.push(format!(
                        "{} {:?}: error falls as spp^{:.3}, not spp^-0.5",
                        v.scene, c.integrator, fit.slope
                    ));
                }
            }
            for (what, ratio) in [
                ("equal spp", v.ratio_equal_spp),
                ("equal GPU time", v.ratio_equal_time),
            ] {
                if ratio.is_nan() || ratio >= 1.0 {
                    out.push(format!(
                        "{}: pt/seed error ratio {ratio:.3} at {what} (pt should be lower)",
                        v.scene
                    ));
                }
            }
        }
        out
    }

    /// The report as text, section by section.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.watertight.is_empty() {
            out.push(
                "watertightness (rays from inside closed meshes at vertices and edges):".into(),
            );
            for w in &self.watertight {
                out.push(format!(
                    "  {:<12} {:>6} triangles  {:>8} rays  {} escapes  {} overshoots  {} stack overflows",
                    w.mesh,
                    w.triangles,
                    w.rays,
                    w.escapes,
                    w.overshoots.map_or("n/a (not convex)".into(), |n| n.to_string()),
                    w.stack_overflows
                ));
            }
        }
        if !self.plane.is_empty() {
            out.push("lit plane (radiance must be albedo x light at every scale):".into());
            for p in &self.plane {
                out.push(format!(
                    "  scale {:>7.0e} offset {:>6.0e}  {:<17} {:<4}  {:.5} (exact {:.3}, error {:.2}%)  {} pixels >1% off",
                    p.scale,
                    p.offset,
                    format!("{:?}", p.lighting),
                    format!("{:?}", p.integrator),
                    p.mean,
                    p.expected,
                    100.0 * p.relative_error,
                    p.pixels_off
                ));
            }
        }
        if !self.scaled.is_empty() {
            out.push("whole scene scaled (same seed, against scale 1):".into());
            for s in &self.scaled {
                out.push(format!(
                    "  {} x{:<7.0e} mean ratio {:.5}  RMSE/noise {:.4}",
                    s.scene, s.scale, s.mean_ratio, s.rmse_over_noise
                ));
            }
        }
        if !self.furnace.is_empty() {
            out.push("white furnace (mean over the object must not exceed 1):".into());
            for f in &self.furnace {
                out.push(format!(
                    "  {:<26} {:<9} {:<4}  {:.4} ± {:.4}  max pixel {:.3}",
                    f.material,
                    f.shape,
                    format!("{:?}", f.integrator),
                    f.mean,
                    f.std_error,
                    f.max_pixel
                ));
            }
        }
        out.extend(self.gltf_furnace_lines());
        if !self.emission.is_empty() {
            out.push("very large emission (image must scale linearly):".into());
            for e in &self.emission {
                out.push(format!(
                    "  {} emission x{:e}: ratio {:.7}",
                    e.scene, e.factor, e.ratio
                ));
            }
        }
        for v in &self.convergence {
            out.extend(v.report_lines());
        }
        let c = self.counts();
        out.push(format!(
            "counts: {} rays tried, {} escapes, {} overshoots, {} non-finite samples, {} non-finite pixels, {} stack overflows",
            c.rays_tried, c.escapes, c.overshoots, c.nonfinite_samples, c.nonfinite_pixels, c.stack_overflows
        ));
        out
    }
}

/// Whether a slope is held to −1/2. `seed` on a scene with a sharp glossy highlight (mirror-room's
/// α = 200 sphere) samples it uniformly: the variance is finite but carried by paths so rare
/// that a few hundred samples per pixel rarely see them, and the fitted slope wanders (−0.40 to
/// −0.54 measured). It is reported, not judged; `pt` and `seed` on cornell are judged.
fn judged_slope(v: &Convergence, integrator: Integrator) -> bool {
    integrator == Integrator::Pt || v.scene != "mirror-room"
}
