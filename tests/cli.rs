//! The `fovea` binary as a user meets it: a real render writes real files; bad input gets a
//! clear message and a non-zero exit, never a panic.

mod common;

use common::fovea;

#[test]
fn render_writes_png_and_exr_and_reports_time_and_counters() {
    let dir = common::test_dir("cli");
    let png = dir.join("bunny.png");
    let (ok, text) = fovea(&[
        "render",
        "--scene",
        "bunny-low",
        "--width",
        "48",
        "--height",
        "32",
        "--spp",
        "2",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    assert!(
        text.contains("gpu pass trace:") && text.contains("Msamples/s"),
        "{text}"
    );
    assert!(
        text.contains("non-finite samples dropped: 0, BVH stack overflows: 0"),
        "{text}"
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let info = decoder.read_info().unwrap().info().clone();
    assert_eq!((info.width, info.height), (48, 32));
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        png.with_extension("exr"),
        |res, _| vec![0f32; res.width() * res.height()],
        |px: &mut Vec<f32>, pos, (r, _g, _b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * 48 + pos.x()] = r
        },
    )
    .unwrap();
    assert!(exr.layer_data.channel_data.pixels.iter().any(|&r| r > 0.0));
}

#[test]
fn the_same_frame_twice_writes_the_same_exr_bytes() {
    // Stereo, so that the file has many chunks: a writer that stores chunks in the order its
    // threads finish them made different files of the same pixels.
    let dir = common::test_dir("cli-exr-bytes");
    let files: Vec<Vec<u8>> = (0..2)
        .map(|i| {
            let out = dir.join(format!("frame{i}.exr"));
            let (ok, text) = fovea(&[
                "render",
                "--scene",
                "mirror-room",
                "--stereo",
                "--width",
                "48",
                "--height",
                "40",
                "--spp",
                "1",
                "--out",
                out.to_str().unwrap(),
            ]);
            assert!(ok, "{text}");
            std::fs::read(&out).unwrap()
        })
        .collect();
    assert!(files[0].len() > 1000, "{} bytes", files[0].len());
    assert!(files[0] == files[1], "the two files differ");
}

#[test]
fn bad_input_gets_a_clear_error_and_nonzero_exit() {
    // A layer config whose inner layer is coarser than the background.
    let dir = common::test_dir("bad-input");
    let bad_layers = dir.join("bad-layers.toml");
    std::fs::write(
        &bad_layers,
        "[[layer]]\nradius_deg = 6.0\nspacing = 4\n[[layer]]\nspacing = 2\n",
    )
    .unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--width", "0", "--out", common::SCRATCH_PNG],
            "out of range",
        ),
        (
            &["render", "--spp", "0", "--out", common::SCRATCH_PNG],
            "--spp 0",
        ),
        (
            &["render", "--height", "100000", "--out", common::SCRATCH_PNG],
            "out of range",
        ),
        (
            &[
                "render",
                "--scene",
                "no-such-scene",
                "--out",
                common::SCRATCH_PNG,
            ],
            "unknown scene 'no-such-scene'",
        ),
        (
            &[
                "render",
                "--scene",
                "/nonexistent/model.glb",
                "--out",
                common::SCRATCH_PNG,
            ],
            "/nonexistent/model.glb",
        ),
        (
            &[
                "render",
                "--scene",
                "control",
                "--width",
                "8",
                "--height",
                "8",
                "--out",
                concat!(env!("CARGO_TARGET_TMPDIR"), "/fovea-scratch.bmp"),
            ],
            ".png or .exr",
        ),
        (
            &[
                "render",
                "--device",
                "no-such-gpu",
                "--out",
                common::SCRATCH_PNG,
            ],
            "no Vulkan device matches",
        ),
        (
            &["render", "--foveation", "/nonexistent/layers.toml"],
            "'thesis'",
        ),
        (&["render", "--gaze", "up"], "forward, corner or X,Y"),
        (&["render", "--gaze", "1,x"], "not a number"),
        (
            &["render", "--foveation", bad_layers.to_str().unwrap()],
            "spacing",
        ),
    ];
    for (args, expected) in cases {
        let (ok, text) = fovea(args);
        assert!(!ok, "fovea {args:?} should fail");
        assert!(
            text.contains(expected),
            "fovea {args:?}: expected '{expected}' in:\n{text}"
        );
    }
}

#[test]
fn foveated_stereo_render_reports_layers_and_writes_both_eyes() {
    let dir = common::test_dir("cli-fov");
    let png = dir.join("layers.png");
    let (ok, text) = fovea(&[
        "render",
        "--scene",
        "bunny-low",
        "--width",
        "40",
        "--height",
        "44",
        "--foveation",
        "thesis",
        "--spp",
        "1",
        "--stereo",
        "--fov",
        "vive-pro-eye",
        "--gaze",
        "10,12:corner",
        "--debug",
        "layers",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    assert!(
        text.contains("left eye: gaze at pixel (10.0, 12.0)"),
        "{text}"
    );
    assert!(
        text.contains("right eye: gaze at pixel (0.5, 0.5)"),
        "{text}"
    );
    assert!(
        text.contains("left trace") && text.contains("right resolve"),
        "{text}"
    );
    assert!(text.contains("samples traced:"), "{text}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let info = decoder.read_info().unwrap().info().clone();
    assert_eq!((info.width, info.height), (80, 44));

    let (ok, text) = fovea(&[
        "render",
        "--scene",
        "control",
        "--width",
        "48",
        "--height",
        "48",
        "--foveation",
        "thesis",
        "--debug",
        "diff",
        "--out",
        dir.join("diff.png").to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    let identical: f64 = text
        .split("% of pixels identical")
        .next()
        .and_then(|t| t.rsplit(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no identical-pixel share in:\n{text}"));
    // The fovea is identical to the regular frame, the periphery is not.
    assert!(identical > 0.5 && identical < 100.0, "{text}");
}

#[test]
fn a_fractional_layer_is_reported_with_its_share_and_the_points_filled() {
    let dir = common::test_dir("cli-fraction");
    let toml = dir.join("half.toml");
    std::fs::write(&toml, "[[layer]]\nspacing = 1\nspp = 2\nfraction = 2\n").unwrap();
    let (ok, text) = fovea(&[
        "render",
        "--width",
        "32",
        "--height",
        "24",
        "--foveation",
        toml.to_str().unwrap(),
        "--out",
        dir.join("half.png").to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    assert!(text.contains("per frame") && text.contains("1/2"), "{text}");
    // A checkerboard of 32x24: half the pixels, but column 0's skipped ones (no left
    // neighbour to fill them from) are traced.
    let filled = 32 * 24 / 2 - 24 / 2;
    let line = format!("lattice points filled from their traced neighbours: {filled}");
    assert!(text.contains(&line), "{text}");
    assert!(text.contains("gpu pass lattice fill"), "{text}");
}

/// `render --bench --json` writes what the table shows: a record per built-in scene, mode and
/// traversal (`--traversal auto` measures both where the device has ray queries, as lavapipe
/// does) with the medians, the same GPU ms the table prints (to its 0.1 ms), the regular
/// frame's samples equal to its pixels × spp, and the trace part of each frame's time.
#[test]
fn render_bench_json_holds_the_table() {
    let dir = common::test_dir("cli-json");
    let json_path = dir.join("bench.json");
    let (ok, text) = fovea(&[
        "render",
        "--bench",
        "--width",
        "16",
        "--height",
        "12",
        "--spp",
        "2",
        "--bench-frames",
        "1",
        "--foveation",
        "thesis",
        "--json",
        json_path.to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let records = json["records"].as_array().unwrap();
    let scenes = fovea::scene::builtin::BUILTIN_SCENES;
    let traversals = ["software", "rayquery"];
    assert_eq!(
        records.len(),
        scenes.len() * 3 * traversals.len(),
        "{json:#}"
    );
    for ((name, _), traversal) in scenes.iter().flat_map(|s| traversals.map(|t| (s, t))) {
        // The table's row: scene, traversal, then regular, forward and corner GPU ms.
        let row: Vec<&str> = text
            .lines()
            .map(|l| l.split_whitespace().collect::<Vec<_>>())
            .find(|w| w.len() > 2 && w[0] == *name && w[1] == traversal)
            .unwrap_or_else(|| panic!("no table row for {name} {traversal}:\n{text}"));
        for (column, mode) in ["regular", "forward", "corner"].iter().enumerate() {
            let r = records
                .iter()
                .find(|r| r["scene"] == *name && r["mode"] == *mode && r["traversal"] == traversal)
                .unwrap_or_else(|| panic!("no record for {name} {mode} {traversal}: {json:#}"));
            let gpu_ms = r["gpu_ms"].as_f64().unwrap();
            let trace_ms = r["trace_ms"].as_f64().unwrap();
            let printed: f64 = row[2 + column].parse().unwrap();
            assert!(
                (gpu_ms - printed).abs() <= 0.05 + 1e-9,
                "{name} {mode}: {gpu_ms} vs {printed}"
            );
            assert!(trace_ms > 0.0 && trace_ms <= gpu_ms, "{name} {mode}: {r}");
            if *mode == "regular" {
                assert_eq!(r["samples"].as_f64().unwrap(), (16 * 12 * 2) as f64, "{r}");
            }
        }
    }
    assert_eq!(json["width"], 16);
    assert_eq!(json["spp"], 2);
}

/// `--traversal` picks what traces the frame, and says so; the traversal profile counts the
/// software traversal's work, so asking it of ray queries is refused with a message.
#[test]
fn traversal_flag_picks_the_traversal_and_the_profile_needs_software() {
    let dir = common::test_dir("cli-traversal");
    let out = dir.join("t.png");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--scene",
            "cubes-441",
            "--width",
            "16",
            "--height",
            "16",
        ];
        args.extend(["--spp", "1", "--out", out.to_str().unwrap()]);
        args.extend(extra);
        fovea(&args)
    };
    for (flag, printed) in [
        ("software", "software traversal"),
        ("rayquery", "rayquery traversal"),
        // lavapipe is a CPU driver: auto keeps the software traversal there.
        ("auto", "software traversal"),
    ] {
        let (ok, text) = render(&["--traversal", flag]);
        assert!(ok && text.contains(printed), "--traversal {flag}: {text}");
    }
    let (ok, text) = render(&["--traversal", "rayquery", "--profile-traversal"]);
    assert!(!ok && text.contains("use --traversal software"), "{text}");
    let (ok, text) = render(&["--traversal", "sideways"]);
    assert!(!ok && text.contains("software"), "{text}");
}

#[test]
fn a_camera_path_renders_one_frame_per_row_and_bad_paths_say_what_is_wrong() {
    let dir = common::test_dir("cli-path");
    let path = dir.join("path.csv");
    let header = "frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n";
    std::fs::write(
        &path,
        format!("{header}0,0,0,0,0,0,0\n1,0.05,0,0,2,0,0\n2,0.1,0,0,4,1,0\n"),
    )
    .unwrap();
    let out = dir.join("frames");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--scene",
            "cornell",
            "--width",
            "24",
            "--height",
            "24",
            "--foveation",
            "thesis",
        ];
        args.extend_from_slice(extra);
        fovea(&args)
    };
    let (ok, text) = render(&[
        "--camera-path",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{text}");
    assert!(
        text.contains("3 frames") && text.contains("temporal history on"),
        "{text}"
    );
    for k in 0..3 {
        for ext in ["png", "exr"] {
            let file = out.join(format!("frame_{k:04}.{ext}"));
            assert!(file.is_file(), "{} missing:\n{text}", file.display());
        }
    }
    assert!(!out.join("frame_0003.png").exists());
    assert!(!text.contains("gpu pass"), "{text}");
    // --pass-times: every frame's passes after its line, history's among them.
    let (ok, text) = render(&[
        "--camera-path",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--pass-times",
    ]);
    assert!(ok, "{text}");
    for pass in ["gpu pass trace:", "gpu pass resolve:", "gpu pass temporal:"] {
        assert_eq!(text.matches(pass).count(), 3, "{pass}\n{text}");
    }
    let (ok, text) = render(&[
        "--camera-path",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--temporal",
        "off",
    ]);
    assert!(ok && text.contains("temporal history off"), "{text}");

    // Bad input: a row out of order, an image name for the directory, history without a path.
    std::fs::write(&path, format!("{header}0,0,0,0,0,0,0\n2,0,0,0,0,0,0\n")).unwrap();
    let (ok, text) = render(&[
        "--camera-path",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && text.contains("line 3: frame '2' where 1 was expected"),
        "{text}"
    );
    std::fs::write(&path, format!("{header}0,0,0,0,0,0,0\n")).unwrap();
    let (ok, text) = render(&["--camera-path", path.to_str().unwrap(), "--out", "x.png"]);
    assert!(!ok && text.contains("give a directory"), "{text}");
    let (ok, text) = render(&["--temporal", "on"]);
    assert!(!ok && text.contains("--camera-path"), "{text}");
}
