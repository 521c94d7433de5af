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

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::backend::RGBPixel;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

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
    write_both(stem, &LinesFig { title, series })
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

/// Writes a PNG (at `path`, used as given) with the panels side by side, left
/// to right, each under a caption band of [`STRIP_CAPTION_HEIGHT`] px, with
/// [`STRIP_GAP`] px of white between panels. Width = Σ widths + gap·(k − 1);
/// height = caption band + tallest panel (shorter panels are top-aligned on
/// white). Errors: no panels, an `rgb8` length ≠ width·height·3, or an empty
/// or oversized (> u32 pixels) result.
pub fn image_strip(path: &Path, panels: &[Panel]) -> Result<PathBuf, PlotError> {
    if panels.is_empty() {
        return Err(PlotError::NoPanels { path: path.into() });
    }
    check_panels(path, panels)?;
    let (w, h) = strip_size(path, panels)?;
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    let mut x0 = 0u32;
    for p in panels {
        blit(&mut buf, w, p, x0, STRIP_CAPTION_HEIGHT);
        x0 += p.width + STRIP_GAP;
    }
    ensure_font(path)?;
    draw_captions(&mut buf, (w, h), panels).map_err(|message| PlotError::Draw {
        path: path.into(),
        message,
    })?;
    create_parent(path)?;
    encode_png(path, &buf, (w, h))?;
    Ok(path.into())
}

fn check_panels(path: &Path, panels: &[Panel]) -> Result<(), PlotError> {
    for (index, p) in panels.iter().enumerate() {
        let expected = u64::from(p.width) * u64::from(p.height) * 3;
        if p.rgb8.len() as u64 != expected {
            let (label, width, height, actual) = (p.label.clone(), p.width, p.height, p.rgb8.len());
            return Err(PlotError::PanelSize {
                path: path.into(),
                index,
                label,
                width,
                height,
                expected,
                actual,
            });
        }
    }
    Ok(())
}

/// Strip size, checked so that width·height fits in u32 (plotters and PNG
/// both index pixels with u32).
fn strip_size(path: &Path, panels: &[Panel]) -> Result<(u32, u32), PlotError> {
    let gaps = u64::from(STRIP_GAP) * (panels.len() as u64 - 1);
    let w = panels.iter().map(|p| u64::from(p.width)).sum::<u64>() + gaps;
    let h = u64::from(STRIP_CAPTION_HEIGHT)
        + panels
            .iter()
            .map(|p| u64::from(p.height))
            .max()
            .unwrap_or(0);
    let fits = w > 0 && w.checked_mul(h).is_some_and(|px| px <= u64::from(u32::MAX));
    match (fits, u32::try_from(w), u32::try_from(h)) {
        (true, Ok(w32), Ok(h32)) => Ok((w32, h32)),
        _ => Err(PlotError::BadSize {
            path: path.into(),
            width: w,
            height: h,
        }),
    }
}

/// Copies a panel's rows into the strip buffer at (x0, y0).
fn blit(buf: &mut [u8], strip_w: u32, p: &Panel, x0: u32, y0: u32) {
    let row_bytes = p.width as usize * 3;
    if row_bytes == 0 {
        return;
    }
    for (y, row) in p.rgb8.chunks_exact(row_bytes).enumerate() {
        let start = ((y0 as usize + y) * strip_w as usize + x0 as usize) * 3;
        buf[start..start + row_bytes].copy_from_slice(row);
    }
}

/// Renders each caption centred above its panel, straight into the buffer.
fn draw_captions(buf: &mut [u8], size: (u32, u32), panels: &[Panel]) -> Result<(), String> {
    let backend =
        BitMapBackend::<RGBPixel>::with_buffer_and_format(buf, size).map_err(|e| e.to_string())?;
    let root = backend.into_drawing_area();
    let style = TextStyle::from((FONT, 18).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
    let mut x0 = 0i32;
    for p in panels {
        let centre = (x0 + p.width as i32 / 2, STRIP_CAPTION_HEIGHT as i32 / 2);
        root.draw_text(&p.label, &style, centre)
            .map_err(|e| e.to_string())?;
        x0 += (p.width + STRIP_GAP) as i32;
    }
    root.present().map_err(|e| e.to_string())
}

fn encode_png(path: &Path, rgb: &[u8], (w, h): (u32, u32)) -> Result<(), PlotError> {
    let io = |source| PlotError::Io {
        path: path.into(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let encode = |source| PlotError::Encode {
        path: path.into(),
        source,
    };
    let mut writer = enc.write_header().map_err(encode)?;
    writer.write_image_data(rgb).map_err(encode)?;
    writer.finish().map_err(encode)
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

struct LinesFig<'a> {
    title: &'a str,
    series: &'a [Series],
}

impl Figure for LinesFig<'_> {
    fn title(&self) -> &str {
        self.title
    }

    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let Some((lo, hi)) =
            finite_bounds(self.series.iter().flat_map(|s| s.values.iter().copied()))
        else {
            return no_data(area);
        };
        let (y0, y1) = linear_range(lo, hi, true);
        let frames = self
            .series
            .iter()
            .map(|s| s.values.len())
            .max()
            .unwrap_or(1);
        let x1 = frames.saturating_sub(1).max(1) as f64;
        let (w, _) = area.dim_in_pixel();
        let (plot, legend) = area.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("frame")
            .y_desc("fps")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .label_style(axis_font())
            .axis_desc_style(axis_font())
            .draw()?;
        // Regular runs are drawn last so they stay on top of the foveated ones.
        let mut order: Vec<usize> = (0..self.series.len()).collect();
        order.sort_by_key(|&i| mode_color(&self.series[i].label, i).0 == BLACK);
        for i in order {
            let s = &self.series[i];
            let style = line_style(&s.label, i);
            let points = s.values.iter().enumerate().map(|(x, &y)| (x as f64, y));
            for run in runs(points, |p| p.1.is_finite()) {
                if run.len() == 1 {
                    chart.draw_series(run.iter().map(|&p| Circle::new(p, 3, style.filled())))?;
                } else {
                    chart.draw_series(LineSeries::new(run, style))?;
                }
            }
        }
        let entries: Vec<_> = self
            .series
            .iter()
            .enumerate()
            .map(|(i, s)| (s.label.clone(), line_style(&s.label, i)))
            .collect();
        draw_legend(&legend, &entries)
    }
}

struct DotsFig<'a> {
    title: &'a str,
    x_label: &'a str,
    items: &'a [DotWhisker],
}

/// The whisker half-length drawn for an item: |std|, or 0 if not finite.
fn half_whisker(it: &DotWhisker) -> f64 {
    if it.std.is_finite() {
        it.std.abs()
    } else {
        0.0
    }
}

/// Writes each item's label right-aligned left of its row, in `area`'s pixels.
fn draw_row_labels<DB: DrawingBackend, CT: CoordTranslate<From = (f64, f64)>>(
    area: &DrawingArea<DB, Shift>,
    plot: &DrawingArea<DB, CT>,
    items: &[DotWhisker],
    (x0, row_y): (f64, impl Fn(usize) -> f64),
) -> DrawResult<DB> {
    let style = TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Right, VPos::Center));
    let base = area.get_base_pixel();
    for (i, it) in items.iter().enumerate() {
        let (px, py) = plot.map_coordinate(&(x0, row_y(i)));
        area.draw_text(&it.label, &style, (px - 8 - base.0, py - base.1))?;
    }
    Ok(())
}

impl Figure for DotsFig<'_> {
    fn title(&self) -> &str {
        self.title
    }

    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let ends = self
            .items
            .iter()
            .flat_map(|it| [it.mean - half_whisker(it), it.mean + half_whisker(it)]);
        let Some((lo, hi)) = finite_bounds(ends) else {
            return no_data(area);
        };
        let (x0, x1) = linear_range(lo, hi, true);
        let n = self.items.len();
        // Row i is drawn at y = n-1-i so the first item is on top.
        let row_y = |i: usize| (n - 1 - i) as f64;
        let longest = self.items.iter().map(|it| it.label.chars().count()).max();
        let label_w = (longest.unwrap_or(0) as u32 * 8 + 20).clamp(60, 320);
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(label_w)
            .build_cartesian_2d(x0..x1, -0.5..n as f64 - 0.5)?;
        // Rows are categories, not numbers: no numeric y ticks; the labels
        // are drawn by hand (plotters' custom key points lack a formatter for f64).
        chart
            .configure_mesh()
            .x_desc(self.x_label)
            .y_labels(0)
            .disable_y_mesh()
            .label_style(axis_font())
            .axis_desc_style(axis_font())
            .draw()?;
        let guide = RGBColor(220, 220, 220).stroke_width(1);
        for i in 0..n {
            chart.draw_series([PathElement::new(
                vec![(x0, row_y(i)), (x1, row_y(i))],
                guide,
            )])?;
        }
        draw_row_labels(area, chart.plotting_area(), self.items, (x0, row_y))?;
        let style = BLACK.stroke_width(2);
        for (i, it) in self
            .items
            .iter()
            .enumerate()
            .filter(|(_, it)| it.mean.is_finite())
        {
            let (y, s) = (row_y(i), half_whisker(it));
            let cap =
                |x: f64| EmptyElement::at((x, y)) + PathElement::new(vec![(0, -6), (0, 6)], style);
            chart.draw_series([PathElement::new(
                vec![(it.mean - s, y), (it.mean + s, y)],
                style,
            )])?;
            chart.draw_series([cap(it.mean - s), cap(it.mean + s)])?;
            chart.draw_series([Circle::new(
                (it.mean, y),
                5,
                mode_color(&it.label, i).0.filled(),
            )])?;
        }
        Ok(())
    }
}

struct ErrorFig<'a> {
    title: &'a str,
    y_label: &'a str,
    curves: &'a [Curve],
}

/// Values a log axis accepts. Bounded because plotters' log key-point search
/// loops about log10(max/min) times: an unbounded ratio (e.g. 1e-308 to 1e308
/// overflows to ∞) would hang it.
const LOG_LIMITS: std::ops::RangeInclusive<f64> = 1e-100..=1e100;

/// Whether a point can be placed on log-log axes.
fn loggable(p: &CurvePoint) -> bool {
    LOG_LIMITS.contains(&p.ms) && LOG_LIMITS.contains(&p.error)
}

/// Compact tick label for log axes, whose ticks span decades.
fn log_tick(v: &f64) -> String {
    let a = v.abs();
    if (0.01..1e4).contains(&a) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

impl Figure for ErrorFig<'_> {
    fn title(&self) -> &str {
        self.title
    }

    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let valid = || {
            self.curves
                .iter()
                .flat_map(|c| c.points.iter().filter(|p| loggable(p)))
        };
        let (Some((xl, xh)), Some((yl, yh))) = (
            finite_bounds(valid().map(|p| p.ms)),
            finite_bounds(valid().map(|p| p.error)),
        ) else {
            return no_data(area);
        };
        let ((x0, x1), (y0, y1)) = (log_range(xl, xh), log_range(yl, yh));
        let (w, _) = area.dim_in_pixel();
        let (plot, legend) = area.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(65)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("GPU time (ms)")
            .y_desc(self.y_label)
            .x_label_formatter(&log_tick)
            .y_label_formatter(&log_tick)
            .label_style(axis_font())
            .axis_desc_style(axis_font())
            .draw()?;
        let mut entries = Vec::new();
        for (i, c) in self.curves.iter().enumerate() {
            let color = mode_color(&c.label, i).0;
            let style = color.stroke_width(2);
            entries.push((c.label.clone(), style));
            for run in runs(c.points.iter().copied(), loggable) {
                chart.draw_series(LineSeries::new(run.iter().map(|p| (p.ms, p.error)), style))?;
            }
            let text = TextStyle::from((FONT, 12).into_font()).color(&color);
            chart.draw_series(c.points.iter().filter(|p| loggable(p)).map(|p| {
                EmptyElement::at((p.ms, p.error))
                    + Circle::new((0, 0), 4, style.filled())
                    + Text::new(p.spp.to_string(), (6, -16), text.clone())
            }))?;
        }
        draw_legend(&legend, &entries)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh, unique directory under the system temp dir.
    fn temp_dir(name: &str) -> PathBuf {
        static N: AtomicUsize = AtomicUsize::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("fovea-plots-{}-{name}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
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
        let _ = std::fs::remove_dir_all(dir);
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
        let _ = std::fs::remove_dir_all(dir);
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
        let _ = std::fs::remove_dir_all(dir);
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
        let _ = std::fs::remove_dir_all(dir);
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
        let _ = std::fs::remove_dir_all(dir);
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
        let _ = std::fs::remove_dir_all(dir);
    }
}
