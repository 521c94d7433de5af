//! `fovea bench --motion` as a user runs it, on lavapipe with validation on: the sequences'
//! rows, summary, report, plots and animation are written and parse; the temporal history
//! makes a still view converge and cuts the periphery's flicker under motion; an interrupted
//! run resumes to the rows of an uninterrupted one; bad input gets a message.

mod common;

use common::fovea;
use std::collections::BTreeSet;
use std::path::Path;

fn temp_dir(name: &str) -> common::TestDir {
    common::test_dir(&format!("motion-{name}"))
}

const FRAMES: usize = 8;
/// Three sequences × frames × two eyes × (whole image + four bands).
const ROWS: usize = 3 * FRAMES * 2 * 5;

fn run_args<'a>(script: &'a str, dir: &'a str, cache: &'a str) -> Vec<&'a str> {
    vec![
        "bench",
        "--motion",
        script,
        "--scenes",
        "cubes-441",
        "--frames",
        "8",
        "--width",
        "64",
        "--height",
        "72",
        "--spp",
        "2",
        "--reference-spp",
        "128",
        "--dir",
        dir,
        "--reference-cache",
        cache,
    ]
}

fn rows(path: &Path) -> Vec<csv::StringRecord> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    reader.records().map(|r| r.unwrap()).collect()
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// A sequence's mean of `field` (rel_mse, rel_mse_settled, flicker) in `region`.
fn mean(summary: &serde_json::Value, sequence: &str, region: &str, field: &str) -> f64 {
    let seq = summary["scenes"][0]["sequences"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["sequence"] == sequence)
        .unwrap_or_else(|| panic!("no sequence {sequence}"));
    seq["regions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["region"] == region)
        .and_then(|r| r[field].as_f64())
        .unwrap_or_else(|| panic!("{sequence} has no {field} in {region}"))
}

#[test]
fn a_moving_run_writes_every_file_and_history_calms_the_periphery() {
    let dir = temp_dir("moving");
    let run = dir.join("run");
    let cache = dir.join("refs");
    let args = run_args(
        "head-and-saccades",
        run.to_str().unwrap(),
        cache.to_str().unwrap(),
    );
    let (ok, text) = fovea(&args);
    assert!(ok, "{text}");
    assert!(text.contains("temporal-on-2spp"), "{text}");

    let motion = rows(&run.join("motion.csv"));
    assert_eq!(motion.len(), ROWS);
    // A reference per frame: the head never stands still.
    let references = std::fs::read_dir(&cache).unwrap().count();
    assert_eq!(references, FRAMES);
    let s = summary(&run);
    assert_eq!(s["complete"], true);
    assert_eq!(s["parameters"]["motion"]["frame_rate_hz"], 90.0);

    // The history keeps the periphery's noise from changing every frame: less flicker
    // beyond 20° than fresh frames at the same spp (the sparsest layer, where each frame's
    // bicubic fill of a new lattice would shimmer).
    let (on, off) = (
        mean(&s, "temporal-on-2spp", "20+", "flicker"),
        mean(&s, "temporal-off-2spp", "20+", "flicker"),
    );
    assert!(on < 0.7 * off, "flicker beyond 20°: on {on}, off {off}");

    // FovVideoVDP judged every sequence and eye as a video.
    let jods = rows(&run.join("motion-jod.csv"));
    assert_eq!(jods.len(), 3 * 2, "{jods:?}");
    for r in &jods {
        assert_eq!(&r[3], FRAMES.to_string().as_str(), "{r:?}");
        let jod: f64 = r[4].parse().unwrap();
        assert!(jod > 0.0 && jod < 10.0, "{r:?}");
    }
    let sequences = s["scenes"][0]["sequences"].as_array().unwrap();
    assert!(
        sequences.iter().all(|q| q["jod"].as_f64().is_some()),
        "{sequences:?}"
    );

    let report = std::fs::read_to_string(run.join("report.md")).unwrap();
    assert!(report.contains("History on against off"), "{report}");
    assert!(report.contains("JOD (video)"), "{report}");
    for region in ["whole", "0-6", "6-10", "10-20", "20+"] {
        for what in ["error", "flicker"] {
            let plot = run.join(format!("plots/cubes-441-motion-{what}-{region}.png"));
            assert!(plot.exists(), "{}", plot.display());
        }
    }
    // The animation: an APNG of every frame, five panels of the 64-px eye side by side.
    let file = std::fs::File::open(run.join("images/cubes-441-motion.png")).unwrap();
    let reader = png::Decoder::new(file).read_info().unwrap();
    let info = reader.info();
    assert_eq!(
        info.animation_control().map(|a| a.num_frames),
        Some(FRAMES as u32)
    );
    assert_eq!(info.width, 5 * 64 + 4 * 4);
}

#[test]
fn a_still_view_converges_with_history_and_not_without() {
    let dir = temp_dir("still");
    let run = dir.join("run");
    let cache = dir.join("refs");
    let (ok, text) = fovea(&run_args(
        "still",
        run.to_str().unwrap(),
        cache.to_str().unwrap(),
    ));
    assert!(ok, "{text}");
    // One pose: one reference for every frame.
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 1);
    let s = summary(&run);
    // In the fovea (every pixel traced every frame) fresh frames keep their error and
    // accumulated ones lose it: the history's second half is well below its mean over all
    // frames and below fresh frames at twice the spp. (8 frames of 2 spp: the second half
    // averages 10–16 samples a pixel.)
    let settled = mean(&s, "temporal-on-2spp", "0-6", "rel_mse_settled");
    let all = mean(&s, "temporal-on-2spp", "0-6", "rel_mse");
    let fresh = mean(&s, "temporal-off-4spp", "0-6", "rel_mse_settled");
    assert!(settled < 0.6 * all, "settled {settled}, all frames {all}");
    assert!(
        settled < 0.6 * fresh,
        "settled {settled}, fresh 4 spp {fresh}"
    );
    let off_settled = mean(&s, "temporal-off-2spp", "0-6", "rel_mse_settled");
    let off_all = mean(&s, "temporal-off-2spp", "0-6", "rel_mse");
    assert!(
        off_settled > 0.6 * off_all,
        "without history a still view does not converge: {off_settled} vs {off_all}"
    );
}

#[test]
fn an_interrupted_motion_run_resumes_to_the_same_rows() {
    let dir = temp_dir("resume");
    let cache = dir.join("refs");
    let (whole, cut) = (dir.join("whole"), dir.join("cut"));
    let (ok, text) = fovea(&run_args(
        "head-and-saccades",
        whole.to_str().unwrap(),
        cache.to_str().unwrap(),
    ));
    assert!(ok, "{text}");
    // An interrupted run: the first sequence complete, the second cut mid-frame with a
    // torn last line, no summary or animation yet.
    std::fs::create_dir_all(&cut).unwrap();
    std::fs::copy(whole.join("plan.json"), cut.join("plan.json")).unwrap();
    let text = std::fs::read_to_string(whole.join("motion.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let kept = 1 + ROWS / 3 + 17;
    let mut torn = lines[..kept].join("\n");
    torn.push_str("\ncubes-441,temporal-on-2spp,true,2,3,33.3");
    std::fs::write(cut.join("motion.csv"), torn).unwrap();

    let (ok, text) = fovea(&["bench", "--resume", cut.to_str().unwrap()]);
    assert!(ok, "{text}");
    let keys = |path: &Path| -> BTreeSet<Vec<String>> {
        rows(path)
            .iter()
            .map(|r| [0, 1, 4, 6, 7].iter().map(|&i| r[i].to_string()).collect())
            .collect()
    };
    let resumed = rows(&cut.join("motion.csv"));
    assert_eq!(resumed.len(), ROWS);
    assert_eq!(
        keys(&cut.join("motion.csv")),
        keys(&whole.join("motion.csv"))
    );
    // The complete first sequence was kept as it was, not measured again.
    assert_eq!(
        &resumed[..ROWS / 3],
        &rows(&whole.join("motion.csv"))[..ROWS / 3]
    );
    assert_eq!(summary(&cut)["complete"], true);
    assert!(cut.join("images/cubes-441-motion.png").exists());
}

#[test]
fn bad_motion_input_gets_a_clear_error() {
    let dir = temp_dir("bad");
    let d = dir.join("x");
    let d = d.to_str().unwrap();
    let trace = dir.join("gaze.csv");
    std::fs::write(
        &trace,
        "frame,time_s,left_tan_x,left_tan_y,right_tan_x,right_tan_y,status\n0,0,0,0,0,0,fixed\n",
    )
    .unwrap();
    let cases: [(&[&str], &str); 3] = [
        (
            &["bench", "--motion", "--frames", "1", "--dir", d],
            "--frames of at least 2",
        ),
        (
            &["bench", "--motion", "spin", "--dir", d],
            "invalid value 'spin'",
        ),
        (
            &[
                "bench",
                "--motion",
                "--gaze-trace",
                trace.to_str().unwrap(),
                "--dir",
                d,
            ],
            "drop --gaze-trace",
        ),
    ];
    for (args, expected) in cases {
        let (ok, text) = fovea(args);
        assert!(!ok, "{args:?} succeeded");
        assert!(text.contains(expected), "{args:?}: {text}");
        assert!(!Path::new(d).exists(), "{args:?} left {d} behind");
    }
}
