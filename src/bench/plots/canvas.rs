//! Drawing one chart on both backends: the [`Figure`] every chart is, the embedded font,
//! and the SVG + PNG pair each chart function writes.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use super::types::PlotError;

/// Pixel size of every chart.
pub(super) const SIZE: (u32, u32) = (900, 500);
/// Font family registered with the embedded DejaVu Sans.
pub(super) const FONT: &str = "sans-serif";

pub(super) type DrawResult<DB> =
    Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A chart drawable on any backend, so SVG and PNG share one routine.
pub(super) trait Figure {
    fn title(&self) -> &str;
    /// Draws everything below the title into `area`.
    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// Registers DejaVu Sans as "sans-serif" once per process.
pub(super) fn ensure_font(path: &Path) -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok());
    ok.then_some(())
        .ok_or_else(|| PlotError::Font { path: path.into() })
}

pub(super) fn create_parent(path: &Path) -> Result<(), PlotError> {
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
pub(super) fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    s.into()
}

/// Draws `fig` once on an SVG and once on a PNG backend.
pub(super) fn write_both(stem: &Path, fig: &impl Figure) -> Result<Vec<PathBuf>, PlotError> {
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

pub(super) fn no_data<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 20).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text("no data", &style, (w as i32 / 2, h as i32 / 2))
}
