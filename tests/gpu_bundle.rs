//! The GPU bundle (issue 35): tools/gpu-bundle.sh packs this build, and the bundle's
//! run-report.sh, run from a directory holding nothing but the bundle and with the bundle's
//! own Vulkan loader, writes a complete quick report on lavapipe: every file parses, a row for
//! every scene, config, eye count and traversal, every pass timed, a fovea spp search that
//! agrees with its own measurements, and three headset sessions.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

fn rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    reader.deserialize().map(|r| r.unwrap()).collect()
}

fn number(row: &BTreeMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column} = '{}' in {row:?}", row[column]))
}

#[test]
fn the_bundle_alone_writes_a_complete_quick_report() {
    let dir = common::test_dir("gpu-bundle");
    let bundle = dir.join("fovea-gpu");
    // This test build's fovea and simulated headset (cargo test leaves the library in
    // deps/; a cargo build also puts it beside fovea).
    let built = dir.join("built");
    std::fs::create_dir_all(&built).unwrap();
    let exe = Path::new(env!("CARGO_BIN_EXE_fovea"));
    std::fs::copy(exe, built.join("fovea")).unwrap();
    let library = [
        exe.with_file_name("deps"),
        exe.parent().unwrap().to_path_buf(),
    ]
    .iter()
    .map(|d| d.join("libsim_headset.so"))
    .find(|p| p.exists())
    .expect("libsim_headset.so built beside fovea or in deps/");
    std::fs::copy(library, built.join("libsim_headset.so")).unwrap();
    let out = Command::new("bash")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/gpu-bundle.sh"))
        .arg("--out")
        .arg(&bundle)
        .arg("--prebuilt")
        .arg(&built)
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    std::fs::remove_dir_all(&built).unwrap();
    let size: u64 = ["fovea", "libsim_headset.so"]
        .iter()
        .map(|f| bundle.join(f).metadata().unwrap().len())
        .sum();
    assert!(size < 60 << 20, "{size} bytes");
    assert!(bundle
        .join("loader/usr/lib/x86_64-linux-gnu/libvulkan.so.1")
        .exists());

    // From a directory that holds only the bundle, with the bundle's loader.
    let out = Command::new(bundle.join("run-report.sh"))
        .args(["--quick", "--size", "40x44", "--bundled-loader", "report"])
        .current_dir(&*dir)
        .env("FOVEA_VALIDATION", "1")
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("Vulkan loader from the bundle"), "{text}");
    let report = dir.join("report");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("report.json")).unwrap())
            .unwrap();
    assert!(json["device"]["name"]
        .as_str()
        .unwrap()
        .contains("llvmpipe"));
    let traversals = match json["device"]["ray_queries"].as_bool().unwrap() {
        true => vec!["software", "rayquery"],
        false => vec!["software"],
    };
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("Goal: 90 Hz stereo"), "{md}");

    // A row for every scene, config, eye count and traversal; every pass of each timed.
    let scenes = [
        "control",
        "bunny-low",
        "bunny-high",
        "cubes-441",
        "mirror-room",
        "cornell",
    ];
    let modes = [
        "regular-1spp",
        "thesis",
        "tuned-regular-1spp",
        "tuned-quality",
    ];
    let frames = rows(&report.join("frames.csv"));
    assert_eq!(
        frames.len(),
        scenes.len() * modes.len() * 2 * traversals.len()
    );
    let passes = rows(&report.join("passes.csv"));
    for scene in scenes {
        for mode in modes {
            for traversal in &traversals {
                for (eyes, expected) in [("1", 4), ("2", 7)] {
                    let key = |r: &BTreeMap<String, String>| {
                        r["scene"] == scene
                            && r["mode"] == mode
                            && r["eyes"] == eyes
                            && r["traversal"] == *traversal
                    };
                    let frame: Vec<_> = frames.iter().filter(|r| key(r)).collect();
                    assert_eq!(frame.len(), 1, "{scene} {mode} {eyes} {traversal}");
                    assert!(number(frame[0], "frames") >= 60.0);
                    assert!(number(frame[0], "median_ms") > 0.0);
                    assert!(number(frame[0], "msamples_per_s") > 0.0);
                    // plan, dispatch sizes, trace, resolve; in stereo per eye but the sizes.
                    let of_case: Vec<_> = passes.iter().filter(|r| key(r)).collect();
                    assert_eq!(
                        of_case.len(),
                        expected,
                        "{scene} {mode} {eyes}: {of_case:?}"
                    );
                    let names: BTreeSet<&str> =
                        of_case.iter().map(|r| r["pass"].as_str()).collect();
                    assert_eq!(names.len(), expected);
                    assert!(of_case.iter().all(|r| number(r, "median_ms") >= 0.0
                        && number(r, "p99_ms") >= number(r, "median_ms")));
                }
            }
        }
    }

    // The search: per scene and traversal an answer per budget that its own probes bear
    // out — every spp it visited up to the answer measured within the budget, every spp
    // above it over — and that starts at 1 spp.
    let answers = rows(&report.join("spp.csv"));
    let probes = rows(&report.join("spp-probes.csv"));
    assert_eq!(answers.len(), scenes.len() * traversals.len() * 2);
    for a in &answers {
        let budget = number(a, "budget_ms");
        let spp = number(a, "fovea_spp");
        let of_search: Vec<_> = probes
            .iter()
            .filter(|p| {
                p["scene"] == a["scene"]
                    && p["traversal"] == a["traversal"]
                    && p["budget_ms"] == a["budget_ms"]
            })
            .collect();
        assert_eq!(number(of_search[0], "fovea_spp"), 1.0, "{of_search:?}");
        for p in &of_search {
            let fits = number(p, "median_ms") <= budget;
            assert_eq!(number(p, "fovea_spp") <= spp, fits, "{a:?} against {p:?}");
        }
        if spp > 0.0 {
            assert!(number(a, "median_ms") <= budget, "{a:?}");
        }
    }

    // Three paced headset sessions at the same size; one frame in flight never overlaps.
    let sessions = rows(&report.join("sessions.csv"));
    let in_flight: Vec<f64> = sessions
        .iter()
        .map(|s| number(s, "frames_in_flight"))
        .collect();
    assert_eq!(in_flight, [1.0, 2.0, 3.0]);
    for s in &sessions {
        assert_eq!(number(s, "frames"), 90.0);
        assert!(number(s, "frame_period_median_ms") > 0.0);
        assert!(number(s, "gaze_to_photon_median_ms") > 0.0);
    }
    assert_eq!(number(&sessions[0], "overlapped"), 0.0);
    assert!(json["peak_gpu_memory_bytes"].as_u64().unwrap() > 0);

    // No deeper than two folders: report/session-K-in-flight/file.
    for entry in std::fs::read_dir(&report).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            for inner in std::fs::read_dir(&path).unwrap() {
                assert!(!inner.unwrap().path().is_dir(), "{path:?} holds a folder");
            }
        }
    }
}
