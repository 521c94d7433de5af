//! The charts behind [`frame_rate_lines`](super::frame_rate_lines),
//! [`mean_std_dots`](super::mean_std_dots) and
//! [`error_vs_time`](super::error_vs_time), as [`Figure`]s, with their
//! drawing code.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::{no_data, DrawResult, Figure, FONT};
use super::style::{
    axis_font, draw_legend, finite_bounds, line_style, linear_range, log_range, mode_color, runs,
    LEGEND_WIDTH,
};
use super::types::{Curve, CurvePoint, DotWhisker, Series};

pub(super) struct LinesFig<'a> {
    pub(super) title: &'a str,
    pub(super) y_label: &'a str,
    pub(super) series: &'a [Series],
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
            .y_desc(self.y_label)
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

pub(super) struct DotsFig<'a> {
    pub(super) title: &'a str,
    pub(super) x_label: &'a str,
    pub(super) items: &'a [DotWhisker],
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

pub(super) struct ErrorFig<'a> {
    pub(super) title: &'a str,
    pub(super) y_label: &'a str,
    pub(super) curves: &'a [Curve],
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
