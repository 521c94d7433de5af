use super::canvas::SIZE;
use super::style::{mode_color, PALETTE};
use super::*;
use plotters::prelude::{BLACK, BLUE, RED};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh, unique directory under the system temp dir.
fn temp_dir(name: &str) -> crate::test_dir::TestDir {
    static N: AtomicUsize = AtomicUsize::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    crate::test_dir::TestDir::new(&format!("plots-{name}-{n}"))
}

/// Decodes a PNG into (width, height, RGB or RGBA bytes, bytes per pixel).
fn decode(path: &Path) -> (u32, u32, Vec<u8>, usize) {
    let dec = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf, info.color_type.samples())
}

/// Both files exist, the SVG holds the title, the PNG is 900×500 and not flat.
fn check_chart(files: &[PathBuf], title: &str) {
    assert_eq!(files.len(), 2);
    let svg = std::fs::read_to_string(&files[0]).unwrap();
    assert!(
        svg.contains("<svg") && svg.contains(title),
        "{}",
        files[0].display()
    );
    let (w, h, px, bpp) = decode(&files[1]);
    assert_eq!((w, h), SIZE);
    assert!(px.chunks(bpp).any(|p| p != &px[..bpp]), "flat PNG");
}

fn series(label: &str, values: Vec<f64>) -> Series {
    Series {
        label: label.into(),
        values,
    }
}

#[test]
fn frame_rate_lines_writes_both() {
    let dir = temp_dir("lines");
    let mut all = vec![series(
        "regular",
        (0..100).map(|i| 22.0 + (i % 7) as f64).collect(),
    )];
    for r in 1..=10 {
        all.push(series(
            &format!("forward r{r}"),
            (0..100).map(|i| 44.0 + ((i * r) % 9) as f64).collect(),
        ));
        all.push(series(
            &format!("corner r{r}"),
            (0..100).map(|i| 89.0 + ((i + r) % 5) as f64).collect(),
        ));
    }
    all[1].values[5] = f64::NAN;
    let files = frame_rate_lines(&dir.join("low.lines"), "Low triangle scene", &all).unwrap();
    assert!(files[0].ends_with("low.lines.svg") && files[1].ends_with("low.lines.png"));
    check_chart(&files, "Low triangle scene");
}

#[test]
fn frame_rate_lines_degenerate_inputs() {
    let dir = temp_dir("lines-degenerate");
    let cases = [
        vec![],
        vec![series("regular", vec![])],
        vec![series("regular", vec![f64::NAN, f64::INFINITY])],
        vec![series("regular", vec![42.0])],
        vec![
            series("regular", vec![0.0; 10]),
            series("x", vec![f64::NAN, 1.0, f64::NAN]),
        ],
        vec![series("forward", vec![5.0; 3])],
        vec![series("corner", vec![f64::MAX, -f64::MAX, 1e-300])],
    ];
    for (i, c) in cases.iter().enumerate() {
        check_chart(
            &frame_rate_lines(&dir.join(format!("c{i}")), "Degenerate", c).unwrap(),
            "Degenerate",
        );
    }
    let svg = std::fs::read_to_string(dir.join("c0.svg")).unwrap();
    assert!(svg.contains("no data"));
}

#[test]
fn mean_std_dots_writes_both() {
    let dir = temp_dir("dots");
    let dot = |label: &str, mean, std| DotWhisker {
        label: label.into(),
        mean,
        std,
    };
    let items = [
        dot("regular", 22.45, 2.89),
        dot("forward", 44.89, 7.69),
        dot("corner", 89.69, 4.8),
        dot("broken", f64::NAN, 1.0),
    ];
    check_chart(
        &mean_std_dots(&dir.join("dots"), "Mean fps", "fps", &items).unwrap(),
        "Mean fps",
    );
    for (i, c) in [
        vec![],
        vec![dot("one", 3.0, 0.0)],
        vec![dot("nan", f64::NAN, f64::NAN)],
        vec![dot("neg", 2.0, -1.0)],
        vec![dot("huge", f64::MAX, f64::MAX), dot("tiny", -f64::MAX, 1.0)],
    ]
    .iter()
    .enumerate()
    {
        check_chart(
            &mean_std_dots(&dir.join(format!("d{i}")), "Edge", "fps", c).unwrap(),
            "Edge",
        );
    }
}

#[test]
fn error_vs_time_writes_both() {
    let dir = temp_dir("error");
    let pt = |ms, error, spp| CurvePoint { ms, error, spp };
    let curves = [
        Curve {
            label: "regular".into(),
            points: (0..6)
                .map(|k| pt(2f64.powi(k), 0.2 / 2f64.powi(k).sqrt(), 1 << k))
                .collect(),
        },
        Curve {
            label: "foveated".into(),
            points: vec![
                pt(0.5, 0.3, 1),
                pt(-1.0, 0.2, 2),
                pt(2.0, f64::NAN, 4),
                pt(4.0, 0.1, 8),
            ],
        },
    ];
    let files = error_vs_time(&dir.join("err"), "FLIP vs time", "mean FLIP", &curves).unwrap();
    check_chart(&files, "FLIP vs time");
    let svg = std::fs::read_to_string(&files[0]).unwrap();
    // plotters writes each text on its own line.
    assert!(
        svg.lines().any(|l| l.trim() == "32"),
        "spp annotation missing"
    );
    let one = [Curve {
        label: "x".into(),
        points: vec![pt(1.0, 1.0, 1)],
    }];
    let bad = [Curve {
        label: "x".into(),
        points: vec![pt(0.0, 1.0, 1), pt(1.0, -1.0, 2)],
    }];
    let extreme = [Curve {
        label: "x".into(),
        points: vec![
            pt(f64::MIN_POSITIVE, f64::MAX, 1),
            pt(1e-100, 1e100, 2),
            pt(1e100, 1e-100, 4),
            pt(f64::MAX, 5e-324, 8),
        ],
    }];
    for (i, c) in [&one[..], &bad[..], &extreme[..], &[]].iter().enumerate() {
        check_chart(
            &error_vs_time(&dir.join(format!("e{i}")), "Edge", "err", c).unwrap(),
            "Edge",
        );
    }
}

#[test]
fn mode_colours_follow_the_thesis() {
    assert_eq!(mode_color("regular", 5), (BLACK, false));
    assert_eq!(mode_color("Forward r3", 0), (RED, true));
    assert_eq!(mode_color("cubes corner", 0), (BLUE, true));
    assert_eq!(mode_color("other", 1), (PALETTE[1], false));
}

fn solid(label: &str, w: u32, h: u32, rgb: [u8; 3]) -> Panel {
    Panel {
        label: label.into(),
        width: w,
        height: h,
        rgb8: rgb.repeat((w * h) as usize),
    }
}

#[test]
fn image_strip_layout_and_pixels() {
    let dir = temp_dir("strip");
    let panels = [
        solid("reference", 64, 48, [255, 0, 0]),
        solid("regular", 80, 48, [0, 255, 0]),
        solid("FLIP error", 32, 20, [0, 0, 255]),
    ];
    let path = image_strip(&dir.join("strip.png"), &panels).unwrap();
    let (w, h, px, bpp) = decode(&path);
    assert_eq!(w, 64 + 80 + 32 + 2 * STRIP_GAP);
    assert_eq!(h, STRIP_CAPTION_HEIGHT + 48);
    let at = |x: u32, y: u32| px[(y * w + x) as usize * bpp..][..3].to_vec();
    assert_eq!(at(32, STRIP_CAPTION_HEIGHT + 24), [255, 0, 0]);
    assert_eq!(
        at(64 + STRIP_GAP + 40, STRIP_CAPTION_HEIGHT + 24),
        [0, 255, 0]
    );
    assert_eq!(
        at(64 + 80 + 2 * STRIP_GAP + 16, STRIP_CAPTION_HEIGHT + 10),
        [0, 0, 255]
    );
    // Below the short blue panel is white; the caption band holds dark text.
    assert_eq!(at(64 + 80 + 2 * STRIP_GAP + 16, h - 1), [255, 255, 255]);
    let band = &px[..(STRIP_CAPTION_HEIGHT * w) as usize * bpp];
    assert!(
        band.chunks(bpp)
            .any(|p| p[0] < 128 && p[1] < 128 && p[2] < 128),
        "no caption text"
    );
}

#[test]
fn image_strip_rejects_bad_input() {
    let dir = temp_dir("strip-bad");
    let path = dir.join("bad.png");
    let mut short = solid("short", 4, 4, [1, 2, 3]);
    short.rgb8.pop();
    let err = image_strip(&path, &[solid("ok", 4, 4, [0; 3]), short]).unwrap_err();
    assert!(matches!(
        err,
        PlotError::PanelSize {
            index: 1,
            expected: 48,
            actual: 47,
            ..
        }
    ));
    assert!(err.to_string().contains("bad.png"));
    assert!(matches!(
        image_strip(&path, &[]),
        Err(PlotError::NoPanels { .. })
    ));
    let empty = Panel {
        label: "empty".into(),
        width: 0,
        height: 0,
        rgb8: vec![],
    };
    assert!(matches!(
        image_strip(&path, &[empty]),
        Err(PlotError::BadSize { .. })
    ));
    let huge = Panel {
        label: "huge".into(),
        width: u32::MAX,
        height: 2,
        rgb8: vec![],
    };
    assert!(matches!(
        image_strip(&path, &[huge]),
        Err(PlotError::PanelSize { .. })
    ));
    assert!(!path.exists());
}
