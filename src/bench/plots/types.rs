//! What the charts take and how they fail: the data of each chart, the panels of an image
//! strip, and [`PlotError`].

use std::path::PathBuf;

/// Height of the caption band above the panels of [`image_strip`](super::image_strip).
pub const STRIP_CAPTION_HEIGHT: u32 = 28;
/// White gap between two panels of [`image_strip`](super::image_strip) (none at the outer
/// edges).
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

/// One line of [`frame_rate_lines`](super::frame_rate_lines): per-frame fps of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text; its prefix picks the colour ("regular", "forward", "corner").
    pub label: String,
    pub values: Vec<f64>,
}

/// One row of [`mean_std_dots`](super::mean_std_dots).
#[derive(Clone, Debug, PartialEq)]
pub struct DotWhisker {
    pub label: String,
    pub mean: f64,
    pub std: f64,
}

/// One measured point of [`error_vs_time`](super::error_vs_time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// GPU time in milliseconds (x, log scale).
    pub ms: f64,
    /// Error against the reference (y, log scale).
    pub error: f64,
    /// Samples per pixel, written next to the point.
    pub spp: u32,
}

/// One line of [`error_vs_time`](super::error_vs_time).
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub label: String,
    pub points: Vec<CurvePoint>,
}

/// One image of [`image_strip`](super::image_strip): 8-bit RGB, row-major, 3 bytes per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub label: String,
    pub width: u32,
    pub height: u32,
    pub rgb8: Vec<u8>,
}

/// What [`jod_vs_time`](super::jod_vs_time) draws.
pub struct JodChart<'a> {
    pub title: &'a str,
    /// Lines through labelled points (`spp` written beside each, none when 0); `error` is
    /// the JOD. The label's first word picks the colour as in
    /// [`error_vs_time`](super::error_vs_time).
    pub curves: &'a [Curve],
    /// Other measured points, (ms, JOD), drawn as grey dots.
    pub scatter: &'a [(f64, f64)],
    /// A vertical line at this GPU time.
    pub budget_ms: Option<f64>,
    /// A point to ring, (ms, JOD).
    pub chosen: Option<(f64, f64)>,
}
