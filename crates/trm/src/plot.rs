//! SVG line charts for the commands' figures (plotters' SVG backend needs no system fonts).

use std::ops::Range;

use anyhow::Result;
use plotters::prelude::*;

/// One line of a chart; `None` colour = the next palette colour, `Some(BLACK)` for references.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points.
    pub points: Vec<(f64, f64)>,
    /// Colour; the palette's when absent.
    pub color: Option<RGBAColor>,
}

/// One chart panel: a title, axis labels, ranges and lines.
pub struct Panel {
    /// Caption.
    pub title: String,
    /// (x, y) axis descriptions.
    pub axes: (String, String),
    /// x range.
    pub x: Range<f64>,
    /// y range.
    pub y: Range<f64>,
    /// The lines.
    pub series: Vec<Series>,
}

/// An axis range plotters can draw: a range that is empty, reversed, narrower than a
/// millionth of its magnitude (plotters' tick search never ends on it) or not finite is
/// widened to its centre ± 5 % (± 0.5 near zero); non-finite ends become 0..1.
pub fn drawable(range: &Range<f64>) -> Range<f64> {
    let (a, b) = (range.start, range.end);
    if !(a.is_finite() && b.is_finite()) {
        return 0.0..1.0;
    }
    let (lo, hi) = (a.min(b), a.max(b));
    if hi - lo > 1e-6 * lo.abs().max(hi.abs()).max(1e-300) {
        return lo..hi;
    }
    let centre = 0.5 * (lo + hi);
    let half = (0.05 * centre.abs()).max(0.5);
    centre - half..centre + half
}

/// Panels stacked vertically (each `size` pixels), each a line chart with a legend, as an SVG
/// document.
pub fn panels(size: (u32, u32), panels: &[Panel]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (size.0, size.1 * panels.len().max(1) as u32))
            .into_drawing_area();
        root.fill(&WHITE)?;
        for (area, panel) in root
            .split_evenly((panels.len().max(1), 1))
            .iter()
            .zip(panels)
        {
            let mut chart = ChartBuilder::on(area)
                .caption(panel.title.as_str(), ("sans-serif", 16))
                .margin(12)
                .x_label_area_size(38)
                .y_label_area_size(55)
                .build_cartesian_2d(drawable(&panel.x), drawable(&panel.y))?;
            chart
                .configure_mesh()
                .x_desc(panel.axes.0.as_str())
                .y_desc(panel.axes.1.as_str())
                .draw()?;
            for (i, s) in panel.series.iter().enumerate() {
                let color = s.color.unwrap_or_else(|| Palette99::pick(i).to_rgba());
                chart
                    .draw_series(LineSeries::new(
                        s.points
                            .iter()
                            .copied()
                            .filter(|(x, y)| x.is_finite() && y.is_finite()),
                        color.stroke_width(2),
                    ))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }
        root.present()?;
    }
    Ok(svg)
}

/// A single-panel line chart with a legend, as an SVG document.
pub fn lines(
    title: &str,
    axes: (&str, &str),
    x: Range<f64>,
    y: Range<f64>,
    series: Vec<Series>,
) -> Result<String> {
    panels(
        (640, 440),
        &[Panel {
            title: title.into(),
            axes: (axes.0.into(), axes.1.into()),
            x,
            y,
            series,
        }],
    )
}

/// A 3-D scatter of points coloured by value from blue (lowest) to red (highest), with an
/// optional polyline.
pub fn scatter_points(
    title: &str,
    points: &[[f64; 3]],
    values: &[f64],
    path: Option<&[[f64; 3]]>,
) -> Result<String> {
    let range = |i: usize| {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p[i]), b.max(p[i]))
            });
        if lo.is_finite() && hi > lo {
            let pad = 0.05 * (hi - lo);
            (lo - pad)..(hi + pad)
        } else {
            -0.1..0.1
        }
    };
    let (vmin, vmax) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 700)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("{title}; colour {vmin:.3} (blue) to {vmax:.3} (red)"),
                ("sans-serif", 15),
            )
            .margin(10)
            .build_cartesian_3d(range(0), range(2), range(1))?;
        chart.with_projection(|mut p| {
            p.yaw = 0.6;
            p.pitch = 0.35;
            p.scale = 0.85;
            p.into_matrix()
        });
        chart.configure_axes().draw()?;
        chart.draw_series(points.iter().zip(values).map(|(p, v)| {
            let u = if vmax > vmin {
                (v - vmin) / (vmax - vmin)
            } else {
                0.0
            };
            let color = RGBColor((255.0 * u) as u8, 60, (255.0 * (1.0 - u)) as u8);
            Circle::new((p[0], p[2], p[1]), 3, color.filled())
        }))?;
        if let Some(path) = path {
            chart.draw_series(LineSeries::new(
                path.iter().map(|t| (t[0], t[2], t[1])),
                BLACK.stroke_width(3),
            ))?;
        }
        root.present()?;
    }
    Ok(svg)
}

/// A 3-D scatter of the task points (the first three task dimensions; fewer are padded with 0)
/// coloured by task cost, like Fig. 3 of the parallel paper; with `path`, the task-space path
/// is drawn over them.
pub fn map_scatter(map: &trm_roadmap::Roadmap, path: Option<&[Vec<f64>]>) -> Result<String> {
    let at = |t: &[f64], i: usize| t.get(i).copied().unwrap_or(0.0);
    let points: Vec<[f64; 3]> = map
        .points
        .iter()
        .map(|p| [at(&p.t, 0), at(&p.t, 1), at(&p.t, 2)])
        .collect();
    let costs: Vec<f64> = map.points.iter().map(|p| p.cost).collect();
    let path: Option<Vec<[f64; 3]>> =
        path.map(|p| p.iter().map(|t| [at(t, 0), at(t, 1), at(t, 2)]).collect());
    let title = format!("{} points, task `{}`", map.points.len(), map.task);
    scatter_points(&title, &points, &costs, path.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_reversed_and_non_finite_ranges_are_drawn_widened() {
        assert_eq!(drawable(&(2.0..2.0)), 1.5..2.5);
        assert_eq!(drawable(&(3.0..1.0)), 1.0..3.0);
        assert_eq!(drawable(&(f64::NAN..1.0)), 0.0..1.0);
        assert_eq!(drawable(&(100.0..100.0)), 95.0..105.0);
        let svg = panels(
            (300, 200),
            &[Panel {
                title: "flat".into(),
                axes: ("x".into(), "y".into()),
                x: 2.0..2.0,
                y: 0.0..0.0,
                series: vec![Series {
                    label: "one point".into(),
                    points: vec![(2.0, 0.0), (f64::NAN, 1.0)],
                    color: None,
                }],
            }],
        )
        .unwrap();
        assert!(svg.starts_with("<svg"));
    }
}
