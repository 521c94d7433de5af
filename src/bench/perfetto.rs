//! trace.json: the GPU passes of every timed frame in the Chrome trace event format, which
//! Perfetto (ui.perfetto.dev) and chrome://tracing open. Written as frames are measured: the
//! format allows the closing `]` to be missing, so a killed run's trace still opens, and a
//! resumed run appends to it.
//!
//! Tracks: one per scene and mode for the GPU passes, one per scene and mode for the CPU
//! frame. A frame is placed at its wall-clock submit time; its passes at their GPU offsets
//! within the frame.

use super::rows::FrameRow;
use serde_json::json;
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

pub struct TraceWriter {
    path: PathBuf,
    out: BufWriter<File>,
    /// Thread ids given out, by track name; named once per file.
    tracks: HashMap<String, u64>,
    /// Whether the file holds an event yet (every later one is preceded by a comma).
    has_events: bool,
}

const PID: u64 = 1;

impl TraceWriter {
    /// Opens `path`, continuing an existing trace (its closing `]`, if any, is removed).
    pub fn open(path: &Path) -> std::io::Result<Self> {
        let existing = path.exists() && std::fs::metadata(path)?.len() > 0;
        let mut file = OpenOptions::new()
            .create(true)
            .read(true)
            .write(true)
            .truncate(false)
            .open(path)?;
        let mut tracks = HashMap::new();
        if existing {
            let mut text = String::new();
            file.read_to_string(&mut text)?;
            // Reuse the track ids the file already names, so resumed frames join their tracks.
            for line in text.lines() {
                if let Ok(event) =
                    serde_json::from_str::<serde_json::Value>(line.trim_start_matches(','))
                {
                    if event["ph"] == "M" && event["name"] == "thread_name" {
                        if let (Some(name), Some(tid)) =
                            (event["args"]["name"].as_str(), event["tid"].as_u64())
                        {
                            tracks.insert(name.to_string(), tid);
                        }
                    }
                }
            }
            let keep = text.trim_end().trim_end_matches(']').len() as u64;
            file.set_len(keep)?;
            file.seek(SeekFrom::End(0))?;
        }
        let mut writer = Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            tracks,
            has_events: existing,
        };
        if !existing {
            writer.out.write_all(b"[\n")?;
            writer.event(&json!({
                "ph": "M", "pid": PID, "name": "process_name", "args": {"name": "fovea bench"}
            }))?;
        }
        writer.out.flush()?;
        Ok(writer)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes one event on its own line. Every event but the first starts with a comma, so
    /// the file is valid JSON once `]` is appended.
    fn event(&mut self, value: &serde_json::Value) -> std::io::Result<()> {
        if self.has_events {
            self.out.write_all(b",")?;
        }
        self.has_events = true;
        serde_json::to_writer(&mut self.out, value)?;
        self.out.write_all(b"\n")
    }

    fn track(&mut self, name: String) -> std::io::Result<u64> {
        if let Some(&tid) = self.tracks.get(&name) {
            return Ok(tid);
        }
        let tid = self.tracks.values().max().map_or(1, |t| t + 1);
        self.event(&json!({
            "ph": "M", "pid": PID, "tid": tid, "name": "thread_name", "args": {"name": name}
        }))?;
        // Sort tracks in the order they first appear.
        self.event(&json!({
            "ph": "M", "pid": PID, "tid": tid, "name": "thread_sort_index",
            "args": {"sort_index": tid}
        }))?;
        self.tracks.insert(name, tid);
        Ok(tid)
    }

    /// The passes of one frame (`passes`: name, start and duration in GPU ms) and its CPU
    /// time, described by the frame's first row.
    pub fn frame(&mut self, row: &FrameRow, passes: &[(String, f64, f64)]) -> std::io::Result<()> {
        let label = format!("{} {}", row.scene, row.mode.name());
        let gpu = self.track(format!("{label} GPU"))?;
        let cpu = self.track(format!("{label} CPU"))?;
        let args = json!({"repeat": row.repeat, "frame": row.frame});
        self.event(&json!({
            "ph": "X", "pid": PID, "tid": cpu, "name": format!("frame {}", row.frame),
            "ts": row.wall_us, "dur": row.cpu_ms * 1e3, "args": args
        }))?;
        for (name, start_ms, ms) in passes {
            self.event(&json!({
                "ph": "X", "pid": PID, "tid": gpu, "name": name,
                "ts": row.wall_us as f64 + start_ms * 1e3, "dur": ms * 1e3, "args": args
            }))?;
        }
        self.out.flush()
    }

    /// Closes the JSON array.
    pub fn finish(mut self) -> std::io::Result<()> {
        self.out.write_all(b"]\n")?;
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::protocol::Mode;

    fn row(frame: u32) -> FrameRow {
        FrameRow {
            scene: "control".into(),
            mode: Mode::Forward,
            repeat: 0,
            frame,
            eye: "left".into(),
            gpu_plan_ms: 0.5,
            trace_ms: 1.0,
            resolve_ms: 0.25,
            eye_gpu_ms: 1.75,
            frame_gpu_ms: 3.5,
            cpu_ms: 5.0,
            plan_ms: 0.1,
            record_ms: 0.05,
            paths: 10,
            rays: 20,
            nonfinite: 0,
            overflows: 0,
            gaze_x: 1.0,
            gaze_y: 2.0,
            wall_us: 1_000_000 + frame as u64 * 10_000,
            ..Default::default()
        }
    }

    fn passes() -> Vec<(String, f64, f64)> {
        vec![
            ("left trace".into(), 0.0, 1.0),
            ("left resolve".into(), 1.0, 0.5),
        ]
    }

    fn events(path: &Path) -> Vec<serde_json::Value> {
        let text = std::fs::read_to_string(path).unwrap();
        serde_json::from_str::<Vec<serde_json::Value>>(&text).unwrap()
    }

    #[test]
    fn a_finished_trace_is_json_and_a_resumed_one_joins_its_tracks() {
        let dir = crate::test_dir::TestDir::new("trace");
        let path = dir.join("trace.json");
        let mut w = TraceWriter::open(&path).unwrap();
        w.frame(&row(0), &passes()).unwrap();
        drop(w); // killed: no closing bracket
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(serde_json::from_str::<serde_json::Value>(&format!("{text}]")).is_ok());

        let mut w = TraceWriter::open(&path).unwrap();
        w.frame(&row(1), &passes()).unwrap();
        w.finish().unwrap();
        let all = events(&path);
        let slices: Vec<_> = all.iter().filter(|e| e["ph"] == "X").collect();
        assert_eq!(slices.len(), 2 * 3, "a CPU frame and two passes per frame");
        let names: Vec<_> = all.iter().filter(|e| e["name"] == "thread_name").collect();
        assert_eq!(
            names.len(),
            2,
            "the resumed run reuses the GPU and CPU tracks"
        );
        let resolve = slices
            .iter()
            .find(|e| e["name"] == "left resolve" && e["args"]["frame"] == 1)
            .unwrap();
        assert_eq!(resolve["ts"].as_f64().unwrap(), 1_010_000.0 + 1000.0);
        assert_eq!(resolve["dur"].as_f64().unwrap(), 500.0);

        // Opening a finished trace again removes its bracket and goes on.
        let mut w = TraceWriter::open(&path).unwrap();
        w.frame(&row(2), &passes()).unwrap();
        w.finish().unwrap();
        assert_eq!(events(&path).iter().filter(|e| e["ph"] == "X").count(), 9);
    }
}
