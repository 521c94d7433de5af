//! summary.json: the statistics of a run, computed from its rows alone (so a resumed run and
//! an uninterrupted one summarize the same way), with the device and every parameter.

use super::protocol::{BenchPlan, Mode, EYES};
use super::rows::{FrameRow, QualityRow};
use super::stats::{frame_rates, impact, summarize, FrameRates, Impact, Summary as Stats};
use crate::gpu::DeviceInfo;
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize)]
pub struct Device {
    pub name: String,
    pub kind: String,
    pub driver: String,
    pub api_version: String,
}

impl From<&DeviceInfo> for Device {
    fn from(d: &DeviceInfo) -> Self {
        Self {
            name: d.name.clone(),
            kind: d.kind.clone(),
            driver: d.driver.clone(),
            api_version: d.api_version.clone(),
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub fovea_version: String,
    /// The command that started the run, then any that resumed it.
    pub commands: Vec<String>,
    /// UTC, when this summary was written.
    pub written_at: String,
    /// Every planned frame was measured.
    pub complete: bool,
    pub frame_rows: u64,
    pub expected_frame_rows: u64,
    pub device: Device,
    pub parameters: BenchPlan,
    pub scenes: Vec<SceneSummary>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SceneSummary {
    pub scene: String,
    pub modes: Vec<ModeSummary>,
    pub quality: Vec<QualitySummary>,
}

/// One mode of one scene over all its repeats. Times are GPU milliseconds from timestamps
/// unless named cpu; per-pass times are per eye.
#[derive(Clone, Debug, Serialize)]
pub struct ModeSummary {
    pub mode: Mode,
    pub frames: usize,
    /// fps per frame (from both eyes' GPU time) and frame time.
    pub rates: Option<FrameRates>,
    pub cpu_ms: Option<Stats>,
    pub gpu_plan_ms: Option<Stats>,
    pub trace_ms: Option<Stats>,
    pub resolve_ms: Option<Stats>,
    /// Mean over frames of both eyes' camera paths and rays.
    pub paths_per_frame: f64,
    pub rays_per_frame: f64,
    /// Throughput: camera paths per second of median frame GPU time, in millions.
    pub msamples_per_s: Option<f64>,
    /// Foveated fps over regular fps (None for regular).
    pub impact: Option<Impact>,
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
}

/// Error of one mode at one spp in one region, the mean over both eyes.
#[derive(Clone, Debug, Serialize)]
pub struct QualitySummary {
    pub mode: Mode,
    pub spp: u32,
    pub region: String,
    /// Visible pixels of the region, both eyes together; the errors mean nothing at 0.
    pub pixels: u64,
    pub mse: f64,
    pub rel_mse: f64,
    pub psnr_db: f64,
    pub flip: f64,
    pub frame_gpu_ms: f64,
    /// Mean of both eyes' JOD (whole image only; None where it was not measured).
    pub jod: Option<f64>,
}

/// The mean of `values`; NaN when there are none.
pub(super) fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// The statistics of one mode's rows.
pub fn mode_summary(mode: Mode, rows: &[&FrameRow]) -> ModeSummary {
    // One fps value per frame: the left eye's row carries the frame's time.
    let firsts: Vec<&&FrameRow> = rows.iter().filter(|r| r.eye == "left").collect();
    let frame_ms: Vec<f64> = firsts.iter().map(|r| r.frame_gpu_ms).collect();
    let per_eye =
        |f: fn(&FrameRow) -> f64| summarize(&rows.iter().map(|r| f(r)).collect::<Vec<_>>());
    let frames = firsts.len();
    let per_frame = |f: fn(&FrameRow) -> u64| {
        rows.iter().map(|r| f(r) as f64).sum::<f64>() / frames.max(1) as f64
    };
    ModeSummary {
        mode,
        frames,
        rates: frame_rates(&frame_ms),
        cpu_ms: summarize(&firsts.iter().map(|r| r.cpu_ms).collect::<Vec<_>>()),
        gpu_plan_ms: per_eye(|r| r.gpu_plan_ms),
        trace_ms: per_eye(|r| r.trace_ms),
        resolve_ms: per_eye(|r| r.resolve_ms),
        paths_per_frame: per_frame(|r| r.paths),
        rays_per_frame: per_frame(|r| r.rays),
        msamples_per_s: frame_rates(&frame_ms)
            .map(|r| per_frame(|r| r.paths) / (r.ms.median * 1e3).max(1e-9)),
        impact: None,
        nonfinite_samples: rows.iter().map(|r| r.nonfinite).sum(),
        stack_overflows: rows.iter().map(|r| r.overflows).sum(),
    }
}

/// Summarizes every scene of `plan` from the rows measured so far.
pub fn summarize_run(
    plan: &BenchPlan,
    device: &DeviceInfo,
    commands: &[&str],
    frames: &[FrameRow],
    quality: &[QualityRow],
) -> Summary {
    let scenes = plan
        .scenes
        .iter()
        .map(|scene| {
            let mut modes: Vec<ModeSummary> = plan
                .modes()
                .into_iter()
                .map(|mode| {
                    let rows: Vec<&FrameRow> = frames
                        .iter()
                        .filter(|r| r.scene == *scene && r.mode == mode)
                        .collect();
                    mode_summary(mode, &rows)
                })
                .collect();
            let regular = modes[0].rates.map(|r| r.fps);
            for m in modes.iter_mut().skip(1) {
                m.impact = match (regular, m.rates) {
                    (Some(r), Some(f)) => impact(&r, &f.fps),
                    _ => None,
                };
            }
            SceneSummary {
                scene: scene.clone(),
                modes,
                quality: quality_summary(scene, quality),
            }
        })
        .collect();
    let expected = plan.expected_frame_rows();
    Summary {
        fovea_version: crate::build_version(),
        commands: commands.iter().map(|c| c.to_string()).collect(),
        written_at: utc_now(),
        complete: frames.len() as u64 == expected,
        frame_rows: frames.len() as u64,
        expected_frame_rows: expected,
        device: Device::from(device),
        parameters: plan.clone(),
        scenes,
    }
}

fn quality_summary(scene: &str, rows: &[QualityRow]) -> Vec<QualitySummary> {
    // Regions in reading order: the whole image, then the bands outward.
    let order = |region: &str| {
        crate::metrics::BANDS
            .iter()
            .position(|b| b.name == region)
            .map_or(0, |i| i + 1)
    };
    let mut groups: BTreeMap<(Mode, u32, usize, String), Vec<&QualityRow>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.scene == scene) {
        groups
            .entry((r.mode, r.spp, order(&r.region), r.region.clone()))
            .or_default()
            .push(r);
    }
    groups
        .into_iter()
        .filter(|(_, g)| g.len() as u32 == EYES)
        .map(|((mode, spp, _, region), g)| QualitySummary {
            mode,
            spp,
            region,
            pixels: g.iter().map(|r| r.pixels).sum(),
            mse: mean(g.iter().map(|r| r.mse)),
            rel_mse: mean(g.iter().map(|r| r.rel_mse)),
            psnr_db: mean(g.iter().map(|r| r.psnr_db)),
            flip: mean(g.iter().map(|r| r.flip)),
            frame_gpu_ms: g[0].frame_gpu_ms,
            jod: g
                .iter()
                .map(|r| r.jod)
                .sum::<Option<f64>>()
                .map(|sum| sum / g.len() as f64),
        })
        .collect()
}

/// Now in UTC as `YYYY-MM-DDTHH:MM:SSZ` (and `YYYYMMDD-HHMMSS` for directory names).
pub fn utc_now() -> String {
    let (date, time) = utc_parts();
    format!(
        "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z",
        date.0, date.1, date.2, time.0, time.1, time.2
    )
}

pub fn utc_stamp() -> String {
    let (date, time) = utc_parts();
    format!(
        "{:04}{:02}{:02}-{:02}{:02}{:02}",
        date.0, date.1, date.2, time.0, time.1, time.2
    )
}

fn utc_parts() -> ((i64, u32, u32), (u64, u64, u64)) {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let day = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    (
        civil_from_days(day),
        (rem / 3600, rem % 3600 / 60, rem % 60),
    )
}

/// Year, month, day of a day count since 1970-01-01 (H. Hinnant's `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + if m <= 2 { 1 } else { 0 };
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(mode: Mode, frame: u32, eye: &str, frame_gpu_ms: f64) -> FrameRow {
        FrameRow {
            scene: "s".into(),
            mode,
            repeat: 0,
            frame,
            eye: eye.into(),
            trace_ms: frame_gpu_ms / 4.0,
            gpu_plan_ms: 0.0,
            resolve_ms: frame_gpu_ms / 4.0,
            eye_gpu_ms: frame_gpu_ms / 2.0,
            frame_gpu_ms,
            cpu_ms: frame_gpu_ms + 1.0,
            plan_ms: 0.0,
            record_ms: 0.0,
            paths: 100,
            rays: 300,
            nonfinite: 0,
            overflows: 0,
            gaze_x: 0.0,
            gaze_y: 0.0,
            wall_us: 0,
            ..Default::default()
        }
    }

    #[test]
    fn fps_and_impact_come_from_one_value_per_frame() {
        // Regular frames of 40 and 50 ms (25 and 20 fps), forward of 10 and 20 ms (100, 50).
        let mut rows = Vec::new();
        for (mode, ms) in [(Mode::Regular, [40.0, 50.0]), (Mode::Forward, [10.0, 20.0])] {
            for (f, ms) in ms.into_iter().enumerate() {
                rows.push(row(mode, f as u32, "left", ms));
                rows.push(row(mode, f as u32, "right", ms));
            }
        }
        let plan = BenchPlan {
            scenes: vec!["s".into()],
            frames: 2,
            repeats_foveated: 1,
            ..BenchPlan::quick()
        };
        let device = DeviceInfo {
            name: "d".into(),
            kind: "cpu".into(),
            driver: "x".into(),
            api_version: "1.4".into(),
            timestamp_period_ns: 1.0,
            max_storage_buffer_range: 0,
            max_texel_buffer_elements: 0,
            min_texel_buffer_offset_alignment: 16,
            subgroup_size: 8,
            max_image_dimension_2d: 4096,
            ray_query: None,
        };
        let s = summarize_run(&plan, &device, &["fovea bench"], &rows, &[]);
        assert!(!s.complete, "corner is missing");
        assert_eq!(s.frame_rows, 8);
        assert_eq!(s.expected_frame_rows, 12);
        let modes = &s.scenes[0].modes;
        let regular = modes[0].rates.unwrap();
        assert_eq!(regular.fps.n, 2);
        assert!((regular.fps.mean - 22.5).abs() < 1e-12);
        assert!((regular.fps.std - (12.5f64).sqrt()).abs() < 1e-12);
        assert!((modes[1].rates.unwrap().fps.mean - 75.0).abs() < 1e-12);
        let impact = modes[1].impact.unwrap();
        assert!((impact.factor - 75.0 / 22.5).abs() < 1e-12);
        assert!(modes[2].rates.is_none() && modes[2].impact.is_none());
        assert_eq!(modes[0].paths_per_frame, 200.0);
        assert_eq!(modes[0].rays_per_frame, 600.0);
        assert!((modes[0].cpu_ms.unwrap().mean - 46.0).abs() < 1e-12);
    }

    #[test]
    fn dates_are_civil() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(19_723), (2024, 1, 1));
        assert_eq!(civil_from_days(20_513), (2026, 3, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }
}
