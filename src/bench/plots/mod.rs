//! The thesis' plots, written as SVG and PNG with plotters.
//!
//! Every chart function takes a `stem` and writes `<stem>.svg` and
//! `<stem>.png` (the extension is *appended*, so a stem like `out/low.fwd`
//! keeps its dot) from one drawing routine generic over the backend. Missing
//! parent directories are created.
//!
//! Input handling, the same for every chart:
//! - non-finite values (NaN, ±∞) are skipped; a gap is left in lines;
//! - a chart with no drawable value still writes both files, showing the
//!   title and "no data" (so a report never links to a missing file);
//! - a flat range (all values equal, or a single point) is padded so no axis
//!   has zero extent.
//!
//! Text is rendered with the embedded DejaVu Sans, registered once as
//! "sans-serif", so PNGs do not depend on system fonts.

mod figures;
mod jod_fig;
mod strip;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use figures::{DotsFig, ErrorFig, LinesFig};
use jod_fig::JodFig;
pub use strip::{animated_strip, image_strip};

/// Pixel size of every chart.
const SIZE: (u32, u32) = (900, 500);
/// Font family registered with the embedded DejaVu Sans.
const FONT: &str = "sans-serif";
/// Width of the legend column right of a chart.
const LEGEND_WIDTH: u32 = 180;
/// Height of the caption band above the panels of [`image_strip`].
pub const STRIP_CAPTION_HEIGHT: u32 = 28;
/// White gap between two panels of [`image_strip`] (none at the outer edges).
pub const STRIP_GAP: u32 = 4;

/// Why a plot could not be written; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("{}: cannot register the embedded DejaVu Sans font", .path.display())]
    Font { path: PathBuf },
    #[error("{}: {source}", .path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: drawing failed: {message}", .path.display())]
    Draw { path: PathBuf, message: String },
    #[error("{}: PNG encoding failed: {source}", .path.display())]
    Encode {
        path: PathBuf,
        source: png::EncodingError,
    },
    #[error("{}: no panels to draw", .path.display())]
    NoPanels { path: PathBuf },
    #[error("{}: panel {index} ({label:?}) has {actual} bytes, expected {expected} ({width}×{height}×3)", .path.display())]
    PanelSize {
        path: PathBuf,
        index: usize,
        label: String,
        width: u32,
        height: u32,
        expected: u64,
        actual: usize,
    },
    #[error("{}: image size {width}×{height} is empty or too large", .path.display())]
    BadSize {
        path: PathBuf,
        width: u64,
        height: u64,
    },
}

/// One line of [`frame_rate_lines`]: per-frame fps of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text; its prefix picks the colour ("regular", "forward", "corner").
    pub label: String,
    pub values: Vec<f64>,
}

/// One row of [`mean_std_dots`].
#[derive(Clone, Debug, PartialEq)]
pub struct DotWhisker {
    pub label: String,
    pub mean: f64,
    pub std: f64,
}

/// One measured point of [`error_vs_time`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// GPU time in milliseconds (x, log scale).
    pub ms: f64,
    /// Error against the reference (y, log scale).
    pub error: f64,
    /// Samples per pixel, written next to the point.
    pub spp: u32,
}

/// One line of [`error_vs_time`].
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub label: String,
    pub points: Vec<CurvePoint>,
}

/// One image of [`image_strip`]: 8-bit RGB, row-major, 3 bytes per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub label: String,
    pub width: u32,
    pub height: u32,
    pub rgb8: Vec<u8>,
}

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A chart drawable on any backend, so SVG and PNG share one routine.
trait Figure {
    fn title(&self) -> &str;
    /// Draws everything below the title into `area`.
    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// The thesis' per-frame line graph: x = frame index, y = fps, one line per
/// series; regular black and solid, forward red, corner blue (thinner and
/// lighter), other labels from a fixed palette. Returns the files written.
pub fn frame_rate_lines(
    stem: &Path,
    title: &str,
    series: &[Series],
) -> Result<Vec<PathBuf>, PlotError> {
    per_frame_lines(stem, title, "fps", series)
}

/// [`frame_rate_lines`] with another quantity on the y axis (`y_label`), linear: a value
/// per frame of each series, e.g. a motion sequence's error or flicker.
pub fn per_frame_lines(
    stem: &Path,
    title: &str,
    y_label: &str,
    series: &[Series],
) -> Result<Vec<PathBuf>, PlotError> {
    write_both(
        stem,
        &LinesFig {
            title,
            y_label,
            series,
        },
    )
}

/// The thesis' dot-and-whisker plot: one row per item (first on top, labels on
/// the y axis), a dot at the mean and a whisker of ± std along x. Items with a
/// non-finite mean keep their row but draw nothing; a non-finite std draws the
/// dot only; a negative std is taken by magnitude.
pub fn mean_std_dots(
    stem: &Path,
    title: &str,
    x_label: &str,
    items: &[DotWhisker],
) -> Result<Vec<PathBuf>, PlotError> {
    write_both(
        stem,
        &DotsFig {
            title,
            x_label,
            items,
        },
    )
}

/// Run time against error on log-log axes (x GPU ms, y `y_label`), lines with
/// markers, each point annotated with its spp. Points whose ms or error is
/// non-positive or non-finite cannot be placed on log axes and are skipped, as
/// are (absurd) values outside 1e-100..=1e100, which would stall plotters.
pub fn error_vs_time(
    stem: &Path,
    title: &str,
    y_label: &str,
    curves: &[Curve],
) -> Result<Vec<PathBuf>, PlotError> {
    write_both(
        stem,
        &ErrorFig {
            title,
            y_label,
            curves,
        },
    )
}

/// What [`jod_vs_time`] draws.
pub struct JodChart<'a> {
    pub title: &'a str,
    /// Lines through labelled points (`spp` written beside each, none when 0); `error` is
    /// the JOD. The label's first word picks the colour as in [`error_vs_time`].
    pub curves: &'a [Curve],
    /// Other measured points, (ms, JOD), drawn as grey dots.
    pub scatter: &'a [(f64, f64)],
    /// A vertical line at this GPU time.
    pub budget_ms: Option<f64>,
    /// A point to ring, (ms, JOD).
    pub chosen: Option<(f64, f64)>,
}

/// Perceptual quality against run time: x = GPU ms, y = JOD, both linear. Returns the
/// files written.
pub fn jod_vs_time(stem: &Path, chart: &JodChart) -> Result<Vec<PathBuf>, PlotError> {
    write_both(stem, &JodFig(chart))
}

/// Registers DejaVu Sans as "sans-serif" once per process.
fn ensure_font(path: &Path) -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok());
    ok.then_some(())
        .ok_or_else(|| PlotError::Font { path: path.into() })
}

fn create_parent(path: &Path) -> Result<(), PlotError> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            std::fs::create_dir_all(dir).map_err(|source| PlotError::Io {
                path: path.into(),
                source,
            })
        }
        _ => Ok(()),
    }
}

/// `stem` + "." + `ext`, appending rather than replacing an extension.
fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    s.into()
}

/// Draws `fig` once on an SVG and once on a PNG backend.
fn write_both(stem: &Path, fig: &impl Figure) -> Result<Vec<PathBuf>, PlotError> {
    let (svg, png) = (with_ext(stem, "svg"), with_ext(stem, "png"));
    ensure_font(&svg)?;
    create_parent(&svg)?;
    let draw_err = |path: &Path, e: String| PlotError::Draw {
        path: path.into(),
        message: e,
    };
    render(&SVGBackend::new(&svg, SIZE).into_drawing_area(), fig)
        .map_err(|e| draw_err(&svg, e.to_string()))?;
    render(&BitMapBackend::new(&png, SIZE).into_drawing_area(), fig)
        .map_err(|e| draw_err(&png, e.to_string()))?;
    Ok(vec![svg, png])
}

fn render<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &impl Figure) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let body = root.titled(fig.title(), (FONT, 22))?;
    fig.body(&body)?;
    root.present()
}

fn no_data<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 20).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text("no data", &style, (w as i32 / 2, h as i32 / 2))
}

/// Finite (min, max) of `values`, or `None` if there is no finite value.
fn finite_bounds(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| {
            Some(acc.map_or((v, v), |(lo, hi): (f64, f64)| (lo.min(v), hi.max(v))))
        })
}

/// Axis range around [lo, hi]: 5 % padding, or ±max(10 %, 1) when flat.
/// With `from_zero` and non-negative data the axis starts at 0, which keeps
/// the ratio between regular and foveated frame rates visually honest.
fn linear_range(lo: f64, hi: f64, from_zero: bool) -> (f64, f64) {
    let lo = if from_zero && lo >= 0.0 { 0.0 } else { lo };
    let span = hi - lo;
    let (a, b) = if span <= f64::EPSILON * hi.abs().max(1.0) {
        let pad = (hi.abs() * 0.1).max(1.0);
        (lo - pad, hi + pad)
    } else if lo == 0.0 && from_zero {
        (0.0, hi + span * 0.05)
    } else {
        (lo - span * 0.05, hi + span * 0.05)
    };
    if a.is_finite() && b.is_finite() {
        (a, b)
    } else {
        (lo.max(-f64::MAX / 4.0), hi.min(f64::MAX / 4.0))
    }
}

/// Log axis range around positive [lo, hi]: a factor 1.25 of padding, or 2 when flat.
fn log_range(lo: f64, hi: f64) -> (f64, f64) {
    let pad = if hi / lo < 1.0 + 1e-9 { 2.0 } else { 1.25 };
    (lo / pad, hi * pad)
}

/// Colours for labels without a mode prefix; black, red and blue are avoided.
const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 150, 70),
    RGBColor(230, 130, 0),
    RGBColor(130, 60, 170),
    RGBColor(0, 150, 160),
    RGBColor(140, 90, 40),
    RGBColor(200, 0, 160),
];

/// The thesis' mode colours: the first word of the label (case-insensitive)
/// that names a mode picks it — "regular" black, "forward"/"foveated" red,
/// "corner" blue — so "forward r3" and "cubes forward" both read as forward.
/// Other labels take a palette colour by `index`. The flag marks foveated modes.
fn mode_color(label: &str, index: usize) -> (RGBColor, bool) {
    let lower = label.to_ascii_lowercase();
    let mode = lower
        .split(|c: char| !c.is_ascii_alphanumeric())
        .find_map(|w| match w {
            "regular" => Some((BLACK, false)),
            "forward" | "foveated" => Some((RED, true)),
            "corner" => Some((BLUE, true)),
            _ => None,
        });
    mode.unwrap_or((PALETTE[index % PALETTE.len()], false))
}

/// Line style for [`frame_rate_lines`]: foveated runs thinner and lighter so
/// the (fewer) regular lines stay readable among ~20 foveated ones.
fn line_style(label: &str, index: usize) -> ShapeStyle {
    match mode_color(label, index) {
        (c, true) => c.mix(0.55).stroke_width(1),
        (c, false) if c == BLACK => c.stroke_width(2),
        (c, false) => c.stroke_width(1),
    }
}

/// Splits `points` into runs separated by points for which `keep` fails, so
/// skipped values leave a gap instead of a misleading straight segment.
fn runs<T: Copy>(points: impl IntoIterator<Item = T>, keep: impl Fn(&T) -> bool) -> Vec<Vec<T>> {
    let mut out = vec![Vec::new()];
    for p in points {
        match (keep(&p), out.last_mut()) {
            (true, Some(run)) => run.push(p),
            (false, Some(run)) if !run.is_empty() => out.push(Vec::new()),
            _ => {}
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// A legend column: a short line in each entry's style and its label. Rows
/// shrink to fit; what still does not fit is summarized as "… +k more".
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, ShapeStyle)],
) -> DrawResult<DB> {
    let (_, h) = area.dim_in_pixel();
    let top = 20i32;
    let avail = (h as i32 - top - 10).max(0);
    let n = entries.len().max(1) as i32;
    let row = (avail / n).clamp(10, 18);
    let fit = (avail / row).max(1) as usize;
    let shown = if entries.len() > fit {
        fit - 1
    } else {
        entries.len()
    };
    let text = TextStyle::from((FONT, row - 4).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, (label, style)) in entries.iter().take(shown).enumerate() {
        let y = top + i as i32 * row + row / 2;
        area.draw(&PathElement::new(vec![(6, y), (30, y)], *style))?;
        area.draw_text(label, &text, (36, y))?;
    }
    if shown < entries.len() {
        let y = top + shown as i32 * row + row / 2;
        area.draw_text(
            &format!("… +{} more", entries.len() - shown),
            &text,
            (36, y),
        )?;
    }
    Ok(())
}

fn axis_font() -> TextStyle<'static> {
    (FONT, 14).into()
}
