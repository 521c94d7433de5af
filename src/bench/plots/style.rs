//! What every chart's axes and lines look like: ranges that skip non-finite values and
//! never collapse, the thesis' mode colours, gaps in lines, and the legend column.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::{DrawResult, FONT};

/// Width of the legend column right of a chart.
pub(super) const LEGEND_WIDTH: u32 = 180;

/// Finite (min, max) of `values`, or `None` if there is no finite value.
pub(super) fn finite_bounds(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
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
pub(super) fn linear_range(lo: f64, hi: f64, from_zero: bool) -> (f64, f64) {
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
pub(super) fn log_range(lo: f64, hi: f64) -> (f64, f64) {
    let pad = if hi / lo < 1.0 + 1e-9 { 2.0 } else { 1.25 };
    (lo / pad, hi * pad)
}

/// Colours for labels without a mode prefix; black, red and blue are avoided.
pub(super) const PALETTE: [RGBColor; 6] = [
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
pub(super) fn mode_color(label: &str, index: usize) -> (RGBColor, bool) {
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

/// Line style for [`frame_rate_lines`](super::frame_rate_lines): foveated runs thinner and lighter so
/// the (fewer) regular lines stay readable among ~20 foveated ones.
pub(super) fn line_style(label: &str, index: usize) -> ShapeStyle {
    match mode_color(label, index) {
        (c, true) => c.mix(0.55).stroke_width(1),
        (c, false) if c == BLACK => c.stroke_width(2),
        (c, false) => c.stroke_width(1),
    }
}

/// Splits `points` into runs separated by points for which `keep` fails, so
/// skipped values leave a gap instead of a misleading straight segment.
pub(super) fn runs<T: Copy>(
    points: impl IntoIterator<Item = T>,
    keep: impl Fn(&T) -> bool,
) -> Vec<Vec<T>> {
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
pub(super) fn draw_legend<DB: DrawingBackend>(
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

pub(super) fn axis_font() -> TextStyle<'static> {
    (FONT, 14).into()
}
