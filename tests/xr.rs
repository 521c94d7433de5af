//! The XR path end to end through the simulated headset (tools/sim-headset), on lavapipe with
//! the validation layer on: `fovea xr` sessions in-process (`--simulated`) and through the
//! Khronos loader (`XR_RUNTIME_JSON`), the runtime saving each eye's submitted image and
//! writing a report of what the application left alive.

mod common;

use common::fovea_with_env;
use fovea::foveation::{EyeFov, ImageGeometry};
use fovea::scene::cpu_raycast::CpuRaycaster;
use glam::Vec3;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> common::TestDir {
    common::test_dir(&format!("xr-{name}"))
}

/// Runs `fovea xr` on the simulated headset with `env` (SIM_HEADSET_*), its images saved and
/// its report written under `dir`.
fn xr(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> (bool, String) {
    let session = dir.join("session");
    let mut all_args = vec!["xr", "--session", session.to_str().unwrap()];
    all_args.extend_from_slice(args);
    fovea_saving_under(dir, &all_args, env)
}

/// Runs `fovea ARGS` with `env`, the simulated headset saving the eye images it is handed
/// under `dir/images` and writing its report to `dir/report.json`.
fn fovea_saving_under(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> (bool, String) {
    let images = dir.join("images");
    let report = dir.join("report.json");
    let mut all_env = vec![
        ("SIM_HEADSET_SAVE_DIR", images.to_str().unwrap()),
        ("SIM_HEADSET_REPORT", report.to_str().unwrap()),
    ];
    all_env.extend_from_slice(env);
    fovea_with_env(args, &all_env)
}

fn report(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("report.json")).expect("the runtime's report");
    serde_json::from_str(&text).unwrap()
}

/// Nothing the application created was left for xrDestroyInstance to clean up.
fn assert_clean_teardown(dir: &Path) {
    let r = report(dir);
    assert_eq!(r["clean_teardown"], true, "{r:#}");
    for (kind, n) in r["alive_at_instance_destroy"].as_object().unwrap() {
        assert_eq!(n, 0, "{kind} left alive: {r:#}");
    }
    for (kind, n) in r["vulkan_alive_at_instance_destroy"].as_object().unwrap() {
        assert_eq!(n, 0, "Vulkan {kind} left alive: {r:#}");
    }
}

/// RGBA8 pixels of a PNG.
fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let rgba = buf[..info.buffer_size()]
        .chunks_exact(channels)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    (info.width, info.height, rgba)
}

fn last_image(dir: &Path, eye: u32) -> PathBuf {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir.join("images"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_str().unwrap().ends_with(&format!("-eye-{eye}.png")))
        .collect();
    names.sort();
    names.pop().expect("saved eye images")
}

/// Centroid of the foveal layer's overlay colour (red, `--debug layers`) in an eye image.
fn foveal_centroid(path: &Path) -> [f64; 2] {
    let (w, _, rgba) = read_png(path);
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for (i, p) in rgba.chunks_exact(4).enumerate() {
        let (r, g, b) = (p[0] as f64, p[1] as f64, p[2] as f64);
        if r > 40.0 && r > 1.6 * g && r > 1.6 * b {
            sx += (i as u32 % w) as f64 + 0.5;
            sy += (i as u32 / w) as f64 + 0.5;
            n += 1.0;
        }
    }
    assert!(n > 20.0, "{}: only {n} foveal pixels", path.display());
    [sx / n, sy / n]
}

fn gaze_statuses(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("session/gaze.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().to_string())
        .collect()
}

#[test]
fn a_ten_frame_session_exits_cleanly_and_both_eyes_show_the_scene() {
    let dir = scratch("ten");
    let (ok, out) = xr(
        &dir,
        &[
            "--simulated",
            "--frames",
            "10",
            "--scene",
            "cornell",
            "--foveation",
            "off",
            "--spp",
            "4",
            // One frame's own samples, as `fovea render` renders them (the default history
            // would show the mean of all ten frames).
            "--temporal",
            "off",
        ],
        &[("SIM_HEADSET_SIZE", "48x48")],
    );
    assert!(ok, "{out}");
    assert!(out.contains("10 frames"), "{out}");
    assert!(
        out.contains("FOCUSED") && out.contains("STOPPING → IDLE → EXITING"),
        "{out}"
    );
    assert_clean_teardown(&dir);
    assert_eq!(report(&dir)["images_saved"].as_u64(), Some(20));
    // Each eye shows what `fovea render` renders for that eye (same camera, field of view,
    // seed and samples): the session's last frame (index 9) used seed 1 + 9. Compared
    // inside the lens's visible area; the rest is never traced.
    let render_png = dir.join("render.png");
    let (ok, out) = common::fovea(&[
        "render",
        "--scene",
        "cornell",
        "--width",
        "48",
        "--height",
        "48",
        "--stereo",
        "--fov",
        "vive-pro-eye",
        "--foveation",
        "off",
        "--spp",
        "4",
        "--seed",
        "10",
        "--out",
        render_png.to_str().unwrap(),
    ]);
    assert!(ok, "{out}");
    let (rw, _, rendered) = read_png(&render_png);
    assert_eq!(rw, 96);
    for eye in 0..2u32 {
        let (w, h, rgba) = read_png(&last_image(&dir, eye));
        assert_eq!((w, h), (48, 48));
        let (mut worst, mut lit) = (0i32, 0);
        for y in 12..36u32 {
            for x in 12..36u32 {
                let a = &rgba[((y * 48 + x) * 4) as usize..][..3];
                let b = &rendered[((y * 96 + eye * 48 + x) * 4) as usize..][..3];
                for c in 0..3 {
                    worst = worst.max((a[c] as i32 - b[c] as i32).abs());
                }
                lit += (a.iter().map(|v| *v as u32).sum::<u32>() > 60) as u32;
            }
        }
        // sRGB encoding by the blit (hardware) and by the PNG writer may round apart by one.
        assert!(
            worst <= 1,
            "eye {eye}: differs from fovea render by up to {worst}/255"
        );
        assert!(lit > 100, "eye {eye}: only {lit} of 576 central pixels lit");
    }
    // The session profile has the bench's columns for both eyes of every frame.
    let frames = std::fs::read_to_string(dir.join("session/frames.csv")).unwrap();
    assert!(frames.starts_with("scene,mode,repeat,frame,eye,gpu_plan_ms,trace_ms,resolve_ms"));
    assert_eq!(frames.lines().count(), 1 + 2 * 10);
    assert!(frames
        .lines()
        .nth(1)
        .unwrap()
        .starts_with("cornell,regular,0,0,left,"));
    let session: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("session/session.json")).unwrap())
            .unwrap();
    assert_eq!(session["statistics"]["frames"], 10);
    // Every frame's timing: the gaze latched before the GPU finished, display times one
    // period apart (the simulated headset's 90 Hz), none missed.
    let latency = &session["latency"];
    assert_eq!(latency["frames"], 10, "{latency}");
    assert_eq!(latency["missed_frames"], 0, "{latency}");
    let period = latency["frame_period_ms"]["median"].as_f64().unwrap();
    assert!((period - 1000.0 / 90.0).abs() < 1e-3, "{latency}");
    let header: Vec<&str> = frames.lines().next().unwrap().split(',').collect();
    let column = |row: &str, name: &str| -> String {
        let at = header.iter().position(|h| *h == name).unwrap();
        row.split(',').nth(at).unwrap().to_string()
    };
    for row in frames.lines().skip(1) {
        let latch: f64 = column(row, "latch_ms").parse().unwrap();
        let done: f64 = column(row, "gpu_done_ms").parse().unwrap();
        assert!(latch >= 0.0 && latch < done, "{row}");
        // Empty while the session is not focused yet (no gaze sample); after, the tracker's
        // sample is older than the display time by at least a period.
        let frame: u32 = column(row, "frame").parse().unwrap();
        let photon = column(row, "gaze_to_photon_ms");
        if frame >= 2 || !photon.is_empty() {
            let photon: f64 = photon.parse().unwrap();
            assert!(photon >= 1000.0 / 90.0 - 1e-3, "{row}");
        }
    }
}

/// Where the projection maths puts the fixation of a gaze `yaw` right and `pitch` up (degrees)
/// from the head at the scene camera, in each eye (±IPD/2 along the camera's right, with the
/// Vive Pro Eye's fields of view at `size`): written out here, independently of
/// foveation::fixation.
fn expected_gaze_pixels(scene: &str, yaw: f32, pitch: f32, size: u32) -> [[f64; 2]; 2] {
    let scene = fovea::scene::load(scene, 1.0).unwrap();
    let c = scene.camera;
    let (right, up, forward) = c.basis();
    let (yaw, pitch) = (yaw.to_radians(), pitch.to_radians());
    let dir = (right * (pitch.cos() * yaw.sin())
        + up * pitch.sin()
        + forward * (pitch.cos() * yaw.cos()))
    .normalize();
    let t = CpuRaycaster::new(&scene)
        .closest_hit(c.position, dir)
        .expect("the gaze hits the scene");
    let p = c.position + dir * t;
    let eye = |side: f32, fov: EyeFov| {
        let e = c.position + right * (side * 0.0315);
        let v: Vec3 = p - e;
        let depth = v.dot(forward) as f64;
        let tan = [v.dot(right) as f64 / depth, v.dot(up) as f64 / depth];
        ImageGeometry::new(size, size, fov).pixel_of(tan)
    };
    [
        eye(-1.0, EyeFov::VIVE_PRO_EYE_LEFT),
        eye(1.0, EyeFov::VIVE_PRO_EYE_RIGHT),
    ]
}

#[test]
fn a_scripted_gaze_centres_each_eyes_fovea_where_the_projection_says() {
    let dir = scratch("gaze");
    let size = 256;
    let (ok, out) = xr(
        &dir,
        &[
            "--simulated",
            "--frames",
            "3",
            "--scene",
            "cornell",
            // The thesis' 6-degree fovea, tinted, is small enough to locate by its centroid
            // (the shipped config's 20-degree one reaches past this image's edges).
            "--foveation",
            "thesis",
            "--debug",
            "layers",
        ],
        &[
            ("SIM_HEADSET_SIZE", "256x256"),
            ("SIM_HEADSET_GAZE", "0 12 -6 valid"),
        ],
    );
    assert!(ok, "{out}");
    let expected = expected_gaze_pixels("cornell", 12.0, -6.0, size);
    let measured = [
        foveal_centroid(&last_image(&dir, 0)),
        foveal_centroid(&last_image(&dir, 1)),
    ];
    for e in 0..2 {
        for a in 0..2 {
            assert!(
                (measured[e][a] - expected[e][a]).abs() < 1.0,
                "eye {e}: fovea centred at {:?}, projection says {:?}",
                measured[e],
                expected[e]
            );
        }
    }
    // Parallax: the eyes see the fixation at different pixels; the difference matches.
    let expected_parallax = expected[0][0] - expected[1][0];
    let measured_parallax = measured[0][0] - measured[1][0];
    assert!(expected_parallax.abs() > 2.0, "{expected_parallax}");
    assert!(
        (measured_parallax - expected_parallax).abs() < 1.0,
        "parallax {measured_parallax} px, expected {expected_parallax} px"
    );
    assert!(gaze_statuses(&dir).contains(&"tracked".to_string()));
}

#[test]
fn without_eye_gaze_the_session_runs_with_centre_foveation_and_says_why() {
    for (setting, says) in [
        ("off", "does not offer XR_EXT_eye_gaze_interaction"),
        ("unsupported", "supportsEyeGazeInteraction is false"),
        ("inactive", "eye gaze action is not active"),
    ] {
        let dir = scratch(&format!("nogaze-{setting}"));
        let (ok, out) = xr(
            &dir,
            &["--simulated", "--frames", "4"],
            &[
                ("SIM_HEADSET_SIZE", "32x32"),
                ("SIM_HEADSET_EYE_GAZE", setting),
                ("SIM_HEADSET_GAZE", "0 20 10 valid"),
            ],
        );
        assert!(ok, "{setting}: {out}");
        assert_eq!(out.matches(says).count(), 1, "{setting}: {out}");
        let statuses = gaze_statuses(&dir);
        assert_eq!(statuses.len(), 4);
        assert!(
            statuses.iter().all(|s| s == "centre"),
            "{setting}: {statuses:?}"
        );
        assert_clean_teardown(&dir);
    }
}

#[test]
fn invalid_samples_hold_the_last_gaze_then_fall_back_to_the_centre() {
    let dir = scratch("invalid");
    // Frames are 1/90 s apart; a 0.025 s hold covers two frames after the last good sample.
    let (ok, out) = xr(
        &dir,
        &["--simulated", "--frames", "9", "--gaze-hold", "0.025"],
        &[
            ("SIM_HEADSET_SIZE", "32x32"),
            (
                "SIM_HEADSET_GAZE",
                "0 5 0 valid; 4 0 0 invalid; 7 0 0 untracked",
            ),
        ],
    );
    assert!(ok, "{out}");
    let statuses = gaze_statuses(&dir);
    let tracked = statuses
        .iter()
        .position(|s| s == "tracked")
        .expect("tracked");
    // Frame k shows script frame k+1 or k (the runtime counts its own frames); find the
    // invalid stretch by its statuses instead of assuming the offset.
    let after: Vec<&str> = statuses[tracked..]
        .iter()
        .map(String::as_str)
        .skip_while(|s| *s == "tracked")
        .collect();
    assert!(after.len() >= 4, "{statuses:?}");
    assert_eq!(&after[..2], ["held", "held"], "{statuses:?}");
    assert!(after[2..].iter().all(|s| *s == "centre"), "{statuses:?}");
    assert!(out.contains("holding the last good gaze"), "{out}");
    assert!(out.contains("foveating around the view axis"), "{out}");
}

#[test]
fn the_runtime_ending_the_session_tears_down_cleanly() {
    let dir = scratch("exit");
    // No --frames: the runtime asks to stop at its frame 5, as a user quitting would.
    let (ok, out) = xr(
        &dir,
        &["--simulated"],
        &[
            ("SIM_HEADSET_SIZE", "32x32"),
            ("SIM_HEADSET_EXIT_AT_FRAME", "5"),
        ],
    );
    assert!(ok, "{out}");
    assert!(out.contains("STOPPING → IDLE → EXITING"), "{out}");
    assert_clean_teardown(&dir);
}

#[test]
fn a_lost_session_tears_down_cleanly_and_keeps_what_it_recorded() {
    let dir = scratch("loss");
    let (ok, out) = xr(
        &dir,
        &["--simulated", "--frames", "50"],
        &[
            ("SIM_HEADSET_SIZE", "32x32"),
            ("SIM_HEADSET_LOSS_AT_FRAME", "4"),
        ],
    );
    assert!(!ok, "a lost session must not exit 0: {out}");
    assert!(out.contains("session was lost"), "{out}");
    assert!(!out.contains("validation layer reported"), "{out}");
    assert_clean_teardown(&dir);
    let frames = std::fs::read_to_string(dir.join("session/frames.csv")).unwrap();
    let rows = frames.lines().count() - 1;
    assert!((4..50).contains(&rows), "{rows} rows:\n{frames}");
    // Every session is lost at its frame 4: fovea started new ones, a bounded number of
    // times, then gave up with the message.
    assert_eq!(report(&dir)["sessions_lost"], 4, "{out}");
    assert!(
        out.contains("(3 of 3)") && out.contains("in 4 session(s)"),
        "{out}"
    );
}

#[test]
fn after_a_lost_session_a_new_one_renders_the_remaining_frames() {
    let dir = scratch("recover");
    let (ok, out) = xr(
        &dir,
        &["--simulated", "--frames", "8", "--scene", "control"],
        &[
            ("SIM_HEADSET_SIZE", "24x24"),
            ("SIM_HEADSET_LOSS_AT_FRAME", "4"),
            ("SIM_HEADSET_LOSSES", "1"),
        ],
    );
    assert!(ok, "{out}");
    assert!(
        out.contains("starting a new one in 500 ms (1 of 3)"),
        "{out}"
    );
    assert_clean_teardown(&dir);
    let r = report(&dir);
    assert_eq!(r["sessions_lost"], 1, "{r:#}");
    assert_eq!(r["frames_with_layers"], 8, "{r:#}");
    // The second session starts over: IDLE, READY ... after the first one's LOSS_PENDING.
    let states: Vec<&str> = r["session_states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    let lost = states
        .iter()
        .position(|s| s.contains("LOSS_PENDING"))
        .unwrap();
    assert!(
        states[lost..].iter().any(|s| s.contains("FOCUSED")),
        "{states:?}"
    );
    // One session profile for both: frames 0..8 in order, session.json complete.
    let frames = left_column(&dir, "frame");
    let expected: Vec<String> = (0..8).map(|f| f.to_string()).collect();
    assert_eq!(frames, expected);
    let session: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("session/session.json")).unwrap())
            .unwrap();
    assert_eq!(session["sessions"], 2);
    assert_eq!(session["statistics"]["frames"], 8);
    assert_eq!(session["end"], "Requested");
}

/// The simulated headset built as a shared library by this `cargo test` (as a dependency of
/// fovea, cargo builds every crate type it declares).
fn runtime_library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let candidates = [
        deps.join("libsim_headset.so"),
        deps.parent().unwrap().join("libsim_headset.so"),
    ];
    candidates
        .iter()
        .find(|p| p.exists())
        .unwrap_or_else(|| panic!("libsim_headset.so not built: looked at {candidates:?}"))
        .clone()
}

#[test]
fn the_khronos_loader_finds_the_simulated_headset_through_xr_runtime_json() {
    let dir = scratch("loader");
    let manifest = manifest(&dir);
    let (ok, out) = xr(
        &dir,
        &["--frames", "3"],
        &[
            ("XR_RUNTIME_JSON", manifest.to_str().unwrap()),
            ("SIM_HEADSET_SIZE", "32x32"),
        ],
    );
    assert!(ok, "{out}");
    assert!(out.contains("fovea simulated headset"), "{out}");
    assert!(out.contains("3 frames"), "{out}");
    assert_clean_teardown(&dir);
}

#[test]
fn without_a_runtime_the_error_says_what_to_do() {
    let dir = scratch("noruntime");
    let (ok, out) = xr(
        &dir,
        &["--frames", "1"],
        &[(
            "XR_RUNTIME_JSON",
            dir.join("missing.json").to_str().unwrap(),
        )],
    );
    assert!(!ok);
    assert!(
        out.contains("XR_RUNTIME_JSON") && out.contains("--simulated"),
        "{out}"
    );
}

/// Paths traced by the left eye in the session's first frame (frames.csv).
fn left_eye_paths(dir: &Path) -> u64 {
    let text = std::fs::read_to_string(dir.join("session/frames.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|c| *c == "paths").unwrap();
    text.lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(col)
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn pixels_the_lens_hides_are_never_traced() {
    let run = |name: &str, extra: &[&str]| {
        let dir = scratch(name);
        // The background-only scene: its sky lights every pixel the lens does not hide.
        let mut args = vec![
            "--simulated",
            "--frames",
            "1",
            "--foveation",
            "off",
            "--spp",
            "1",
            "--scene",
            "control",
        ];
        args.extend_from_slice(extra);
        let (ok, out) = xr(&dir, &args, &[("SIM_HEADSET_SIZE", "64x64")]);
        assert!(ok, "{out}");
        let (_, _, rgba) = read_png(&last_image(&dir, 0));
        (left_eye_paths(&dir), out, rgba)
    };
    let (open, out_open, open_image) = run("mask-off", &["--no-visibility-mask"]);
    let (masked, out_masked, masked_image) = run("mask-on", &[]);
    assert!(out_open.contains("visibility mask: not used"), "{out_open}");
    assert!(out_masked.contains("visibility mask: used"), "{out_masked}");
    // Regular rendering traces one path per pixel: every pixel without the mask, and only
    // those the simulated lens shows with it (an ellipse reaching 0.92 of each half-extent
    // in tangent space: about π/4 · 0.92² = 66% of the image).
    assert_eq!(open, 64 * 64);
    let fraction = masked as f64 / open as f64;
    assert!(
        (0.62..0.71).contains(&fraction),
        "{masked} of {open} traced"
    );
    // The hidden corners are black (not stale data); the centre is the same image.
    let pixel = |image: &[u8], x: usize, y: usize| image[(y * 64 + x) * 4..][..3].to_vec();
    for (x, y) in [(0, 0), (63, 0), (0, 63), (63, 63)] {
        assert_eq!(pixel(&masked_image, x, y), [0, 0, 0], "corner {x},{y}");
        assert_ne!(
            pixel(&open_image, x, y),
            [0, 0, 0],
            "corner {x},{y} unmasked"
        );
    }
    assert_eq!(pixel(&masked_image, 32, 40), pixel(&open_image, 32, 40));
}

#[test]
fn a_recorded_gaze_trace_replays_in_render() {
    let dir = scratch("record");
    let trace = dir.join("gaze.csv");
    let (ok, out) = xr(
        &dir,
        &[
            "--simulated",
            "--frames",
            "4",
            "--foveation",
            "thesis",
            "--debug",
            "layers",
            "--record-gaze",
            trace.to_str().unwrap(),
        ],
        &[
            ("SIM_HEADSET_SIZE", "128x128"),
            ("SIM_HEADSET_GAZE", "0 -15 8 valid"),
        ],
    );
    assert!(ok, "{out}");
    let rows = std::fs::read_to_string(&trace).unwrap();
    assert_eq!(rows.lines().count(), 1 + 4, "{rows}");
    assert!(rows.lines().last().unwrap().ends_with(",tracked"), "{rows}");
    // The same eyes (the scene camera, IPD apart, Vive Pro Eye fields of view), foveated
    // around the trace's last row: each eye's fovea lands where it did in the headset.
    let replay = dir.join("replay.png");
    let (ok, out) = common::fovea(&[
        "render",
        "--scene",
        "cornell",
        "--width",
        "128",
        "--height",
        "128",
        "--stereo",
        "--fov",
        "vive-pro-eye",
        "--foveation",
        "thesis",
        "--debug",
        "layers",
        "--gaze-trace",
        trace.to_str().unwrap(),
        "--trace-frame",
        "3",
        "--out",
        replay.to_str().unwrap(),
    ]);
    assert!(ok, "{out}");
    let (w, h, rgba) = read_png(&replay);
    for eye in 0..2u32 {
        let half: Vec<u8> = (0..h)
            .flat_map(|y| {
                let start = ((y * w + eye * 128) * 4) as usize;
                rgba[start..start + 128 * 4].to_vec()
            })
            .collect();
        let path = dir.join(format!("replay-eye-{eye}.png"));
        let file = std::fs::File::create(&path).unwrap();
        let mut encoder = png::Encoder::new(file, 128, h);
        encoder.set_color(png::ColorType::Rgba);
        encoder
            .write_header()
            .unwrap()
            .write_image_data(&half)
            .unwrap();
        let replayed = foveal_centroid(&path);
        let live = foveal_centroid(&last_image(&dir, eye));
        for a in 0..2 {
            assert!(
                (replayed[a] - live[a]).abs() < 0.5,
                "eye {eye}: replayed fovea at {replayed:?}, in the headset at {live:?}"
            );
        }
    }
}

/// A runtime manifest in `dir` naming the simulated headset's shared library.
fn manifest(dir: &Path) -> PathBuf {
    let path = dir.join("runtime.json");
    let json = serde_json::json!({
        "file_format_version": "1.0.0",
        "runtime": {
            "name": "fovea simulated headset",
            "library_path": runtime_library().to_str().unwrap(),
        }
    });
    std::fs::write(&path, json.to_string()).unwrap();
    path
}

#[test]
fn khronos_hello_xr_runs_on_the_simulated_headset() {
    use std::process::{Command, Stdio};
    let dir = scratch("hello");
    let report_path = dir.join("report.json");
    let images = dir.join("images");
    // hello_xr quits when its standard input ends: keep a pipe open until it exits (the
    // simulated headset ends the session at its frame 20, as a user quitting would).
    let mut child = Command::new("hello_xr")
        .args(["-g", "Vulkan2"])
        .env("XR_RUNTIME_JSON", manifest(&dir))
        .env("SIM_HEADSET_SIZE", "48x48")
        .env("SIM_HEADSET_EXIT_AT_FRAME", "20")
        .env("SIM_HEADSET_REPORT", &report_path)
        .env("SIM_HEADSET_SAVE_DIR", &images)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hello_xr (tools/setup.sh installs libopenxr-utils)");
    let stdin = child.stdin.take();
    let out = child.wait_with_output().unwrap();
    drop(stdin);
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    let r = report(&dir);
    assert_eq!(r["error_count"], 0, "{r:#}");
    let states: Vec<&str> = r["session_states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert_eq!(states.last(), Some(&"EXITING"), "{states:?}");
    let saved = r["images_saved"].as_u64().unwrap();
    assert!(saved >= 2 * 18, "{r:#}");
    // hello_xr draws coloured cubes on a cleared background: more than one colour per eye.
    let (_, _, rgba) = read_png(&last_image(&dir, 0));
    let mut colours: Vec<&[u8]> = rgba.chunks_exact(4).collect();
    colours.sort();
    colours.dedup();
    assert!(colours.len() > 2, "{} colours", colours.len());
}

#[test]
fn fovea_passes_the_openxr_core_validation_layer() {
    let dir = scratch("core-validation");
    let manifest = manifest(&dir);
    let (ok, out) = xr(
        &dir,
        &["--frames", "4", "--debug", "layers"],
        &[
            ("XR_RUNTIME_JSON", manifest.to_str().unwrap()),
            ("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation"),
            ("SIM_HEADSET_SIZE", "32x32"),
            ("SIM_HEADSET_GAZE", "0 5 5 valid; 2 0 0 invalid"),
        ],
    );
    assert!(ok, "{out}");
    // The layer announces itself; any finding it reports names a VUID.
    assert!(
        out.contains("Core Validation"),
        "the layer did not load:\n{out}"
    );
    assert!(
        !out.contains("VUID") && !out.contains("VALID_ERROR"),
        "{out}"
    );
    assert_clean_teardown(&dir);
}

#[test]
fn bad_xr_options_are_refused_with_what_to_give() {
    for (args, says) in [
        (&["--size", "abc"][..], "give WIDTHxHEIGHT"),
        (&["--size", "0x5"][..], "each side must be from 1"),
        (
            &["--gaze-hold", "-1"][..],
            "give a number of seconds, 0 or more",
        ),
        (
            &["--gaze-hold", "NaN"][..],
            "give a number of seconds, 0 or more",
        ),
        (&["--frames", "0"][..], "give 1 or more"),
        (
            &["--max-bounces", "1000"][..],
            "--max-bounces 1000 is out of range",
        ),
        (&["--spp", "0"][..], "--spp 0 is out of range"),
        (
            &["--device", "llvmpipe"][..],
            "the OpenXR runtime picks the GPU",
        ),
    ] {
        let mut all = vec!["xr", "--simulated"];
        all.extend_from_slice(args);
        let (ok, out) = common::fovea(&all);
        assert!(!ok, "{args:?} was accepted:\n{out}");
        assert!(out.contains(says), "{args:?}:\n{out}");
    }
}

/// `fovea xr --probe` on the simulated headset with `env`; its report and any submitted
/// image go under `dir`.
fn probe(dir: &Path, env: &[(&str, &str)]) -> (bool, String) {
    fovea_saving_under(dir, &["xr", "--probe", "--simulated"], env)
}

/// The probe says, in each eye-gaze mode of the simulated headset, whether gaze is offered,
/// supported and delivered; it names the runtime, the extensions, the view sizes, the
/// formats and the device, submits no image and tears down cleanly.
#[test]
fn the_probe_reports_the_set_up_in_each_eye_gaze_mode_and_renders_nothing() {
    for (setting, says) in [
        (
            "on",
            "eye gaze:          delivered: the gaze action was active in",
        ),
        ("off", "eye gaze:          not offered"),
        ("unsupported", "eye gaze:          not supported"),
        (
            "inactive",
            "eye gaze:          offered and supported, but not delivered",
        ),
    ] {
        let dir = scratch(&format!("probe-{setting}"));
        let (ok, out) = probe(
            &dir,
            &[
                ("SIM_HEADSET_SIZE", "96x80"),
                ("SIM_HEADSET_EYE_GAZE", setting),
            ],
        );
        assert!(ok, "{setting}: {out}");
        assert!(out.contains(says), "{setting}: {out}");
        for fact in [
            "OpenXR runtime:    fovea simulated headset",
            "XR_KHR_vulkan_enable2            offered (required)",
            "eye 0: recommended 96x80",
            "eye 1: recommended 96x80",
            "swapchain formats: ",
            "Vulkan device:     ",
            "probed over 30 empty frames",
        ] {
            assert!(out.contains(fact), "{setting}: no '{fact}' in:\n{out}");
        }
        let gaze_line = |name: &str| format!("{name:<32} ");
        let offered = out.contains(&format!(
            "{}offered",
            gaze_line("XR_EXT_eye_gaze_interaction")
        ));
        assert_eq!(offered, setting != "off", "{setting}: {out}");
        let saved = std::fs::read_dir(dir.join("images")).map_or(0, |d| d.count());
        assert_eq!(saved, 0, "{setting}: the probe submitted images");
        assert_clean_teardown(&dir);
    }
}

#[test]
fn the_probe_without_a_runtime_says_what_to_do() {
    let dir = scratch("probe-noruntime");
    let missing = dir.join("missing.json");
    let (ok, out) = fovea_with_env(
        &["xr", "--probe"],
        &[("XR_RUNTIME_JSON", missing.to_str().unwrap())],
    );
    assert!(!ok, "{out}");
    assert!(
        out.contains("XR_RUNTIME_JSON") && out.contains("--simulated"),
        "{out}"
    );
}

/// SIGTERM (what Ctrl+C or a closed console is on Windows) ends an open-ended session the
/// way `--frames` does: a clean exit, session files that hold every frame, a clean teardown.
#[test]
fn a_termination_signal_ends_the_session_cleanly() {
    let dir = scratch("sigterm");
    let session = dir.join("session");
    let report = dir.join("report.json");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(["xr", "--simulated", "--session", session.to_str().unwrap()])
        .env("FOVEA_VALIDATION", "1")
        .env("SIM_HEADSET_SIZE", "32x32")
        .env("SIM_HEADSET_REPORT", report.to_str().unwrap())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let frames_csv = session.join("frames.csv");
    // Until three frames are written, or the session has ended by itself (a failure: it
    // should run until signalled); no clock decides.
    while std::fs::read_to_string(&frames_csv).map_or(0, |t| t.lines().count()) < 7 {
        if child.try_wait().unwrap().is_some() {
            let out = child.wait_with_output().unwrap();
            panic!(
                "the session ended before 3 frames, unsignalled:\n{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = std::process::Command::new("sh")
        .args(["-c", &format!("kill -TERM {}", child.id())])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("stopping the session (interrupted)"),
        "{text}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(session.join("session.json")).unwrap())
            .unwrap();
    let frames = json["frames"].as_u64().unwrap();
    let rows = std::fs::read_to_string(&frames_csv)
        .unwrap()
        .lines()
        .count() as u64
        - 1;
    assert!(frames >= 3, "{json:#}");
    assert_eq!(rows, 2 * frames, "{json:#}");
    assert_clean_teardown(&dir);
}

/// `column` of every left-eye row of a session's frames.csv, by frame.
fn left_column(dir: &Path, column: &str) -> Vec<String> {
    let frames = std::fs::read_to_string(dir.join("session/frames.csv")).unwrap();
    let header: Vec<&str> = frames.lines().next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    frames
        .lines()
        .skip(1)
        .map(|row| row.split(',').collect::<Vec<_>>())
        .filter(|cells| cells[at("eye")] == "left")
        .map(|cells| cells[at(column)].to_string())
        .collect()
}

#[test]
fn frames_the_compositor_does_not_want_are_submitted_empty_and_counted_as_missed() {
    let dir = scratch("no-render");
    // The session turns visible at frame 1; frames 3 to 6 are not wanted.
    let (ok, out) = xr(
        &dir,
        &["--simulated", "--frames", "6", "--scene", "control"],
        &[
            ("SIM_HEADSET_SIZE", "24x24"),
            ("SIM_HEADSET_NO_RENDER", "3-6"),
        ],
    );
    assert!(ok, "{out}");
    assert_clean_teardown(&dir);
    let r = report(&dir);
    // Six frames rendered and handed over; every unwanted frame still ended, with no layers.
    assert_eq!(r["frames_with_layers"], 6, "{r:#}");
    assert!(r["frames_submitted"].as_u64().unwrap() >= 10, "{r:#}");
    assert_eq!(r["images_saved"], 12, "{r:#}");
    // Nothing was traced for them: six frames recorded, and the gap of four display periods
    // shows as four missed frames, at the first frame after it.
    let missed = left_column(&dir, "missed_frames");
    assert_eq!(missed, ["0", "0", "4", "0", "0", "0"], "{out}");
    let session: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("session/session.json")).unwrap())
            .unwrap();
    assert_eq!(session["latency"]["missed_frames"], 4);
    assert!(out.contains("frames missed: 4"), "{out}");
}

#[test]
fn a_long_session_holds_its_memory_steady() {
    // 3000 frames at a tiny size, the validation layer's default checks on (a message fails
    // the command): resident memory and GPU memory after frame 2999 as after frame 299.
    let dir = scratch("soak");
    let session = dir.join("session");
    let (ok, out) = common::fovea_with_env(
        &[
            "xr",
            "--simulated",
            "--frames",
            "3000",
            "--scene",
            "control",
            "--foveation",
            "thesis",
            "--session",
            session.to_str().unwrap(),
        ],
        &[("SIM_HEADSET_SIZE", "16x16")],
    );
    assert!(ok, "{out}");
    let mib = |column: &str| -> Vec<f64> {
        left_column(&dir, column)
            .iter()
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (rss, gpu) = (mib("rss_mib"), mib("gpu_mib"));
    assert_eq!(rss.len(), 3000);
    assert_eq!(gpu[299], gpu[2999], "GPU memory grew");
    assert!(
        rss[2999] - rss[299] <= 4.0,
        "resident memory grew from {:.1} MiB after frame 299 to {:.1} MiB after frame 2999",
        rss[299],
        rss[2999]
    );
}

/// Runs an 8-frame cornell session with `frames_in_flight` and a gaze that moves every frame
/// (a frame reading another frame's layer parameters would trace other points); with `save`,
/// the runtime saves the eye images it is handed (its read-back waits for the queue, so the
/// frames cannot overlap then).
fn in_flight_session(name: &str, frames_in_flight: &str, save: bool) -> common::TestDir {
    let dir = scratch(name);
    let session = dir.join("session");
    let images = dir.join("images");
    let mut env = vec![
        ("SIM_HEADSET_SIZE", "48x48"),
        (
            "SIM_HEADSET_GAZE",
            "1 10 5; 2 -12 3; 3 5 -8; 4 15 10; 5 -5 -5; 6 8 8; 7 -10 0",
        ),
    ];
    if save {
        env.push(("SIM_HEADSET_SAVE_DIR", images.to_str().unwrap()));
    }
    let (ok, out) = common::fovea_with_env(
        &[
            "xr",
            "--simulated",
            "--frames",
            "8",
            "--scene",
            "cornell",
            "--frames-in-flight",
            frames_in_flight,
            "--session",
            session.to_str().unwrap(),
        ],
        &env,
    );
    assert!(ok, "{out}");
    dir
}

#[test]
fn frames_in_flight_overlap_and_render_what_one_frame_at_a_time_renders() {
    let two = in_flight_session("in-flight-2", "2", false);
    let one = in_flight_session("in-flight-1", "1", false);
    // With two in flight, some frame was submitted while the one before it still ran on the
    // GPU (seen from its fence right before the submission); one at a time, never.
    let busy = left_column(&two, "busy_at_submit");
    assert_eq!(busy.len(), 8);
    assert!(
        busy.iter().any(|b| b == "1"),
        "no frame overlapped: {busy:?}"
    );
    assert!(busy.iter().all(|b| b == "0" || b == "1"), "{busy:?}");
    assert!(left_column(&one, "busy_at_submit").iter().all(|b| b == "0"));
    // Every frame traced what the same frame traced one at a time: its own gaze's points.
    for column in ["paths", "rays", "gaze_x", "gaze_y"] {
        assert_eq!(
            left_column(&two, column),
            left_column(&one, column),
            "{column}"
        );
    }
    // And both loops hand the headset the same images.
    let two = in_flight_session("in-flight-2-images", "2", true);
    let one = in_flight_session("in-flight-1-images", "1", true);
    let mut names: Vec<_> = std::fs::read_dir(one.join("images"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names.len(), 16);
    for name in names {
        let a = std::fs::read(one.join("images").join(&name)).unwrap();
        let b = std::fs::read(two.join("images").join(&name)).unwrap();
        assert!(
            a == b,
            "{name:?} differs between one and two frames in flight"
        );
    }
}

#[test]
fn each_frame_shows_the_trackers_newest_sample_at_its_latch_and_a_slow_compositor_misses_frames() {
    // The simulated tracker samples at 120 Hz on the runtime's clock, which reads two display
    // periods before a frame's display time when its xrWaitFrame returns and moves on in real
    // time; the compositor needs 20 ms a frame, so every frame is shown two 90 Hz periods
    // after the one before.
    let dir = scratch("latency");
    let (ok, out) = xr(
        &dir,
        &["--simulated", "--frames", "12", "--scene", "control"],
        &[
            ("SIM_HEADSET_SIZE", "16x16"),
            ("SIM_HEADSET_COMPOSITOR_MS", "20"),
        ],
    );
    assert!(ok, "{out}");
    let ms = |column: &str| -> Vec<f64> {
        left_column(&dir, column)
            .iter()
            .map(|v| v.parse().unwrap_or(f64::NAN))
            .collect()
    };
    let (photon, latch) = (ms("gaze_to_photon_ms"), ms("latch_ms"));
    let lead_ms = sim_headset::LEAD_NS as f64 * 1e-6;
    let sample_ms = sim_headset::GAZE_PERIOD_NS as f64 * 1e-6;
    // Frame 0 waits for pipelines. How soon the others latch is the machine's speed (a
    // figure in frames.csv, not a verdict); whenever it is, the sample shown is the newest.
    assert!(
        latch[1..].iter().all(|l| l.is_finite() && *l >= 0.0),
        "{latch:?}"
    );
    for f in 1..12 {
        // At the latch the runtime's clock read (display - lead + latch): the gaze's sample
        // is the newest at or before that moment (0.5 ms for the two sides' clocks), so the
        // next sample would have come after it.
        let latched_at = lead_ms - latch[f];
        assert!(photon[f] >= latched_at - 0.5, "frame {f}: {} ms", photon[f]);
        assert!(
            photon[f] - sample_ms < latched_at,
            "frame {f}: {} ms",
            photon[f]
        );
    }
    // The 120 Hz samples beat against the 90 Hz display: not one fixed age.
    let ages: std::collections::BTreeSet<i64> = photon[1..]
        .iter()
        .map(|p| (p * 10.0).round() as i64)
        .collect();
    assert!(ages.len() >= 2, "{photon:?}");
    let missed = left_column(&dir, "missed_frames");
    assert!(missed[1..].iter().all(|m| m == "1"), "{missed:?}");
    let session: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("session/session.json")).unwrap())
            .unwrap();
    assert_eq!(session["latency"]["missed_frames"], 11);
    assert!(out.contains("frames missed: 11"), "{out}");
}

/// The headset shows the scene through the display transform (`--exposure`, `--tonemap`), as
/// `fovea render`'s PNG does for the same frame; without it, the same frame clipped.
#[test]
fn the_headset_shows_the_display_transform() {
    let dir = scratch("display");
    let session = ["--simulated", "--frames", "2", "--scene", "cornell"];
    let frame = ["--foveation", "off", "--spp", "4"];
    let display = ["--exposure", "2", "--tonemap", "pbr-neutral"];
    let size = [("SIM_HEADSET_SIZE", "48x48")];
    let one_frame = ["--temporal", "off"];
    let (ok, out) = xr(
        &dir,
        &[&session[..], &frame, &one_frame, &display].concat(),
        &size,
    );
    assert!(ok, "{out}");
    let shown = [
        read_png(&last_image(&dir, 0)),
        read_png(&last_image(&dir, 1)),
    ];
    // The session's last frame (index 1) used seed 1 + 1.
    let render_png = dir.join("render.png");
    let view = [
        "--width",
        "48",
        "--height",
        "48",
        "--stereo",
        "--fov",
        "vive-pro-eye",
    ];
    let out_arg = ["--seed", "2", "--out", render_png.to_str().unwrap()];
    let (ok, out) = common::fovea(
        &[
            &["render", "--scene", "cornell"],
            &view[..],
            &frame,
            &display,
            &out_arg,
        ]
        .concat(),
    );
    assert!(ok, "{out}");
    let (_, _, rendered) = read_png(&render_png);
    let clipped_png = dir.join("clipped.png");
    let clipped_arg = ["--seed", "2", "--out", clipped_png.to_str().unwrap()];
    let (ok, out) = common::fovea(
        &[
            &["render", "--scene", "cornell"],
            &view[..],
            &frame,
            &clipped_arg,
        ]
        .concat(),
    );
    assert!(ok, "{out}");
    let (_, _, clipped) = read_png(&clipped_png);
    for (eye, (_, _, rgba)) in shown.iter().enumerate() {
        let (mut worst, mut unlike_clipped) = (0i32, 0);
        for y in 12..36usize {
            for x in 12..36usize {
                let a = &rgba[(y * 48 + x) * 4..][..3];
                let at = (y * 96 + eye * 48 + x) * 4;
                let (b, c) = (&rendered[at..][..3], &clipped[at..][..3]);
                for k in 0..3 {
                    worst = worst.max((a[k] as i32 - b[k] as i32).abs());
                }
                unlike_clipped += (0..3).any(|k| (a[k] as i32 - c[k] as i32).abs() > 8) as u32;
            }
        }
        // sRGB encoding by the blit (hardware) and by the PNG writer may round apart by one.
        assert!(
            worst <= 1,
            "eye {eye}: differs from fovea render by up to {worst}/255"
        );
        assert!(
            unlike_clipped > 100,
            "eye {eye}: only {unlike_clipped} pixels unlike clipping"
        );
    }
}

#[test]
fn the_headsets_shipped_config_is_the_default_and_a_given_one_wins() {
    // The simulated headset reports itself as Vive Pro Eye-like: its shipped config, whose
    // denoiser needs the history (on by default; off, it is left out and it says so).
    let size = [("SIM_HEADSET_SIZE", "32x32")];
    for (args, says) in [
        (
            &[][..],
            "foveation: assets/foveation/vive-pro-eye.toml (the runtime reports a vive-pro-eye)\n",
        ),
        (
            &["--temporal", "off"][..],
            "(the runtime reports a vive-pro-eye), unfiltered: its filters need the temporal history",
        ),
        (&["--foveation", "thesis"][..], "foveation: as given\n"),
    ] {
        let dir = scratch(&format!("shipped-{}", args.len()));
        let mut all = vec!["--simulated", "--frames", "2"];
        all.extend_from_slice(args);
        let (ok, out) = xr(&dir, &all, &size);
        assert!(ok && out.contains(says), "{args:?}: {out}");
        assert_clean_teardown(&dir);
    }
}
