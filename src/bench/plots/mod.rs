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
//!
//! One direction: this file is the entry (the chart functions); `figures`, `jod_fig` and
//! `strip` draw; what they share is below them: `types` (what a chart takes), `canvas` (the
//! figure, font and files) and `style` (axes, colours, legend).

mod canvas;
mod figures;
mod jod_fig;
mod strip;
mod style;
#[cfg(test)]
mod tests;
mod types;

use std::path::{Path, PathBuf};

use canvas::write_both;
use figures::{DotsFig, ErrorFig, LinesFig};
use jod_fig::JodFig;
pub use strip::{animated_strip, image_strip};
pub use types::{
    Curve, CurvePoint, DotWhisker, JodChart, Panel, PlotError, Series, STRIP_CAPTION_HEIGHT,
    STRIP_GAP,
};

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

/// Perceptual quality against run time: x = GPU ms, y = JOD, both linear. Returns the
/// files written.
pub fn jod_vs_time(stem: &Path, chart: &JodChart) -> Result<Vec<PathBuf>, PlotError> {
    write_both(stem, &JodFig(chart))
}
