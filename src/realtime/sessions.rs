//! Headset sessions on the simulated headset at the plan's size, paced in real time at
//! 90 Hz: `fovea xr --simulated` run as a child process per frames-in-flight setting, read
//! back from its session files (session.json, frames.csv).

use super::plan::RealtimePlan;
use crate::bench::csv_log::CsvLog;
use crate::bench::rows::FrameRow;
use crate::bench::stats::{summarize, Summary};
use std::path::Path;
use std::process::Command;

/// A gaze script for the simulated eye tracker (frame, degrees right, degrees up): a new
/// fixation every 27 frames (300 ms at 90 Hz), so the latched gaze keeps moving.
const GAZE: &str = "0 0 0; 27 10 5; 54 -12 3; 81 5 -8; 108 15 10; 135 -5 -5; 162 8 8; 189 0 0";

/// One session's pacing and latency.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SessionTiming {
    pub frames_in_flight: u32,
    pub frames: usize,
    /// Predicted display time of a frame minus the previous frame's.
    pub frame_period_ms: Option<Summary>,
    /// Display periods no frame of ours was ready for.
    pub missed_frames: u64,
    /// Those after the second frame: without the first frame's pipelines and caches, which
    /// the periods before the second frame wait for.
    pub missed_after_start: u64,
    pub gaze_to_photon_ms: Option<Summary>,
    /// Fraction of frames submitted while an earlier frame still ran on the GPU.
    pub overlapped: f64,
    /// GPU time of a stereo frame.
    pub gpu_ms: Option<Summary>,
    /// The most GPU memory fovea held after a frame, MiB.
    pub gpu_mib_max: f64,
}

/// Runs one session per frames-in-flight setting, its files under `dir`.
pub fn run_sessions(plan: &RealtimePlan, dir: &Path) -> Result<Vec<SessionTiming>, String> {
    let exe = std::env::current_exe()
        .map_err(|e| format!("cannot find fovea's own executable to start sessions: {e}"))?;
    plan.frames_in_flight
        .iter()
        .map(|&k| {
            let session = dir.join(format!("session-{k}-in-flight"));
            let _ = std::fs::remove_dir_all(&session);
            run_session(&exe, plan, k, &session)?;
            read_session(k, &session)
        })
        .collect()
}

fn run_session(exe: &Path, plan: &RealtimePlan, in_flight: u32, dir: &Path) -> Result<(), String> {
    let out = Command::new(exe)
        .args(["xr", "--simulated", "--scene", &plan.xr_scene])
        .args(["--frames", &plan.xr_frames.to_string()])
        .args(["--frames-in-flight", &in_flight.to_string()])
        .arg("--session")
        .arg(dir)
        .env(
            "SIM_HEADSET_SIZE",
            format!("{}x{}", plan.width, plan.height),
        )
        .env("SIM_HEADSET_REALTIME", "1")
        .env("SIM_HEADSET_GAZE", GAZE)
        .output()
        .map_err(|e| format!("cannot start `{} xr --simulated`: {e}", exe.display()))?;
    if !out.status.success() {
        return Err(format!(
            "the simulated headset session with {in_flight} frame(s) in flight failed:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(())
}

/// The display periods `frames` missed (each row's count is of the periods before it).
fn missed(frames: &[&FrameRow]) -> u64 {
    frames
        .iter()
        .map(|r| r.missed_frames.unwrap_or(0) as u64)
        .sum()
}

fn read_session(in_flight: u32, dir: &Path) -> Result<SessionTiming, String> {
    let path = dir.join("frames.csv");
    let (_, rows) =
        CsvLog::<FrameRow>::open(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    // One row per eye and frame; the frame's timings are on both.
    let frames: Vec<&FrameRow> = rows.iter().filter(|r| r.eye == "left").collect();
    if frames.is_empty() {
        return Err(format!("{} holds no frame", path.display()));
    }
    let stat = |f: fn(&FrameRow) -> Option<f64>| {
        summarize(&frames.iter().filter_map(|r| f(r)).collect::<Vec<_>>())
    };
    let overlapped = frames
        .iter()
        .filter(|r| r.busy_at_submit.unwrap_or(0) > 0)
        .count() as f64
        / frames.len() as f64;
    Ok(SessionTiming {
        frames_in_flight: in_flight,
        frames: frames.len(),
        frame_period_ms: stat(|r| r.frame_period_ms),
        missed_frames: missed(&frames),
        missed_after_start: missed(&frames[frames.len().min(2)..]),
        gaze_to_photon_ms: stat(|r| r.gaze_to_photon_ms),
        overlapped,
        gpu_ms: stat(|r| Some(r.frame_gpu_ms)),
        gpu_mib_max: frames.iter().filter_map(|r| r.gpu_mib).fold(0.0, f64::max),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_frames_wait_is_counted_apart() {
        let rows: Vec<FrameRow> = [None, Some(108), Some(0), Some(2)]
            .into_iter()
            .map(|missed_frames| FrameRow {
                missed_frames,
                ..Default::default()
            })
            .collect();
        let frames: Vec<&FrameRow> = rows.iter().collect();
        assert_eq!(missed(&frames), 110);
        assert_eq!(missed(&frames[2..]), 2);
    }
}
