//! SVG figures (plotters, SVG backend only): the comparison bars (paper Fig. 8), the
//! surprise trace (Figs. 6-7), the test-time learning curves (Fig. 9) and the
//! top-down filmstrip of an episode.

use anyhow::{Result, anyhow};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

use crate::report::write_atomic;

/// Renders into an SVG string with `draw`, then writes it atomically.
pub fn write_svg(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<()>,
) -> Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        draw(&root)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    write_atomic(path, svg.as_bytes())
}

/// Turns any plotters error into an anyhow error.
pub fn plot_err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("plotting failed: {e:?}")
}

/// A chart on the SVG backend with `f64` axes, as every figure here draws.
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws the legend of the labelled series (bordered box, translucent white) at `pos`.
fn draw_legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, pos: SeriesLabelPosition) -> Result<()> {
    chart
        .configure_series_labels()
        .position(pos)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()
        .map_err(plot_err)
}

/// One panel of grouped bars: for each label, our value and optionally the paper's.
pub struct BarPanel<'a> {
    /// Panel title.
    pub title: &'a str,
    /// Group labels (methods).
    pub labels: &'a [String],
    /// Our measured values (means over agents).
    pub ours: Vec<f64>,
    /// A 95% interval around each of our values, drawn as a whisker (None: no whisker).
    pub interval: Vec<Option<(f64, f64)>>,
    /// The paper's values, where it reports one.
    pub paper: Vec<Option<f64>>,
}

/// A titled row of panels (e.g. one protocol).
pub struct BarRow<'a> {
    /// Row title, drawn above its panels.
    pub title: String,
    /// The panels, left to right.
    pub panels: Vec<BarPanel<'a>>,
}

/// Grouped bar charts (Fig. 8): one row per entry of `rows`, one panel per metric, ours
/// (blue, with interval whiskers) beside the paper's (grey). The key goes in the row
/// titles, not in legends that would cover the bars.
pub fn grouped_bars(path: &Path, rows: &[BarRow<'_>]) -> Result<()> {
    let columns = rows.iter().map(|r| r.panels.len()).max().unwrap_or(1).max(1);
    let width = 330 * columns as u32;
    let height = 410 * rows.len().max(1) as u32;
    write_svg(path, (width.max(400), height), |root| {
        let areas = root.split_evenly((rows.len().max(1), 1));
        for (area, row) in areas.iter().zip(rows) {
            let titled = area.titled(&row.title, ("sans-serif", 18)).map_err(plot_err)?;
            let cells = titled.split_evenly((1, columns));
            for (cell, panel) in cells.iter().zip(&row.panels) {
                bar_panel(cell, panel)?;
            }
        }
        Ok(())
    })
}

/// Draws one panel of [`grouped_bars`].
fn bar_panel(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, panel: &BarPanel<'_>) -> Result<()> {
    let whisker_ends = panel.interval.iter().flatten().flat_map(|&(lo, hi)| [lo, hi]);
    let values = panel
        .ours
        .iter()
        .copied()
        .chain(panel.paper.iter().flatten().copied())
        .chain(whisker_ends)
        .filter(|v| v.is_finite());
    let (lo, hi) = values.fold((0.0f64, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let pad = ((hi - lo) * 0.1).max(1e-3);
    let n = panel.labels.len();
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(30)
        .y_label_area_size(45)
        .build_cartesian_2d(
            -0.5f64..(n as f64 - 0.5),
            (lo - if lo < 0.0 { pad } else { 0.0 })..(hi + pad),
        )
        .map_err(plot_err)?;
    let labels = panel.labels.to_vec();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&move |x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                labels.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .draw()
        .map_err(plot_err)?;
    let ours = panel.ours.iter().enumerate().map(|(i, &v)| {
        let x = i as f64;
        Rectangle::new([(x - 0.38, 0.0), (x, v)], BLUE.mix(0.75).filled())
    });
    chart.draw_series(ours).map_err(plot_err)?;
    let whiskers = panel.interval.iter().enumerate().filter_map(|(i, w)| {
        w.map(|(lo, hi)| {
            let x = i as f64 - 0.19;
            PathElement::new(
                vec![
                    (x - 0.08, lo),
                    (x + 0.08, lo),
                    (x, lo),
                    (x, hi),
                    (x - 0.08, hi),
                    (x + 0.08, hi),
                ],
                BLACK.stroke_width(2),
            )
        })
    });
    chart.draw_series(whiskers).map_err(plot_err)?;
    let paper = panel.paper.iter().enumerate().filter_map(|(i, v)| {
        v.map(|v| {
            let x = i as f64;
            Rectangle::new([(x, 0.0), (x + 0.38, v)], BLACK.mix(0.3).filled())
        })
    });
    chart.draw_series(paper).map_err(plot_err)?;
    Ok(())
}

/// One line of a line chart.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBColor,
}

/// A stack of line charts sharing the x axis (one per entry), e.g. Fig. 9's curves.
pub fn line_panels(path: &Path, x_label: &str, panels: &[(&str, Vec<Series<'_>>)]) -> Result<()> {
    let height = 260 * panels.len() as u32;
    write_svg(path, (800, height.max(300)), |root| {
        let areas = root.split_evenly((panels.len(), 1));
        for (area, (title, series)) in areas.iter().zip(panels) {
            let xs = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
            let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
            let (x0, x1) = min_max(xs);
            // Fitted to the data; a single x value gets a unit-wide axis.
            let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
            let (y0, y1) = min_max(ys);
            let ypad = ((y1 - y0) * 0.08).max(1e-3);
            let mut chart = ChartBuilder::on(area)
                .caption(*title, ("sans-serif", 16))
                .margin(10)
                .x_label_area_size(30)
                .y_label_area_size(55)
                .build_cartesian_2d(x0..x1, (y0 - ypad)..(y1 + ypad))
                .map_err(plot_err)?;
            chart.configure_mesh().x_desc(x_label).draw().map_err(plot_err)?;
            for s in series {
                let color = s.color;
                chart
                    .draw_series(LineSeries::new(s.points.iter().copied(), color.stroke_width(2)))
                    .map_err(plot_err)?
                    .label(s.label)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 14, y)], color.stroke_width(2)));
            }
            draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
        }
        Ok(())
    })
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) }
}

/// Normalized surprise theta against the threshold epsilon over an episode, with the
/// reasoning ticks shaded (paper Figs. 6-7). `ticks` are (step, theta, reasoned, action label).
pub fn theta_trace(path: &Path, title: &str, ticks: &[(u32, Option<f64>, bool, String)], epsilon: f64) -> Result<()> {
    // A method that measures no surprise (q-learning) gets no theta curve, not a curve at 0.
    let measured = ticks.iter().any(|t| t.1.is_some());
    let title = if measured {
        title.to_string()
    } else {
        format!("{title} (this method measures no surprise)")
    };
    write_svg(path, (900, 380), |root| {
        let n = ticks.iter().map(|t| t.0).max().unwrap_or(0) as f64 + 1.0;
        let mut chart = ChartBuilder::on(root)
            .caption(&title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(35)
            .y_label_area_size(45)
            .build_cartesian_2d(-0.5f64..(n + 0.3), 0.0f64..1.25)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("decision tick")
            .y_desc("theta = 1 - exp(-Omega S)")
            .draw()
            .map_err(plot_err)?;
        let shade = RGBColor(255, 200, 60).mix(0.35);
        chart
            .draw_series(
                ticks
                    .iter()
                    .filter(|t| t.2)
                    .map(|t| Rectangle::new([(t.0 as f64 - 0.5, 0.0), (t.0 as f64 + 0.5, 1.05)], shade.filled())),
            )
            .map_err(plot_err)?
            .label("reasoning tick")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 10, y + 5)], shade.filled()));
        chart
            .draw_series(LineSeries::new(
                [(-0.5, epsilon), (n - 0.5, epsilon)],
                RED.stroke_width(1),
            ))
            .map_err(plot_err)?
            .label(format!("epsilon = {epsilon}"))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], RED));
        if measured {
            let points = ticks.iter().filter_map(|t| t.1.map(|th| (t.0 as f64, th)));
            chart
                .draw_series(LineSeries::new(points, BLUE.stroke_width(2)).point_size(3))
                .map_err(plot_err)?
                .label("theta")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], BLUE.stroke_width(2)));
        }
        chart
            .draw_series(
                ticks
                    .iter()
                    // Actions above the plot, on two alternating rows so neighbours never touch.
                    .map(|t| {
                        let y = if t.0 % 2 == 0 { 1.21 } else { 1.13 };
                        Text::new(t.3.clone(), (t.0 as f64 - 0.35, y), ("sans-serif", 10))
                    }),
            )
            .map_err(plot_err)?;
        draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
        Ok(())
    })
}

/// Top-down filmstrip of an episode: one strip per decision tick showing the road,
/// the crosswalk, the light's colour, the car and the pedestrians.
pub fn filmstrip(path: &Path, map: &unforeseen_sim::Map, ticks: &[crate::runner::Tick]) -> Result<()> {
    use unforeseen_sim::LightPhase;
    let road_half = f64::from(map.road.lanes) * map.road.lane_width / 2.0;
    let y_span = road_half + map.road.sidewalk_width;
    let car_y = -road_half + map.road.lane_width / 2.0;
    let x0 = map.vehicle.start_x - map.vehicle.length - 2.0;
    let x1 = map.road.goal_x + 4.0;
    let strip = 56u32;
    let height = strip * ticks.len().max(1) as u32;
    write_svg(path, (1000, height), |root| {
        let rows = root.split_evenly((ticks.len().max(1), 1));
        for (area, t) in rows.iter().zip(ticks) {
            let mut chart = ChartBuilder::on(area)
                .margin(2)
                .y_label_area_size(70)
                .build_cartesian_2d(x0..x1, -y_span..y_span)
                .map_err(plot_err)?;
            let label = format!(
                "t={} d{} v{} L{} p{}",
                t.step, t.state.d, t.state.v, t.state.l, t.state.p
            );
            let grey = RGBColor(205, 205, 205);
            let walk = RGBColor(235, 235, 235);
            chart
                .draw_series([
                    Rectangle::new([(x0, -y_span), (x1, y_span)], RGBColor(190, 225, 180).filled()),
                    Rectangle::new([(x0, -road_half), (x1, road_half)], grey.filled()),
                    Rectangle::new(
                        [
                            (map.crosswalk.x - map.crosswalk.width / 2.0, -road_half),
                            (map.crosswalk.x + map.crosswalk.width / 2.0, road_half),
                        ],
                        walk.filled(),
                    ),
                    Rectangle::new(
                        [(map.road.goal_x - 0.3, -road_half), (map.road.goal_x, road_half)],
                        BLACK.filled(),
                    ),
                ])
                .map_err(plot_err)?;
            let light = match t.snapshot.light {
                LightPhase::Green => GREEN,
                LightPhase::Amber => RGBColor(255, 170, 0),
                LightPhase::Red => RED,
            };
            let s = &t.snapshot;
            let car = Rectangle::new(
                [
                    (s.car_x - map.vehicle.length, car_y - map.vehicle.width / 2.0),
                    (s.car_x, car_y + map.vehicle.width / 2.0),
                ],
                if t.reasoned {
                    RGBColor(230, 140, 0).filled()
                } else {
                    BLUE.filled()
                },
            );
            chart
                .draw_series([Circle::new(
                    (map.crosswalk.x - map.crosswalk.width, -road_half - 1.0),
                    5,
                    light.filled(),
                )])
                .map_err(plot_err)?;
            chart.draw_series([car]).map_err(plot_err)?;
            chart
                .draw_series(s.pedestrians.iter().map(|p| Circle::new((p.x, p.y), 4, BLACK.filled())))
                .map_err(plot_err)?;
            chart
                .draw_series([Text::new(label, (x0 + 0.5, y_span - 1.0), ("sans-serif", 11))])
                .map_err(plot_err)?;
        }
        Ok(())
    })
}
