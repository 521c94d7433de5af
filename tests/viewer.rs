//! `fovea view` under Xvfb on lavapipe with the validation layer on (any validation message
//! makes the command fail): scripted runs end cleanly, the screenshot is `fovea render`'s
//! image of the same view, the running mean is the mean of frames at successive seeds and
//! converges, and resizing, minimising and hiding the window mid-run break nothing.
//! Wayland cannot be tested here (no compositor); the X11 path is what runs.

mod common;

use fovea::render::FrameOptions;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// An Xvfb server on a display number it picks itself (`-displayfd`), so parallel tests and
/// other X servers never collide; killed on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Self {
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb is needed for the viewer tests: run tools/setup.sh (package xvfb)");
        // Xvfb writes the display number once it accepts connections.
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let number = line.trim();
        assert!(!number.is_empty(), "Xvfb did not start");
        Self {
            display: format!(":{number}"),
            child,
        }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A scratch directory for one test.
fn scratch(name: &str) -> common::TestDir {
    common::test_dir(&format!("viewer-{name}"))
}

/// Runs `fovea view ARGS` on the X server with validation on, on X11 even in a Wayland
/// session; fails the test unless it succeeds. Returns everything it printed.
fn view(x: &Xvfb, dir: &Path, args: &[&str]) -> String {
    let started = std::time::Instant::now();
    // These tests check the running mean of still frames unless they ask for a --refine.
    let refine: &[&str] = match args.contains(&"--refine") {
        true => &[],
        false => &["--refine", "foveated"],
    };
    let out = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .arg("view")
        .args(refine)
        .args(args)
        .current_dir(dir)
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .env("FOVEA_VALIDATION", "1")
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !text.contains("panicked"),
        "fovea view {args:?} panicked:\n{text}"
    );
    assert!(out.status.success(), "fovea view {args:?} failed:\n{text}");
    assert!(!text.contains("validation"), "fovea view {args:?}:\n{text}");
    eprintln!(
        "fovea view {args:?}: {:.1} s",
        started.elapsed().as_secs_f64()
    );
    text
}

/// `fovea render ARGS` (validation on), which must succeed.
fn render(args: &[&str]) {
    let (ok, text) = common::fovea(&[&["render"], args].concat());
    assert!(ok, "fovea render {args:?}:\n{text}");
}

/// Linear RGB of an EXR fovea wrote, and its size.
fn read_exr(path: &Path) -> (usize, usize, Vec<f32>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0.0f32; size.width() * size.height() * 3]),
        |(w, rgb), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * *w + pos.x());
            rgb[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let size = image.layer_data.size;
    let (_, rgb) = image.layer_data.channel_data.pixels;
    (size.width(), size.height(), rgb)
}

fn rmse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum();
    (sum / a.len() as f64).sqrt()
}

/// [`rmse`] of the images as a display shows them: radiance above 1 clips, so that a
/// firefly in one 1-spp frame (which the next frames only dilute) does not outweigh the image.
fn shown_rmse(a: &[f32], b: &[f32]) -> f64 {
    let shown = |v: &[f32]| v.iter().map(|x| x.clamp(0.0, 1.0)).collect::<Vec<f32>>();
    rmse(&shown(a), &shown(b))
}

/// The frame count of the final running mean, from the summary line.
fn accumulated(text: &str) -> u32 {
    let line = text
        .lines()
        .find(|l| l.contains("in the final running mean"))
        .unwrap_or_else(|| panic!("no summary line in:\n{text}"));
    let before = line
        .split(" frame(s) in the final running mean")
        .next()
        .unwrap();
    before.rsplit(' ').next().unwrap().parse().unwrap()
}

/// Tolerance 0: one frame of the viewer is the frame `fovea render` makes, bit for bit: the
/// same passes at the same seed, and the accumulation of a single frame copies it (a new
/// mean is the frame itself, no arithmetic), so the PNG files and the EXRs' pixels are identical.
#[test]
fn one_frame_screenshot_is_the_rendered_frame_bit_for_bit() {
    let x = Xvfb::start();
    let dir = scratch("equal");
    for (view_args, render_args) in [
        (
            vec!["--width", "96", "--height", "64", "--gaze", "40,30"],
            vec!["--width", "96", "--height", "64", "--gaze", "40,30"],
        ),
        (
            vec![
                "--stereo",
                "--width",
                "96",
                "--height",
                "64",
                "--gaze",
                "20,30:26,30",
            ],
            vec![
                "--stereo",
                "--width",
                "48",
                "--height",
                "64",
                "--gaze",
                "20,30:26,30",
            ],
        ),
    ] {
        let shot = dir.join("view.png");
        let out = dir.join("render.png");
        let shared = ["--scene", "cornell", "--foveation", "thesis", "--seed", "7"];
        let shot_arg = shot.to_str().unwrap();
        view(
            &x,
            &dir,
            &[
                &view_args[..],
                &shared[..],
                &["--frames", "1", "--screenshot", shot_arg],
            ]
            .concat(),
        );
        render(
            &[
                &render_args[..],
                &shared[..],
                &["--out", out.to_str().unwrap()],
            ]
            .concat(),
        );
        let png = |p: &Path| std::fs::read(p.with_extension("png")).unwrap();
        assert!(
            png(&shot) == png(&out),
            "{view_args:?}: the viewer's PNG differs from fovea render's"
        );
        // Pixels, not bytes: the EXR writer compresses blocks in parallel, in varying order.
        let (a, b) = (
            read_exr(&shot.with_extension("exr")),
            read_exr(&out.with_extension("exr")),
        );
        assert!(
            a == b,
            "{view_args:?}: the viewer's linear image differs from fovea render's"
        );
    }
}

/// A scripted run (the mouse as gaze, a camera turn and move, the camera reset, the gaze
/// moved) ends with 4 still frames, so its screenshot must be the mean of `fovea render` at
/// seeds 1..=4 of that view. Tolerance: 1e-5 relative (+1e-6 absolute) per channel, room for
/// the float rounding of the running mean m += (x − m)/n over 4 frames (a few ulps, ~1e-7),
/// and far below the per-frame noise (~1e-1) that a wrong seed or a missed restart would leave.
#[test]
fn scripted_run_accumulates_the_mean_of_renders_at_successive_seeds() {
    let x = Xvfb::start();
    let dir = scratch("mean");
    std::fs::write(
        dir.join("script.txt"),
        "0 mouse 10 10\n1 turn 5 0\n1 move 0 0 0.1\n2 key R\n2 mouse 40 30\n",
    )
    .unwrap();
    let size = ["--width", "96", "--height", "64"];
    let text = view(
        &x,
        &dir,
        &[
            &size[..],
            &[
                "--foveation",
                "thesis",
                "--script",
                "script.txt",
                "--frames",
                "6",
            ],
            &["--screenshot", "view.png"],
        ]
        .concat(),
    );
    assert_eq!(accumulated(&text), 4, "{text}");
    let (w, h, shot) = read_exr(&dir.join("view.exr"));
    assert_eq!((w, h), (96, 64));
    let mut mean = vec![0.0f64; shot.len()];
    for seed in 1..=4 {
        let out = dir.join(format!("render-{seed}.png"));
        let seed = seed.to_string();
        render(
            &[
                &size[..],
                &["--foveation", "thesis", "--gaze", "40,30", "--seed", &seed],
                &["--out", out.to_str().unwrap()],
            ]
            .concat(),
        );
        for (m, v) in mean.iter_mut().zip(read_exr(&out.with_extension("exr")).2) {
            *m += v as f64 / 4.0;
        }
    }
    let worst = shot
        .iter()
        .zip(&mean)
        .map(|(s, m)| (*s as f64 - m).abs() - 1e-5 * m.abs())
        .fold(f64::MIN, f64::max);
    assert!(
        worst <= 1e-6,
        "the screenshot is off the mean of the renders by {worst}"
    );
    // The 4 renders differ from each other by noise, so the test can tell them apart.
    assert!(rmse(&shot, &read_exr(&dir.join("render-1.exr")).2) > 1e-3);
}

/// While nothing moves, the error against a 256-spp reference falls as frames of 1 spp
/// (without foveation) accumulate: roughly as 1/sqrt(frames) (Monte Carlo), checked as strictly falling at 1, 2,
/// 4 and 8 frames and at most 0.6x the first frame's error after 8 frames (1/sqrt(8) = 0.35
/// expected; the reference's own noise adds a little).
#[test]
fn error_against_a_converged_render_falls_as_still_frames_accumulate() {
    let x = Xvfb::start();
    let dir = scratch("converge");
    std::fs::write(
        dir.join("script.txt"),
        "0 screenshot f1.exr\n1 screenshot f2.exr\n3 screenshot f4.exr\n7 screenshot f8.exr\n",
    )
    .unwrap();
    let text = view(
        &x,
        &dir,
        &[
            "--width",
            "64",
            "--height",
            "48",
            "--foveation",
            "off",
            "--spp",
            "1",
            "--script",
            "script.txt",
            "--frames",
            "8",
        ],
    );
    assert_eq!(accumulated(&text), 8, "{text}");
    let reference = dir.join("reference.exr");
    render(&[
        "--width",
        "64",
        "--height",
        "48",
        "--spp",
        "256",
        "--seed",
        "1000",
        "--out",
        reference.to_str().unwrap(),
    ]);
    let reference = read_exr(&reference).2;
    let errors: Vec<f64> = [1, 2, 4, 8]
        .iter()
        .map(|n| shown_rmse(&read_exr(&dir.join(format!("f{n}.exr"))).2, &reference))
        .collect();
    eprintln!("RMSE after 1, 2, 4, 8 frames: {errors:?}");
    assert!(errors.windows(2).all(|e| e[1] < e[0]), "{errors:?}");
    assert!(errors[3] < 0.6 * errors[0], "{errors:?}");
    // Foveated (thesis layers at 1 spp), 8 still frames: refining with more foveated frames
    // keeps the periphery's interpolation error; refining with regular frames after the
    // first removes it, so that mean is closer to the reference.
    let mut foveated = Vec::new();
    for refine in ["foveated", "regular", "temporal"] {
        let shot = format!("{refine}.exr");
        view(
            &x,
            &dir,
            &[
                "--width",
                "64",
                "--height",
                "48",
                "--foveation",
                "thesis",
                "--spp",
                "1",
                "--gaze",
                "32,24",
                "--refine",
                refine,
                "--frames",
                "8",
                "--screenshot",
                &shot,
            ],
        );
        foveated.push(rmse(&read_exr(&dir.join(&shot)).2, &reference));
    }
    eprintln!("RMSE after 8 foveated frames, refined foveated, regular and temporal: {foveated:?}");
    assert!(foveated[1] < foveated[0], "{foveated:?}");
    // The temporal history's shifting lattices give half the periphery's pixels samples of
    // their own in 8 frames (spacing 4): closer than the foveated mean too.
    assert!(foveated[2] < foveated[0], "{foveated:?}");
}

/// Resizing, minimising, restoring, hiding and showing the window mid-run, in stereo with
/// the mouse as gaze, while every key binding is pressed (all debug views, foveation off and
/// on, layer configs, spp, scene switch, camera): no crash, no validation message, and the
/// frames after the last resize have the new size.
#[test]
fn window_changes_and_every_key_mid_run_break_nothing() {
    let x = Xvfb::start();
    let dir = scratch("resize");
    std::fs::write(
        dir.join("script.txt"),
        "0 mouse 30 20\n1 resize 120 80\n2 minimise\n3 restore\n4 hide\n5 show\n\
         6 key V\n7 key V\n7 mouse 100 10\n8 key V\n9 key V\n10 key F\n11 key F\n12 key L\n\
         13 key +\n14 key -\n15 key N\n16 key P\n17 turn 10 5\n18 move 0 0 0.2\n\
         19 resize 64 48\n",
    )
    .unwrap();
    let text = view(
        &x,
        &dir,
        &[
            "--stereo",
            "--width",
            "96",
            "--height",
            "64",
            "--script",
            "script.txt",
            "--frames",
            "22",
            "--screenshot",
            "end.png",
        ],
    );
    let recreated: u32 = text
        .split("swapchain recreated ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no recreation count in:\n{text}"));
    assert!(
        recreated >= 2,
        "two resizes, {recreated} recreations:\n{text}"
    );
    assert!(
        dir.join("end-1.png").exists(),
        "the P key's screenshot:\n{text}"
    );
    let decoder = png::Decoder::new(BufReader::new(
        std::fs::File::open(dir.join("end.png")).unwrap(),
    ));
    let info = decoder.read_info().unwrap().info().clone();
    assert_eq!((info.width, info.height), (64, 48));
}

/// A recorded gaze trace replays one row per frame; past its end the last row holds, so the
/// view stands still and frames accumulate again.
#[test]
fn gaze_trace_replays_and_then_holds() {
    let x = Xvfb::start();
    let dir = scratch("trace");
    std::fs::write(
        dir.join("trace.csv"),
        "frame,time_s,left_tan_x,left_tan_y,right_tan_x,right_tan_y,status\n\
         0,0.0,0.0,0.0,0.0,0.0,tracked\n\
         1,0.011,0.1,0.05,0.1,0.05,tracked\n\
         2,0.022,-0.2,0.1,-0.2,0.1,tracked\n",
    )
    .unwrap();
    let text = view(
        &x,
        &dir,
        &[
            "--width",
            "64",
            "--height",
            "48",
            "--gaze-trace",
            "trace.csv",
            "--frames",
            "5",
        ],
    );
    // Rows 0, 1, 2 move the gaze every frame; frames 3 and 4 hold row 2.
    assert_eq!(accumulated(&text), 3, "{text}");
}

/// Turbo as accumulate.comp computes it (display values).
fn turbo(x: f64) -> [f64; 3] {
    let r4 = [0.13572138, 4.61539260, -42.66032258, 132.13108234];
    let g4 = [0.09140261, 2.19418839, 4.84296658, -14.18503333];
    let b4 = [0.10667330, 12.64194608, -60.58204836, 110.36276771];
    let (r2, g2, b2) = (
        [-152.94239396, 59.28637943],
        [4.27729857, 2.82956604],
        [-89.90310912, 27.34824973],
    );
    let x = x.clamp(0.0, 1.0);
    let v = [1.0, x, x * x, x * x * x];
    let w = [v[2] * v[2], v[3] * v[2]];
    let c = |a: [f64; 4], b: [f64; 2]| {
        (a.iter().zip(v).map(|(a, v)| a * v).sum::<f64>() + b[0] * w[0] + b[1] * w[1])
            .clamp(0.0, 1.0)
    };
    [c(r4, r2), c(g4, g2), c(b4, b2)]
}

/// The GPU debug views without a window: after 2 frames of the thesis config (4 spp per
/// target pixel), the heat map colours the pixel at the gaze for 2 × 4 = 8 samples per pixel
/// and a corner (background layer, spacing 4) for 2 × 4 / 16 = 0.5, on the log2 ramp; the
/// difference from regular frames at the same seeds is exactly 0 in the fovea, where the two
/// are bit-identical, and not elsewhere.
#[test]
fn heat_map_and_difference_view_show_what_they_say() {
    use fovea::foveation::{FoveationConfig, GazeChoice};
    use fovea::render::accumulate::{AccumulateRequest, Accumulator, Mean, Show};
    use fovea::render::{eye_views, DebugView, FovChoice, FrameRequest, Renderer};
    use fovea::shader_layout::{ACCUM_HEAT_LOG2_MAX, ACCUM_HEAT_LOG2_MIN};

    let ctx = common::context();
    let scene = fovea::scene::builtin::builtin("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    // The accumulator reads the frames from the output image.
    renderer.set_output_image(true);
    let mut means = Accumulator::new(&ctx).unwrap();
    let thesis = FoveationConfig::thesis();
    let regular = FoveationConfig::regular(4);
    let gaze: GazeChoice = "32,32".parse().unwrap();
    let eyes = eye_views(&scene.camera, 1.0, FovChoice::Scene, false, gaze);
    let settings = common::settings(64, 64, 4, 1, fovea::render::Integrator::Pt);
    let mut frame = |means: &mut Accumulator, config: &FoveationConfig, into, show| {
        renderer
            .frame(
                &FrameRequest {
                    settings: fovea::render::RenderSettings {
                        seed: means.next_seed(1, into),
                        ..settings
                    },
                    foveation: config,
                    eyes: &eyes,
                    debug: DebugView::None,
                },
                FrameOptions::measure(),
            )
            .map(Option::unwrap)
            .unwrap();
        let image = renderer.output_image().unwrap();
        means
            .add(&AccumulateRequest {
                frame: image,
                eyes: &eyes,
                eye_size: [64, 64],
                foveation: config,
                into,
                show,
            })
            .unwrap();
        image.read_back().unwrap()
    };
    frame(&mut means, &thesis, Mean::Main, Show::Mean);
    let heat = frame(&mut means, &thesis, Mean::Main, Show::Heat);
    assert_eq!(means.frames(), 2);
    for ((x, y), spp) in [((32, 32), 8.0f64), ((0, 0), 0.5)] {
        let p = &heat[4 * (y * 64 + x)..][..3];
        let t = (spp.log2() - ACCUM_HEAT_LOG2_MIN as f64)
            / (ACCUM_HEAT_LOG2_MAX as f64 - ACCUM_HEAT_LOG2_MIN as f64);
        let colour = turbo(t).map(|c| c.powf(2.2));
        // The pixel is the colour times the image's faint luminance, 0.6 to 1.
        let scale: Vec<f64> = (0..3).map(|c| p[c] as f64 / colour[c]).collect();
        assert!(
            scale
                .iter()
                .all(|s| (s - scale[0]).abs() < 1e-3 && (0.599..=1.001).contains(s)),
            "pixel ({x}, {y}): {p:?} is not the colour of {spp} spp {colour:?}"
        );
    }
    means.reset();
    frame(&mut means, &thesis, Mean::Main, Show::Nothing);
    frame(&mut means, &regular, Mean::Regular, Show::Difference);
    frame(&mut means, &thesis, Mean::Main, Show::Nothing);
    let diff = frame(&mut means, &regular, Mean::Regular, Show::Difference);
    let at = |x: usize, y: usize| &diff[4 * (y * 64 + x)..][..3];
    assert_eq!(at(32, 32), [0.0; 3]);
    assert_eq!(at(30, 33), [0.0; 3]);
    let outside: f32 = (0..64).flat_map(|y| at(0, y).to_vec()).sum();
    assert!(
        outside > 0.0,
        "the periphery differs from regular rendering"
    );
    drop(renderer);
    drop(means);
    common::assert_no_validation_messages(&ctx);
}

/// Esc ends a run cleanly before --frames is reached; a render scale of 0.5 renders (and
/// saves) half the window's resolution and presents it scaled up.
#[test]
fn escape_ends_the_run_and_the_render_scale_applies() {
    let x = Xvfb::start();
    let dir = scratch("escape");
    std::fs::write(dir.join("script.txt"), "2 key Escape\n").unwrap();
    let text = view(
        &x,
        &dir,
        &[
            "--width",
            "96",
            "--height",
            "64",
            "--scale",
            "0.5",
            "--script",
            "script.txt",
            "--frames",
            "100",
            "--screenshot",
            "end.png",
        ],
    );
    assert!(
        text.contains("frames: 2 (2 rendered, 2 presented"),
        "{text}"
    );
    let decoder = png::Decoder::new(BufReader::new(
        std::fs::File::open(dir.join("end.png")).unwrap(),
    ));
    let info = decoder.read_info().unwrap().info().clone();
    assert_eq!((info.width, info.height), (48, 32));
}

/// With `--exposure` and `--tonemap`, the window shows the image through them (a display pass
/// runs before it is presented) and the screenshot's PNG is `fovea render`'s with the same
/// flags, its EXR the same scene-referred radiance.
#[test]
fn the_window_shows_the_display_transform() {
    let x = Xvfb::start();
    let dir = scratch("display");
    let shot = dir.join("view.png");
    let out = dir.join("render.png");
    let shared = [
        "--scene",
        "cornell",
        "--width",
        "64",
        "--height",
        "48",
        "--foveation",
        "off",
        "--spp",
        "2",
        "--seed",
        "5",
        "--exposure",
        "1.5",
        "--tonemap",
        "pbr-neutral",
    ];
    let text = view(
        &x,
        &dir,
        &[
            &shared[..],
            &["--frames", "1", "--screenshot", shot.to_str().unwrap()],
        ]
        .concat(),
    );
    render(&[&shared[..], &["--out", out.to_str().unwrap()]].concat());
    let png = |p: &Path| std::fs::read(p.with_extension("png")).unwrap();
    assert!(
        png(&shot) == png(&out),
        "the viewer's PNG differs from fovea render's"
    );
    let (a, b) = (
        read_exr(&shot.with_extension("exr")),
        read_exr(&out.with_extension("exr")),
    );
    assert!(
        a == b,
        "the viewer's linear image differs from fovea render's"
    );
    assert!(
        text.contains("display: PbrNeutral at +1.5 EV (a display pass before presenting)"),
        "{text}"
    );
}

/// By default the viewer shows what the headset shows: the temporal history, no running mean.
#[test]
fn the_viewer_shows_the_temporal_history_by_default() {
    let x = Xvfb::start();
    let dir = scratch("default-refine");
    let out = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args([
            "view", "--scene", "cornell", "--width", "48", "--height", "32", "--frames", "3",
        ])
        .current_dir(&*dir)
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .env("FOVEA_VALIDATION", "1")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "{text}");
    assert_eq!(
        accumulated(&text),
        0,
        "a running mean instead of the history:\n{text}"
    );
    assert!(text.contains("refine: temporal history"), "{text}");
}
