//! `fovea bench` as a user runs it, on lavapipe with validation on: every file is written and
//! parses, row counts follow the protocol, and a killed run resumes to the same rows.

mod common;

use common::fovea;
use std::collections::BTreeSet;
use std::path::Path;

fn temp_dir(name: &str) -> common::TestDir {
    common::test_dir(&format!("bench-{name}"))
}

/// A `--quick` run cut down to two scenes at a small size so the test takes seconds.
fn small_run<'a>(dir: &'a str, cache: &'a str) -> Vec<&'a str> {
    vec![
        "bench",
        "--quick",
        "--scenes",
        "control,bunny-low",
        "--frames",
        "3",
        "--repeats",
        "2",
        "--width",
        "40",
        "--height",
        "36",
        "--reference-spp",
        "32",
        "--sweep-spp",
        "1,2",
        "--sweep-frames",
        "1",
        "--dir",
        dir,
        "--reference-cache",
        cache,
    ]
}

const SCENES: u64 = 2;
const FRAMES: u64 = 3;
const EYES: u64 = 2;
/// regular 1 + forward 2 + corner 2 repeats.
const RUNS_PER_SCENE: u64 = 5;
/// spp 1, 2 and the protocol's 4, three modes, whole image + four bands.
const QUALITY_ROWS: u64 = SCENES * 3 * 3 * EYES * 5;

fn csv_rows(path: &Path) -> Vec<csv::StringRecord> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    reader.records().map(|r| r.unwrap()).collect()
}

/// The identity of every row: all columns up to the first measured one.
fn keys(path: &Path, columns: usize) -> BTreeSet<Vec<String>> {
    let rows = csv_rows(path);
    let keys: BTreeSet<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().take(columns).map(str::to_string).collect())
        .collect();
    assert_eq!(keys.len(), rows.len(), "{}: duplicate rows", path.display());
    keys
}

/// trace.json of a run, which must parse as one JSON array.
fn trace_events(run: &Path) -> Vec<serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(run.join("trace.json")).unwrap()).unwrap()
}

/// The CPU frame slices of a trace: one per timed frame.
fn frame_slices(trace: &[serde_json::Value]) -> u64 {
    trace
        .iter()
        .filter(|e| e["ph"] == "X" && e["name"].as_str().unwrap().starts_with("frame"))
        .count() as u64
}

#[test]
fn a_quick_run_writes_every_file_and_they_parse() {
    let dir = temp_dir("quick");
    let run = dir.join("run");
    let cache = dir.join("references");
    let (ok, text) = fovea(&small_run(run.to_str().unwrap(), cache.to_str().unwrap()));
    assert!(ok, "{text}");
    assert!(text.contains("impact forward"), "{text}");

    // frames.csv: scenes × runs × frames × eyes, with GPU times that add up.
    let frames = csv_rows(&run.join("frames.csv"));
    assert_eq!(frames.len() as u64, SCENES * RUNS_PER_SCENE * FRAMES * EYES);
    let header = csv::Reader::from_path(run.join("frames.csv"))
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    for r in &frames {
        let f = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert!(f("frame_gpu_ms") > 0.0 && f("cpu_ms") > 0.0, "{r:?}");
        let sum = f("gpu_plan_ms") + f("trace_ms") + f("resolve_ms");
        assert!((sum - f("eye_gpu_ms")).abs() < 1e-9, "{r:?}");
        assert!(f("eye_gpu_ms") <= f("frame_gpu_ms") + 1e-9, "{r:?}");
        assert!(f("rays") >= f("paths") && f("paths") > 0.0, "{r:?}");
        assert_eq!(&r[col("nonfinite")], "0");
        // Regular frames trace every pixel at 4 spp; foveated ones fewer.
        let paths = f("paths") as u64;
        match &r[col("mode")] {
            "regular" => assert_eq!(paths, 40 * 36 * 4),
            _ => assert!(paths < 40 * 36 * 4, "{r:?}"),
        }
    }

    // quality.csv: every sweep point, eye and region; finite errors, identical-free.
    let quality = csv_rows(&run.join("quality.csv"));
    assert_eq!(quality.len() as u64, QUALITY_ROWS);
    // JOD (tools/setup-fvvdp.sh's venv): on every whole-image row, none on the bands, and
    // regular rendering at 4 spp scores above 1 spp in every scene and eye.
    let header = csv::Reader::from_path(run.join("quality.csv"))
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    let q = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut regular: std::collections::HashMap<(String, String, String), f64> =
        std::collections::HashMap::new();
    for r in &quality {
        let jod = &r[q("jod")];
        if &r[q("region")] != "whole" {
            assert_eq!(jod, "", "{r:?}");
            continue;
        }
        let jod: f64 = jod.parse().unwrap_or_else(|_| panic!("{r:?}"));
        assert!(jod > 0.0 && jod < 10.0, "{r:?}");
        if &r[q("mode")] == "regular" {
            let key = (
                r[q("scene")].to_string(),
                r[q("eye")].to_string(),
                r[q("spp")].to_string(),
            );
            regular.insert(key, jod);
        }
    }
    for scene in ["control", "bunny-low"] {
        for eye in ["left", "right"] {
            let at = |spp: &str| regular[&(scene.to_string(), eye.to_string(), spp.to_string())];
            assert!(
                at("4") > at("1"),
                "{scene} {eye}: 4 spp {} against 1 spp {}",
                at("4"),
                at("1")
            );
        }
    }

    // summary.json: complete, with device, parameters and an impact factor per foveated mode.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["complete"], true);
    assert_eq!(
        summary["frame_rows"].as_u64().unwrap(),
        SCENES * RUNS_PER_SCENE * FRAMES * EYES
    );
    assert!(summary["device"]["name"].as_str().unwrap().len() > 1);
    assert!(summary["device"]["driver"].as_str().is_some());
    assert_eq!(summary["parameters"]["width"], 40);
    assert_eq!(
        summary["parameters"]["foveation"]["layers"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    // lavapipe is a CPU driver: `--traversal auto` measured the software traversal.
    assert_eq!(summary["parameters"]["traversal"], "software");
    for scene in summary["scenes"].as_array().unwrap() {
        let modes = scene["modes"].as_array().unwrap();
        // Throughput: paths of a frame over its median GPU time.
        let paths = modes[0]["paths_per_frame"].as_f64().unwrap();
        let median_ms = modes[0]["rates"]["ms"]["median"].as_f64().unwrap();
        let msamples = modes[0]["msamples_per_s"].as_f64().unwrap();
        assert!((msamples - paths / (median_ms * 1e3)).abs() < 1e-9 * msamples.max(1.0));
        assert_eq!(modes[0]["frames"], FRAMES);
        assert_eq!(modes[1]["frames"], 2 * FRAMES);
        assert!(modes[1]["impact"]["factor"].as_f64().unwrap() > 0.0);
        assert!(modes[0]["rates"]["fps"]["mean"].as_f64().unwrap() > 0.0);
    }

    // trace.json: a JSON array with a CPU frame slice and GPU pass slices for every frame.
    let trace = trace_events(&run);
    assert_eq!(frame_slices(&trace), SCENES * RUNS_PER_SCENE * FRAMES);
    assert!(trace.iter().any(|e| e["name"] == "right resolve"));

    // report.md names every scene and links files that exist.
    let report = std::fs::read_to_string(run.join("report.md")).unwrap();
    for scene in ["control", "bunny-low"] {
        assert!(report.contains(&format!("## {scene}")), "{report}");
        for plot in [
            "frames",
            "mean-std",
            "error-time-whole",
            "error-time-fovea",
            "jod-time",
        ] {
            for ext in ["svg", "png"] {
                let path = run.join(format!("plots/{scene}-{plot}.{ext}"));
                assert!(path.exists(), "{} missing", path.display());
            }
        }
        let strip = run.join(format!("images/{scene}.png"));
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&strip).unwrap(),
        ));
        let info = decoder.read_info().unwrap().info().clone();
        assert!(info.width >= 5 * 40, "five panels side by side");
    }
    assert!(!report.contains("Incomplete run"));
    assert!(report.contains("software traversal") && report.contains("Msamples/s"));
    // The references were cached: a second run renders none and measures the same errors.
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 2);
}

#[test]
fn a_killed_run_resumes_to_the_rows_of_an_uninterrupted_one() {
    let dir = temp_dir("resume");
    let cache = dir.join("references");
    let (whole, killed) = (dir.join("whole"), dir.join("killed"));
    let (ok, text) = fovea(&small_run(whole.to_str().unwrap(), cache.to_str().unwrap()));
    assert!(ok, "{text}");

    // Killed after 7 frames (in the middle of the first scene's second repeat).
    let mut args = small_run(killed.to_str().unwrap(), cache.to_str().unwrap());
    args.extend(["--abort-after-frames", "7"]);
    let (ok, _) = fovea(&args);
    assert!(!ok, "an aborted run exits with failure");
    assert_eq!(csv_rows(&killed.join("frames.csv")).len(), 7 * 2);
    assert!(!killed.join("summary.json").exists());
    // A kill can cut the last row in half; resume must cope.
    let mut torn = std::fs::read_to_string(killed.join("frames.csv")).unwrap();
    torn.push_str("bunny-low,forward,1,2,le");
    std::fs::write(killed.join("frames.csv"), torn).unwrap();

    let (ok, text) = fovea(&["bench", "--resume", killed.to_str().unwrap()]);
    assert!(ok, "{text}");
    assert_eq!(
        keys(&killed.join("frames.csv"), 5),
        keys(&whole.join("frames.csv"), 5)
    );
    assert_eq!(
        keys(&killed.join("quality.csv"), 5),
        keys(&whole.join("quality.csv"), 5)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(killed.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["complete"], true);
    assert_eq!(
        frame_slices(&trace_events(&killed)),
        SCENES * RUNS_PER_SCENE * FRAMES
    );

    // A finished run resumed again measures nothing new.
    let before = std::fs::read_to_string(killed.join("frames.csv")).unwrap();
    let (ok, text) = fovea(&["bench", "--resume", killed.to_str().unwrap()]);
    assert!(ok, "{text}");
    assert_eq!(
        std::fs::read_to_string(killed.join("frames.csv")).unwrap(),
        before
    );
    // The report names the command that started the run and each that resumed it.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(killed.join("summary.json")).unwrap())
            .unwrap();
    let commands = summary["commands"].as_array().unwrap();
    assert_eq!(commands.len(), 3);
    assert!(commands[0]
        .as_str()
        .unwrap()
        .contains("--abort-after-frames 7"));
    assert!(commands[2].as_str().unwrap().contains("--resume"));
}

#[test]
fn bad_bench_input_gets_a_clear_error() {
    let dir = temp_dir("bad");
    let d = dir.join("x");
    let d = d.to_str().unwrap();
    let cases: [(&[&str], &str); 7] = [
        (
            &["bench", "--frames", "0", "--dir", d],
            "--frames must be at least 1",
        ),
        (
            &["bench", "--scenes", "nowhere", "--quick", "--dir", d],
            "unknown scene 'nowhere'",
        ),
        (
            &["bench", "--foveation", "off", "--dir", d],
            "nothing to compare",
        ),
        (
            &["bench", "--reference-spp", "8", "--dir", d],
            "not converged enough",
        ),
        (
            &["bench", "--resume", d],
            "--resume needs the directory of an earlier",
        ),
        (&["bench", "--resume", d, "--frames", "3"], "drop --frames"),
        (
            &["bench", "--resume", d, "--display", "varjo-xr-4"],
            "drop --display",
        ),
    ];
    for (args, expected) in cases {
        let (ok, text) = fovea(args);
        assert!(!ok, "{args:?} succeeded");
        assert!(text.contains(expected), "{args:?}: {text}");
        assert!(!Path::new(d).exists(), "{args:?} left {d} behind");
    }
}

/// `--traversal rayquery` measures the run through ray queries and says so in plan.json and
/// the report; resuming takes the traversal (and the sampler) from the plan, so naming another
/// is refused. `--display` sets the field of view and photometry, the sizes given keep theirs.
#[test]
fn a_ray_query_run_records_its_traversal() {
    let dir = temp_dir("rayquery");
    let run = dir.join("run");
    let (run_s, cache) = (run.to_str().unwrap(), dir.join("references"));
    let mut args = vec!["bench", "--quick", "--scenes", "cubes-441", "--frames", "1"];
    args.extend(["--repeats", "1", "--width", "16", "--height", "16"]);
    args.extend([
        "--reference-spp",
        "4",
        "--sweep-spp",
        "1",
        "--sweep-frames",
        "1",
    ]);
    args.extend(["--dir", run_s, "--reference-cache", cache.to_str().unwrap()]);
    args.extend(["--traversal", "rayquery"]);
    // The Varjo XR-4's field of view and photometry, at the small size given.
    args.extend(["--display", "varjo-xr-4"]);
    let (ok, text) = fovea(&args);
    assert!(ok && text.contains("(rayquery traversal)"), "{text}");
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["traversal"], "rayquery");
    let report = std::fs::read_to_string(run.join("report.md")).unwrap();
    assert!(report.contains("rayquery traversal"), "{report}");
    let (ok, text) = fovea(&["bench", "--resume", run_s, "--traversal", "software"]);
    assert!(!ok && text.contains("drop --traversal"), "{text}");
    assert_eq!(
        (&plan["profile"], &plan["fov"], &plan["width"]),
        (&"varjo-xr-4".into(), &"varjo-xr-4".into(), &16.into())
    );
    // The sampler is the plan's too.
    assert_eq!(plan["sampler"], "zsobol");
    let (ok, text) = fovea(&["bench", "--resume", run_s, "--sampler", "independent"]);
    assert!(!ok && text.contains("drop --sampler independent"), "{text}");
}
