//! The log-log plot of error against time (SVG).

use super::report::{sig, slope_text};
use super::*;

/// Line colours, one per [`Configuration`] in order (colour-blind-friendly, after Okabe and Ito).
pub(super) const PLOT_COLOURS: [(u8, u8, u8); 8] = [
    (0, 0, 0),
    (0, 114, 178),
    (213, 94, 0),
    (0, 158, 115),
    (204, 121, 167),
    (86, 180, 233),
    (230, 159, 0),
    (240, 228, 66),
];

/// The marker of the `i`-th configuration, as pixel offsets: circle, triangle, square, diamond, ...
pub(super) fn marker_shape(i: usize) -> Vec<(i32, i32)> {
    let (sides, radius, turn) = match i % 4 {
        0 => (12, 3.5, 0.0),
        1 => (3, 5.0, -0.25),
        2 => (4, 4.5, 0.125),
        _ => (4, 5.0, 0.0),
    };
    (0..sides)
        .map(|k| {
            let a = std::f64::consts::TAU * (k as f64 / sides as f64 + turn);
            ((radius * a.cos()).round() as i32, (radius * a.sin()).round() as i32)
        })
        .collect()
}

/// One line of the plot.
pub(super) struct PlotSeries {
    label: String,
    configuration: usize,
    points: Vec<(f64, f64)>,
}

/// Draws the log-log plot of error against time (SVG): the per-pixel relative error (`relmse`,
/// the renderer's default measure) of every sweep point, one panel per scene, one line per
/// configuration (colour by configuration, the same in every panel, with its fitted slope), a
/// dashed line of slope -1/2.
///
/// # Errors
/// A message if the file cannot be written.
pub fn write_plot(report: &AccuracyReport, path: &Path) -> Result<(), String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| format!("{}: plot: {e}", path.display());
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| err(&e))?;
    }
    let panels = report.scenes.len().max(1);
    let cols = panels.min(2);
    let rows = panels.div_ceil(cols);
    let size = (560 * cols as u32, 60 + 400 * rows as u32);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(
            "Spectrace: per-pixel relative error (relmse) against wall time",
            ("sans-serif", 22),
        )
        .map_err(|e| err(&e))?;
    let areas = root.split_evenly((rows, cols));
    for (scene, area) in report.scenes.iter().zip(&areas) {
        let series: Vec<PlotSeries> = scene
            .configurations
            .iter()
            .filter(|c| !c.points.is_empty())
            .map(|c| {
                let points: Vec<(f64, f64)> = c
                    .points
                    .iter()
                    .filter(|p| p.seconds > 0.0 && p.relmse > 0.0)
                    .map(|p| (p.seconds, p.relmse))
                    .collect();
                let logs: Vec<(f64, f64)> = points.iter().map(|(t, e)| (t.ln(), e.ln())).collect();
                PlotSeries {
                    label: format!(
                        "{} (slope {})",
                        c.configuration.name(),
                        slope_text(fit_slope(&logs))
                    ),
                    configuration: Configuration::ALL
                        .iter()
                        .position(|&k| k == c.configuration)
                        .unwrap_or_default(),
                    points,
                }
            })
            .collect();
        draw_panel(area, &scene.name, &series).map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// One scene's panel of [`write_plot`].
pub(super) fn draw_panel<DB: plotters::prelude::DrawingBackend>(
    area: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    series: &[PlotSeries],
) -> Result<(), String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| format!("panel {title}: {e}");
    let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.iter().copied()).collect();
    let bounds = |f: fn(&(f64, f64)) -> f64| {
        let lo = all.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = all.iter().map(f).fold(0.0, f64::max);
        if lo.is_finite() && hi > lo { (lo / 1.5, hi * 1.5) } else { (1e-3, 1.0) }
    };
    let (x0, x1) = bounds(|p| p.0);
    let (y0, y1) = bounds(|p| p.1);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(56)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("wall time of the render (s)")
        .y_desc("relative RMSE of XYZ")
        .light_line_style(BLACK.mix(0.05))
        .max_light_lines(4)
        .x_label_formatter(&|x| sig(*x))
        .y_label_formatter(&|y| {
            let text = sig(*y * 100.0);
            let text = if text.contains('.') {
                text.trim_end_matches('0').trim_end_matches('.')
            } else {
                &text
            };
            format!("{text}%")
        })
        .draw()
        .map_err(|e| err(&e))?;
    for PlotSeries { label, configuration: ci, points } in series {
        let (r, g, b) = PLOT_COLOURS[ci % PLOT_COLOURS.len()];
        let color = RGBColor(r, g, b);
        let marker = marker_shape(*ci);
        let legend_marker = marker.clone();
        chart
            .draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(label.clone())
            .legend(move |(x, y)| {
                EmptyElement::at((x + 10, y))
                    + PathElement::new(vec![(-10, 0), (10, 0)], color.stroke_width(2))
                    + Polygon::new(legend_marker.clone(), color.filled())
            });
        chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| EmptyElement::at(p) + Polygon::new(marker.clone(), color.filled())),
            )
            .map_err(|e| err(&e))?;
    }
    if !all.is_empty() {
        // Slope -1/2 through the geometric centre of the data.
        let n = all.len() as f64;
        let cx = (all.iter().map(|p| p.0.ln()).sum::<f64>() / n).exp();
        let cy = (all.iter().map(|p| p.1.ln()).sum::<f64>() / n).exp();
        let line = [x0, x1].map(|x| (x, cy * (x / cx).powf(EXPECTED_SLOPE)));
        chart
            .draw_series(DashedLineSeries::new(line, 8, 6, BLACK.stroke_width(1)))
            .map_err(|e| err(&e))?
            .label("slope -1/2 (Monte Carlo)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
    }
    // The error targets of the summary, where they fall inside the panel.
    let targets: Vec<f64> = TARGETS.into_iter().filter(|t| (y0..=y1).contains(t)).collect();
    for (k, &target) in targets.iter().enumerate() {
        let series = chart
            .draw_series(DashedLineSeries::new(
                [(x0, target), (x1, target)],
                2,
                4,
                BLACK.mix(0.5).stroke_width(1),
            ))
            .map_err(|e| err(&e))?;
        if k == 0 {
            series.label("10% and 2% targets").legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5).stroke_width(1))
            });
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 11))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    Ok(())
}
