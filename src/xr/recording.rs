//! What a headset session leaves behind, in the bench's formats so it is analysed like a
//! bench run: `frames.csv` (one row per frame and eye, the bench's columns: GPU time of every
//! pass, counters, gaze pixel), `gaze.csv` (the gaze trace, replayable with `--gaze-trace`)
//! and `session.json` (the run's facts and the bench's per-mode statistics). Rows are flushed
//! as they are written: a session cut short keeps every frame it rendered.

use super::error::XrError;
use super::frame_record::FrameRecord;
use super::summary::XrSummary;
use crate::bench::csv_log::CsvLog;
use crate::bench::protocol::{FrameKey, Mode};
use crate::bench::rows::{FrameRow, HeadsetTiming};
use crate::bench::stats::{summarize, Summary};
use crate::bench::summary::mode_summary;
use crate::foveation::gaze_trace::{TraceRow, TraceStatus, TraceWriter};
use std::path::{Path, PathBuf};

pub struct SessionRecorder {
    scene: String,
    mode: Mode,
    frames: Option<(PathBuf, CsvLog<FrameRow>)>,
    gaze: Option<TraceWriter>,
    /// Only what the latency summary needs stays in memory; the rows are on disk (a session
    /// of hours at 90 Hz must not grow by a row per frame).
    timings: Vec<HeadsetTiming>,
    /// The previous frame's predicted display time, seconds.
    last_display_s: Option<f64>,
}

fn output_error(path: &Path, e: impl std::fmt::Display) -> XrError {
    XrError::Output(format!("cannot write {}: {e}", path.display()))
}

impl SessionRecorder {
    /// Records into `dir` (frames.csv, gaze.csv, session.json) and/or the gaze trace alone
    /// into `gaze_file`. `foveated`: the rows' mode is `headset` (foveated around the
    /// headset's gaze), else `regular`.
    pub fn new(
        scene: &str,
        foveated: bool,
        dir: Option<&Path>,
        gaze_file: Option<&Path>,
    ) -> Result<Self, XrError> {
        let frames = match dir {
            Some(dir) => {
                std::fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
                let path = dir.join("frames.csv");
                if path.exists() {
                    return Err(XrError::Output(format!(
                        "{} already holds a session: give another --session directory",
                        dir.display()
                    )));
                }
                let (log, _) = CsvLog::open(&path).map_err(|e| output_error(&path, e))?;
                Some((dir.to_path_buf(), log))
            }
            None => None,
        };
        let gaze_path = gaze_file
            .map(Path::to_path_buf)
            .or_else(|| dir.map(|d| d.join("gaze.csv")));
        let gaze = match gaze_path {
            Some(path) => {
                Some(TraceWriter::create(&path).map_err(|e| XrError::Output(e.to_string()))?)
            }
            None => None,
        };
        Ok(Self {
            scene: scene.to_string(),
            mode: match foveated {
                true => Mode::Headset,
                false => Mode::Regular,
            },
            frames,
            gaze,
            timings: Vec::new(),
            last_display_s: None,
        })
    }

    pub fn frame(&mut self, record: &FrameRecord) -> Result<(), XrError> {
        let timing = headset_timing(record, self.last_display_s);
        self.last_display_s = Some(record.display_time_s);
        self.timings.push(timing);
        if let Some((dir, log)) = &mut self.frames {
            let key = FrameKey {
                scene: self.scene.clone(),
                mode: self.mode,
                repeat: 0,
                frame: record.index as u32,
            };
            let wall_us = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_micros() as u64);
            for row in FrameRow::from_frame(&key, record.frame, record.cpu_ms, wall_us) {
                let row = row
                    .with_timing(&timing)
                    .with_memory(resident_mib(), record.gpu_bytes as f64 / MIB);
                log.append(&row)
                    .map_err(|e| output_error(&dir.join("frames.csv"), e))?;
            }
        }
        if let Some(writer) = &mut self.gaze {
            let gazes: Vec<_> = record.frame.gazes.iter().map(|(p, _)| *p).collect();
            let tangents: Vec<[f64; 2]> = gazes
                .iter()
                .zip(record.images)
                .map(|(p, image)| image.tan_of(p[0], p[1]))
                .collect();
            let row = TraceRow {
                frame: record.index,
                time_s: record.gaze_time_s,
                left: tangents[0],
                right: tangents[tangents.len() - 1],
                status: TraceStatus::from(record.gaze.status),
            };
            writer
                .write(&row)
                .map_err(|e| XrError::Output(e.to_string()))?;
        }
        Ok(())
    }

    /// The session's latency and pacing so far: the bench's statistics (median, p99, ...) of
    /// each frame timing (summarize skips the first frame's NaN period), frames missed in all.
    pub fn latency(&self) -> LatencySummary {
        let stat = |f: fn(&HeadsetTiming) -> f64| {
            summarize(&self.timings.iter().map(f).collect::<Vec<_>>())
        };
        LatencySummary {
            frames: self.timings.len(),
            gaze_to_photon_ms: stat(|t| t.gaze_to_photon_ms),
            latch_ms: stat(|t| t.latch_ms),
            gpu_done_ms: stat(|t| t.gpu_done_ms),
            frame_period_ms: stat(|t| t.frame_period_ms),
            missed_frames: self.timings.iter().map(|t| t.missed_frames as u64).sum(),
        }
    }

    /// Writes session.json: the session's facts and the bench's statistics of its frames.
    pub fn finish(self, summary: &XrSummary) -> Result<(), XrError> {
        let Some((dir, _)) = &self.frames else {
            return Ok(());
        };
        // The statistics from the rows written, read back once at the end.
        let frames_csv = dir.join("frames.csv");
        let (_, written) =
            CsvLog::<FrameRow>::open(&frames_csv).map_err(|e| output_error(&frames_csv, e))?;
        let rows: Vec<&FrameRow> = written.iter().collect();
        let json = serde_json::json!({
            "runtime": summary.runtime,
            "device": summary.device,
            "scene": self.scene,
            "eye_size": summary.eye_size,
            "swapchain_format": summary.swapchain_format,
            "frames": summary.frames,
            "sessions": summary.sessions,
            "eye_gaze": summary.no_gaze.unwrap_or("tracked by the headset"),
            "visibility_mask": summary.visibility_mask,
            "end": format!("{:?}", summary.end),
            "states": summary.states.iter().map(|s| format!("{s:?}")).collect::<Vec<_>>(),
            "statistics": mode_summary(self.mode, &rows),
            "latency": self.latency(),
        });
        let path = dir.join("session.json");
        let text = serde_json::to_string_pretty(&json).map_err(|e| output_error(&path, e))?;
        std::fs::write(&path, text).map_err(|e| output_error(&path, e))
    }
}

/// A frame's timing, from its record and the previous frame's display time.
fn headset_timing(record: &FrameRecord, last_display_s: Option<f64>) -> HeadsetTiming {
    // A new session after a lost one may start a new timeline: no period across it.
    let period_s = last_display_s
        .map(|last| record.display_time_s - last)
        .filter(|p| *p > 0.0)
        .unwrap_or(f64::NAN);
    // A frame displayed n display periods after the previous one left n - 1 periods to
    // the compositor's reprojection of an older frame.
    let missed = match period_s.is_finite() && record.display_period_s > 0.0 {
        true => ((period_s / record.display_period_s).round() as i64 - 1).max(0) as u32,
        false => 0,
    };
    HeadsetTiming {
        // No sample (no tracker, or not focused yet): no age to give.
        gaze_to_photon_ms: match record.gaze_sampled {
            true => (record.display_time_s - record.gaze_time_s) * 1e3,
            false => f64::NAN,
        },
        latch_ms: record.latch_ms,
        gpu_done_ms: record.gpu_done_ms,
        frame_period_ms: period_s * 1e3,
        missed_frames: missed,
        busy_at_submit: record.frame.stats.busy_at_submit,
    }
}

/// session.json's "latency": how old the gaze was when shown and how the frames were paced.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LatencySummary {
    pub frames: usize,
    pub gaze_to_photon_ms: Option<Summary>,
    pub latch_ms: Option<Summary>,
    pub gpu_done_ms: Option<Summary>,
    pub frame_period_ms: Option<Summary>,
    pub missed_frames: u64,
}

const MIB: f64 = 1024.0 * 1024.0;

/// The process's resident memory in MiB (Linux: /proc/self/status's VmRSS), None where the
/// system does not say.
pub fn resident_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
