//! What a tune run writes, beside `--out FILE.toml` (the chosen config): `FILE-candidates.csv`
//! (every measured config, appended as measured: the run's memory when it resumes),
//! `FILE-front.csv` (the Pareto front, fastest first), `FILE-front.svg`/`.png` (JOD against
//! GPU ms) and `FILE-tune.json` (the plan).

use crate::foveation::FoveationConfig;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One measured config: a row of `-candidates.csv` and `-front.csv`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CandidateRow {
    /// Its place in the search (the same seed gives the same sequence).
    pub index: u32,
    /// "baseline", "random", or "mutation of N".
    pub origin: String,
    /// `space::describe`: each layer as RADIUS:SPACINGxSPP, dN for denoising.
    pub config: String,
    /// One eye's GPU ms: median over the timed frames of every gaze, mean over scenes.
    pub gpu_ms: f64,
    /// With a budget of regular rendering's time: the config's medians over the medians of
    /// the regular frames timed between its frames, summed over scenes (NaN with a budget in
    /// ms). At most 1 is within the budget, however the machine's speed drifted in the run.
    pub pace_ratio: f64,
    /// FovVideoVDP JOD, the objective: with `--objective still` the mean over scenes and gazes
    /// of the first frames; with `motion` the mean over scenes of the videos (`jod_motion`).
    /// Then the first frames' per gaze (mean over scenes).
    pub jod: f64,
    pub jod_forward: f64,
    pub jod_off_axis: f64,
    pub jod_corner: f64,
    /// With `--objective motion`: the videos' JOD, mean over scenes (else empty).
    #[serde(default = "no_score")]
    pub jod_motion: f64,
    /// Camera paths traced per visible pixel (forward gaze, first scene): the rays' share.
    pub paths_per_pixel: f64,
    /// Every ray traced (camera, bounce and shadow rays) per visible pixel, as
    /// `paths_per_pixel`: what a GPU, whose per-pixel passes cost little, pays for most
    /// closely. A path into the black beyond a scene is one ray; one into a room is many.
    /// (A candidates file from before it lacks the column: resuming on one stops and names
    /// the columns it needs; tools/iso-quality.py reads such files without it.)
    pub rays_per_pixel: f64,
    /// Per scene, its median GPU ms and JOD per gaze, as JSON:
    /// `{"cornell": {"gpu_ms": 310.2, "jod": [8.1, 8.3, 8.9]}, ...}`.
    #[serde(default)]
    pub scenes_json: String,
    /// The config itself, as JSON.
    pub config_json: String,
}

fn no_score() -> f64 {
    f64::NAN
}

impl CandidateRow {
    pub fn foveation(&self) -> Result<FoveationConfig, String> {
        serde_json::from_str(&self.config_json)
            .map_err(|e| format!("candidate {} has an unreadable config ({e})", self.index))
    }
}

/// A row of `-front.csv`: a config on the Pareto front, with the cost it was judged by.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrontRow {
    pub index: u32,
    pub config: String,
    /// The GPU ms the front and the budget compare: `gpu_ms`, or with a regular budget
    /// `pace_ratio` × regular rendering's measured ms.
    pub cost_ms: f64,
    pub gpu_ms: f64,
    pub pace_ratio: f64,
    pub jod: f64,
    pub jod_forward: f64,
    pub jod_off_axis: f64,
    pub jod_corner: f64,
    pub config_json: String,
}

impl FrontRow {
    pub fn new(row: &CandidateRow, cost_ms: f64) -> Self {
        Self {
            index: row.index,
            config: row.config.clone(),
            cost_ms,
            gpu_ms: row.gpu_ms,
            pace_ratio: row.pace_ratio,
            jod: row.jod,
            jod_forward: row.jod_forward,
            jod_off_axis: row.jod_off_axis,
            jod_corner: row.jod_corner,
            config_json: row.config_json.clone(),
        }
    }
}

/// The files of a run whose chosen config goes to `out`.
pub struct TuneFiles {
    pub config: PathBuf,
    pub candidates: PathBuf,
    pub front: PathBuf,
    /// Stem of the plot (`.svg` and `.png` are appended).
    pub plot: PathBuf,
    pub plan: PathBuf,
}

impl TuneFiles {
    pub fn new(out: &Path) -> Self {
        let stem = out.with_extension("");
        let with = |suffix: &str| {
            let mut s = stem.as_os_str().to_owned();
            s.push(suffix);
            PathBuf::from(s)
        };
        Self {
            config: out.to_path_buf(),
            candidates: with("-candidates.csv"),
            front: with("-front.csv"),
            plot: with("-front"),
            plan: with("-tune.json"),
        }
    }
}

/// The chosen config as a foveation TOML with a header saying how it was chosen.
pub fn config_toml(config: &FoveationConfig, header: &[String]) -> String {
    let mut text: String = header.iter().map(|l| format!("# {l}\n")).collect();
    text.push('\n');
    text.push_str(&config.to_toml());
    text
}

/// Writes `rows` as a CSV file (whole, replacing what was there).
pub fn write_rows<T: Serialize>(path: &Path, rows: &[T]) -> Result<(), String> {
    let mut writer =
        csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    for row in rows {
        writer
            .serialize(row)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    writer
        .flush()
        .map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_sit_beside_the_chosen_config() {
        let f = TuneFiles::new(Path::new("out/vive-90hz.toml"));
        assert_eq!(f.candidates, Path::new("out/vive-90hz-candidates.csv"));
        assert_eq!(f.front, Path::new("out/vive-90hz-front.csv"));
        assert_eq!(f.plot, Path::new("out/vive-90hz-front"));
        assert_eq!(f.plan, Path::new("out/vive-90hz-tune.json"));
    }

    #[test]
    fn the_written_config_reads_back() {
        let config = FoveationConfig::thesis().with_spp(2);
        let text = config_toml(&config, &["tuned by a test".into(), "JOD 9".into()]);
        assert!(text.starts_with("# tuned by a test\n# JOD 9\n"), "{text}");
        let dir = crate::test_dir::TestDir::new("tune-files");
        let path = dir.join("c.toml");
        std::fs::write(&path, text).unwrap();
        assert_eq!(FoveationConfig::load(&path).unwrap(), config);
    }
}
