//! The chart behind [`jod_vs_time`](super::jod_vs_time): perceptual quality (JOD, linear)
//! against GPU time (linear, from zero), the measured curves as lines with their points labelled, the
//! other measured points as grey dots, the time budget as a vertical line and the chosen
//! point ringed.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::canvas::{no_data, DrawResult, Figure, FONT};
use super::style::{
    axis_font, draw_legend, finite_bounds, linear_range, mode_color, runs, LEGEND_WIDTH,
};
use super::types::JodChart;

pub(super) struct JodFig<'a>(pub(super) &'a JodChart<'a>);

fn placeable(ms: f64, jod: f64) -> bool {
    ms.is_finite() && ms > 0.0 && jod.is_finite()
}

impl Figure for JodFig<'_> {
    fn title(&self) -> &str {
        self.0.title
    }

    fn body<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let c = self.0;
        let points = || {
            let curves = c
                .curves
                .iter()
                .flat_map(|k| k.points.iter().map(|p| (p.ms, p.error)));
            curves
                .chain(c.scatter.iter().copied())
                .filter(|&(ms, jod)| placeable(ms, jod))
        };
        let (Some((xl, xh)), Some((yl, yh))) = (
            finite_bounds(points().map(|p| p.0).chain(c.budget_ms)),
            finite_bounds(points().map(|p| p.1)),
        ) else {
            return no_data(area);
        };
        // Linear time from zero: ratios of cost read as they are.
        let ((x0, x1), (y0, y1)) = (linear_range(xl, xh, true), linear_range(yl, yh, false));
        let (w, _) = area.dim_in_pixel();
        let (plot, legend) = area.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("GPU time (ms)")
            .y_desc("JOD (10 = as the reference)")
            .label_style(axis_font())
            .axis_desc_style(axis_font())
            .draw()?;
        let mut entries = Vec::new();
        let grey = RGBColor(160, 160, 160);
        if !c.scatter.is_empty() {
            entries.push(("other configs".to_string(), grey.filled()));
            chart.draw_series(
                (c.scatter.iter().filter(|p| placeable(p.0, p.1)))
                    .map(|&p| Circle::new(p, 3, grey.filled())),
            )?;
        }
        if let Some(budget) = c.budget_ms.filter(|b| b.is_finite() && *b > 0.0) {
            let style = RGBColor(90, 90, 90).stroke_width(1);
            entries.push((format!("budget {budget:.3} ms"), style));
            chart.draw_series(DashedLineSeries::new(
                [(budget, y0), (budget, y1)],
                6,
                4,
                style,
            ))?;
        }
        for (i, curve) in c.curves.iter().enumerate() {
            let color = mode_color(&curve.label, i).0;
            let style = color.stroke_width(2);
            entries.push((curve.label.clone(), style));
            for run in runs(curve.points.iter().copied(), |p| placeable(p.ms, p.error)) {
                chart.draw_series(LineSeries::new(run.iter().map(|p| (p.ms, p.error)), style))?;
            }
            let text = TextStyle::from((FONT, 12).into_font()).color(&color);
            chart.draw_series(
                (curve.points.iter().filter(|p| placeable(p.ms, p.error))).map(|p| {
                    let label = match p.spp {
                        0 => String::new(),
                        spp => format!("{spp}"),
                    };
                    EmptyElement::at((p.ms, p.error))
                        + Circle::new((0, 0), 4, style.filled())
                        + Text::new(label, (6, -16), text.clone())
                }),
            )?;
        }
        if let Some((ms, jod)) = c.chosen.filter(|p| placeable(p.0, p.1)) {
            let style = BLACK.stroke_width(2);
            entries.push(("chosen".to_string(), style));
            chart.draw_series([Circle::new((ms, jod), 9, style)])?;
        }
        draw_legend(&legend, &entries)
    }
}
