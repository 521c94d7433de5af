//! `--gaze-trace` as a user runs it: the foveal layer follows the trace's gaze, a malformed
//! trace stops the command with a message naming file, line and column, and a bench run with
//! a trace measures a `trace` mode beside regular, forward and corner.

mod common;

use common::fovea;
use fovea::foveation::{EyeFov, ImageGeometry};
use fovea::render::{eye_views, FovChoice};
use std::path::{Path, PathBuf};

const HEADER: &str = "frame,time_s,left_tan_x,left_tan_y,right_tan_x,right_tan_y,status\n";

fn temp_dir(name: &str) -> common::TestDir {
    common::test_dir(&format!("gaze-{name}"))
}

/// A trace looking left, straight ahead, then right (tangent x -0.3, 0, 0.3), the right eye
/// slightly inward of the left as a near fixation makes it.
fn left_to_right(dir: &Path) -> PathBuf {
    let path = dir.join("gaze.csv");
    let rows: String = [-0.3, 0.0, 0.3]
        .iter()
        .enumerate()
        .map(|(k, x)| format!("{k},{},{x},0,{},0,tracked\n", k as f64 / 90.0, x - 0.02))
        .collect();
    std::fs::write(&path, format!("{HEADER}{rows}")).unwrap();
    path
}

/// Pixels of an RGB8 PNG.
fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// Mean x of the pixels tinted as the innermost layer (resolve.comp's LAYER_COLOURS[0], red:
/// sRGB green and blue about 0.54 of red; the next layer's orange has green at 0.85) in the
/// column range `x0..x1`.
fn foveal_centroid_x(rgb: &[u8], width: u32, x0: u32, x1: u32) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for (i, p) in rgb.chunks_exact(3).enumerate() {
        let x = i as u32 % width;
        let (r, g, b) = (p[0] as u32, p[1] as u32, p[2] as u32);
        if (x0..x1).contains(&x) && r > 40 && 10 * g < 7 * r && 10 * b < 7 * r {
            sum += x as f64;
            n += 1;
        }
    }
    assert!(n > 10, "only {n} foveal pixels");
    sum / n as f64
}

/// The gaze pixel `render` printed for `which` ("eye", "left eye", "right eye").
fn printed_gaze(text: &str, which: &str) -> [f64; 2] {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("{which}: gaze at pixel (")))
        .unwrap_or_else(|| panic!("no gaze line for {which} in:\n{text}"));
    let inner = line.split('(').nth(1).unwrap().split(')').next().unwrap();
    let v: Vec<f64> = inner
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    [v[0], v[1]]
}

#[test]
fn the_foveal_layer_follows_the_trace_from_left_to_right() {
    let dir = temp_dir("render");
    let trace = left_to_right(&dir);
    let (w, h) = (64u32, 48u32);
    let scene = fovea::scene::builtin::builtin("cornell", w as f32 / h as f32).unwrap();
    let eyes = eye_views(
        &scene.camera,
        w as f32 / h as f32,
        FovChoice::Scene,
        true,
        "forward".parse().unwrap(),
    );
    let images: Vec<ImageGeometry> = eyes.iter().map(|e| e.image(w, h)).collect();
    let mut centroids = Vec::new();
    for frame in ["0", "1", "2"] {
        let out = dir.join(format!("layers-{frame}.png"));
        let (ok, text) = fovea(&[
            "render",
            "--scene",
            "cornell",
            "--width",
            "64",
            "--height",
            "48",
            "--foveation",
            "thesis",
            "--spp",
            "1",
            "--stereo",
            "--debug",
            "layers",
            "--gaze-trace",
            trace.to_str().unwrap(),
            "--trace-frame",
            frame,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{text}");
        assert!(
            text.contains(&format!("row {frame} of 3 (tracked)")),
            "{text}"
        );
        // Each eye's gaze is its own tangent column mapped through its own image.
        let x: f64 = [-0.3, 0.0, 0.3][frame.parse::<usize>().unwrap()];
        for (e, (which, tx)) in [("left eye", x), ("right eye", x - 0.02)]
            .iter()
            .enumerate()
        {
            let want = images[e].pixel_of([*tx, 0.0]);
            let got = printed_gaze(&text, which);
            assert!(
                (got[0] - want[0]).abs() < 0.06 && (got[1] - want[1]).abs() < 0.06,
                "{which}: printed {got:?}, expected {want:?}"
            );
        }
        let (width, height, rgb) = read_png(&out);
        assert_eq!((width, height), (2 * w, h));
        centroids.push([
            foveal_centroid_x(&rgb, width, 0, w),
            foveal_centroid_x(&rgb, width, w, 2 * w) - w as f64,
        ]);
    }
    for eye in 0..2 {
        let xs: Vec<f64> = centroids.iter().map(|c| c[eye]).collect();
        // tan 0.3 is about 20 pixels from the axis at this size: the disc moves by that much.
        assert!(
            xs[0] + 10.0 < xs[1] && xs[1] + 10.0 < xs[2],
            "eye {eye}: foveal centroids {xs:?} do not move left to right"
        );
    }
}

#[test]
fn a_malformed_trace_is_refused_with_file_line_and_column() {
    let dir = temp_dir("bad");
    let bad = dir.join("bad.csv");
    std::fs::write(
        &bad,
        format!("{HEADER}0,0,0.1,0.2,0.1,0.2,tracked\n1,0.01,0.1,oops,0,0,tracked\n"),
    )
    .unwrap();
    let render = |extra: &[&str]| {
        let out = dir.join("x.png");
        let mut args = vec![
            "render",
            "--scene",
            "control",
            "--width",
            "16",
            "--height",
            "16",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        fovea(&args)
    };
    let (ok, text) = render(&["--gaze-trace", bad.to_str().unwrap()]);
    assert!(!ok, "{text}");
    assert!(
        text.contains("bad.csv, line 3, column 4 (left_tan_y)") && text.contains("'oops'"),
        "{text}"
    );
    // NaN is only for centre rows.
    std::fs::write(&bad, format!("{HEADER}0,0,NaN,0,0,0,held\n")).unwrap();
    let (ok, text) = render(&["--gaze-trace", bad.to_str().unwrap()]);
    assert!(
        !ok && text.contains("line 2, column 3") && text.contains("status centre"),
        "{text}"
    );
    std::fs::write(&bad, "frame,time,x,y\n").unwrap();
    let (ok, text) = render(&["--gaze-trace", bad.to_str().unwrap()]);
    assert!(!ok && text.contains("the header must be"), "{text}");
    std::fs::write(&bad, "").unwrap();
    let (ok, text) = render(&["--gaze-trace", bad.to_str().unwrap()]);
    assert!(!ok && text.contains("is empty"), "{text}");
    let missing = dir.join("missing.csv");
    let (ok, text) = render(&["--gaze-trace", missing.to_str().unwrap()]);
    assert!(!ok && text.contains("cannot read gaze trace"), "{text}");
    // --gaze and --gaze-trace say different things; --trace-frame needs a trace.
    let good = left_to_right(&dir);
    let (ok, text) = render(&["--gaze", "corner", "--gaze-trace", good.to_str().unwrap()]);
    assert!(!ok && text.contains("cannot be used with"), "{text}");
    let (ok, text) = render(&["--trace-frame", "1"]);
    assert!(!ok && text.contains("--gaze-trace"), "{text}");
    // Timing a trace needs foveated frames to move.
    let (ok, text) = render(&["--bench", "--gaze-trace", good.to_str().unwrap()]);
    assert!(!ok && text.contains("give --foveation"), "{text}");
}

#[test]
fn a_bench_run_with_a_trace_measures_the_trace_mode() {
    let dir = temp_dir("bench");
    let trace = left_to_right(&dir);
    let run = dir.join("run");
    let (ok, text) = fovea(&[
        "bench",
        "--quick",
        "--scenes",
        "control",
        "--frames",
        "4",
        "--repeats",
        "1",
        "--width",
        "40",
        "--height",
        "36",
        "--reference-spp",
        "16",
        "--sweep-spp",
        "1",
        "--sweep-frames",
        "1",
        "--spp",
        "1",
        "--gaze-trace",
        trace.to_str().unwrap(),
        "--dir",
        run.to_str().unwrap(),
        "--reference-cache",
        dir.join("references").to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    assert!(text.contains("impact trace"), "{text}");
    // Four frames for three rows: the last row holds, and the log says so.
    assert!(text.contains("has 3 rows for 4 frames"), "{text}");

    let mut reader = csv::Reader::from_path(run.join("frames.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    let traced: Vec<&csv::StringRecord> =
        rows.iter().filter(|r| &r[col("mode")] == "trace").collect();
    // 4 frames × 1 repeat × 2 eyes; the other modes are all there too.
    assert_eq!(traced.len(), 8);
    assert_eq!(rows.len(), 4 * 8);
    let images = [
        ImageGeometry::new(40, 36, EyeFov::VIVE_PRO_EYE_LEFT),
        ImageGeometry::new(40, 36, EyeFov::VIVE_PRO_EYE_RIGHT),
    ];
    for r in traced {
        let frame: usize = r[col("frame")].parse().unwrap();
        let x = [-0.3, 0.0, 0.3][frame.min(2)];
        let (e, tx) = match &r[col("eye")] {
            "left" => (0, x),
            _ => (1, x - 0.02),
        };
        let want = images[e].pixel_of([tx, 0.0]);
        let got: f64 = r[col("gaze_x")].parse().unwrap();
        assert!(
            (got - want[0]).abs() < 1e-6,
            "{r:?}: gaze_x {got}, want {}",
            want[0]
        );
    }

    let quality = csv::Reader::from_path(run.join("quality.csv"))
        .unwrap()
        .records()
        .filter(|r| &r.as_ref().unwrap()[1] == "trace")
        .count();
    // spp 1 (the sweep and the protocol's), 2 eyes, whole image + 4 bands.
    assert_eq!(quality, 2 * 5);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["complete"], true);
    let modes = &summary["scenes"][0]["modes"];
    assert_eq!(modes[3]["mode"], "trace");
    assert!(modes[3]["impact"]["factor"].as_f64().unwrap() > 0.0);
    assert!(summary["parameters"]["gaze_trace"]
        .as_str()
        .unwrap()
        .ends_with("gaze.csv"));
    let report = std::fs::read_to_string(run.join("report.md")).unwrap();
    assert!(
        report.contains("Mode `trace` follows the gaze trace"),
        "{report}"
    );
}
