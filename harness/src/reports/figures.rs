//! SVG figures (plotters, SVG backend only): the comparison bars (paper Fig. 8), the
//! surprise trace (Figs. 6-7), the test-time learning curves (Fig. 9), the sweep panels
//! and the top-down filmstrip of an episode.
//!
//! Every key (legend) is drawn outside the plotting area, beside or above it, so it
//! never covers data; text is laid out from a generous estimate of its width
//! ([`text_width`]), and the integration tests check every figure for overlapping or
//! clipped text (`harness/tests/it/figures.rs`).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

use crate::error::Error;
use crate::files::write_atomic;

/// What the drawing functions return.
type Result<T> = std::result::Result<T, Error>;

/// A drawing area in pixels on the SVG backend.
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Renders into an SVG string with `draw`, then writes it atomically.
pub fn write_svg(path: &Path, size: (u32, u32), draw: impl FnOnce(&Area<'_>) -> Result<()>) -> Result<()> {
    write_atomic(path, render_svg(size, draw)?.as_bytes())
}

/// Renders into an SVG string with `draw`.
pub fn render_svg(size: (u32, u32), draw: impl FnOnce(&Area<'_>) -> Result<()>) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| Error::Plot { message: e.to_string() })?;
        draw(&root)?;
        root.present().map_err(|e| Error::Plot { message: e.to_string() })?;
    }
    Ok(svg)
}

/// Turns any plotters error into an [`Error::Plot`].
pub fn plot_err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Plot {
        message: format!("plotting failed: {e:?}"),
    }
}

/// Font size of keys and small labels (plotters' size; the SVG gets size / 1.24).
const KEY_FONT: f64 = 13.0;
/// Height of one key row, px.
const KEY_ROW: i32 = 17;

/// An estimate of the width in pixels of `text` drawn at plotters font size `size`
/// (plotters writes `size / 1.24` into the SVG; a sans-serif glyph of running text
/// averages about 0.55 em, 0.6 em with capitals and digits).
pub fn text_width(text: &str, size: f64) -> f64 {
    0.6 * size / 1.24 * text.chars().count() as f64
}

/// A tick label: at most three decimals, without trailing zeros (`5`, `0.15`, `-2.5`).
pub fn tick_label(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// A text style at `size`, anchored at `pos`.
fn font(size: f64, h: HPos, v: VPos) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", size).into_font()).pos(Pos::new(h, v))
}

/// What a key entry shows beside its label.
#[derive(Debug, Clone, Copy)]
pub enum Swatch {
    /// A short line in this colour (a line series).
    Line(RGBColor),
    /// A filled box (bars, shaded regions, a car).
    Fill(RGBAColor),
    /// A filled dot (points, pedestrians, the light).
    Dot(RGBColor),
    /// A black interval whisker.
    Whisker,
    /// Nothing (an entry that explains text in the figure).
    Blank,
}

/// One entry of a key: a swatch and what it means.
#[derive(Debug, Clone)]
pub struct KeyEntry {
    /// What the entry looks like in the figure.
    pub swatch: Swatch,
    /// What it means.
    pub label: String,
}

impl KeyEntry {
    /// An entry.
    pub fn new(swatch: Swatch, label: impl Into<String>) -> Self {
        Self {
            swatch,
            label: label.into(),
        }
    }

    /// Width of the entry (swatch, gap, label), px.
    fn width(&self) -> i32 {
        24 + text_width(&self.label, KEY_FONT).ceil() as i32
    }
}

/// Draws `swatch` in the 16 px wide box whose left middle is `(x, y)`.
fn draw_swatch(area: &Area<'_>, swatch: Swatch, x: i32, y: i32) -> Result<()> {
    match swatch {
        Swatch::Line(c) => area.draw(&PathElement::new([(x, y), (x + 16, y)], c.stroke_width(2))),
        Swatch::Fill(c) => area.draw(&Rectangle::new([(x, y - 6), (x + 16, y + 6)], c.filled())),
        Swatch::Dot(c) => area.draw(&Circle::new((x + 8, y), 5, c.filled())),
        Swatch::Whisker => area.draw(&PathElement::new(
            [
                (x + 4, y - 6),
                (x + 12, y - 6),
                (x + 8, y - 6),
                (x + 8, y + 6),
                (x + 4, y + 6),
                (x + 12, y + 6),
            ],
            BLACK.stroke_width(2),
        )),
        Swatch::Blank => Ok(()),
    }
    .map_err(plot_err)
}

/// Draws a key as a column, top-left at `(x, y)` in `area`'s pixels; returns its height.
fn key_column(area: &Area<'_>, x: i32, y: i32, entries: &[KeyEntry]) -> Result<i32> {
    for (i, e) in entries.iter().enumerate() {
        let cy = y + KEY_ROW * i as i32 + KEY_ROW / 2;
        draw_swatch(area, e.swatch, x, cy)?;
        area.draw(&Text::new(
            e.label.clone(),
            (x + 22, cy),
            font(KEY_FONT, HPos::Left, VPos::Center),
        ))
        .map_err(plot_err)?;
    }
    Ok(KEY_ROW * entries.len() as i32)
}

/// Width of [`key_column`] for `entries`, px.
fn key_column_width(entries: &[KeyEntry]) -> i32 {
    entries.iter().map(KeyEntry::width).max().unwrap_or(0)
}

/// Lays a key out in rows no wider than `width`, entries left to right.
fn key_rows(entries: &[KeyEntry], width: i32) -> Vec<Vec<&KeyEntry>> {
    let mut rows: Vec<Vec<&KeyEntry>> = Vec::new();
    let mut used = 0;
    for e in entries {
        let w = e.width() + 12;
        match rows.last_mut() {
            Some(row) if used + w <= width => {
                row.push(e);
                used += w;
            }
            _ => {
                rows.push(vec![e]);
                used = w;
            }
        }
    }
    rows
}

/// Draws a key in rows across `area` (at most its width), top-left at `(x, y)`;
/// returns its height.
fn key_flow(area: &Area<'_>, x: i32, y: i32, entries: &[KeyEntry]) -> Result<i32> {
    let width = area.dim_in_pixel().0 as i32 - x;
    let rows = key_rows(entries, width);
    for (r, row) in rows.iter().enumerate() {
        let cy = y + KEY_ROW * r as i32 + KEY_ROW / 2;
        let mut cx = x;
        for e in row {
            draw_swatch(area, e.swatch, cx, cy)?;
            area.draw(&Text::new(
                e.label.clone(),
                (cx + 22, cy),
                font(KEY_FONT, HPos::Left, VPos::Center),
            ))
            .map_err(plot_err)?;
            cx += e.width() + 12;
        }
    }
    Ok(KEY_ROW * rows.len() as i32)
}

/// Height of [`key_flow`] for `entries` in `width` px.
fn key_flow_height(entries: &[KeyEntry], width: i32) -> i32 {
    KEY_ROW * key_rows(entries, width).len() as i32
}

/// Draws a title centred at the top of `area`; returns the area below it.
fn titled<'a>(area: &Area<'a>, title: &str, size: f64) -> Result<Area<'a>> {
    let w = area.dim_in_pixel().0 as i32;
    area.draw(&Text::new(
        title.to_string(),
        (w / 2, 6),
        font(size, HPos::Center, VPos::Top),
    ))
    .map_err(plot_err)?;
    let h = (size * 1.2) as i32 + 8;
    Ok(area.split_vertically(h).1)
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
    /// Row title, drawn above its key and panels.
    pub title: String,
    /// The key, drawn under the title, above the panels (see [`bar_key`]).
    pub key: Vec<KeyEntry>,
    /// The panels, left to right.
    pub panels: Vec<BarPanel<'a>>,
}

/// Colour of our bars.
const OURS: RGBColor = RGBColor(64, 64, 255);
/// Colour of the paper's bars.
const PAPER: RGBColor = RGBColor(178, 178, 178);

/// The key of a row of [`grouped_bars`]: our bars (over `agents` agents, with whiskers
/// when more than one) and, with `paper`, the paper's bars.
pub fn bar_key(agents: usize, paper: bool) -> Vec<KeyEntry> {
    let mut key = vec![KeyEntry::new(
        Swatch::Fill(OURS.to_rgba()),
        if agents > 1 {
            format!("ours: mean over {agents} agents")
        } else {
            "ours (one agent)".into()
        },
    )];
    if agents > 1 {
        key.push(KeyEntry::new(Swatch::Whisker, "95% interval over the agents"));
    }
    if paper {
        key.push(KeyEntry::new(Swatch::Fill(PAPER.to_rgba()), "the paper's value (§VI)"));
    } else {
        key.push(KeyEntry::new(
            Swatch::Blank,
            "(the paper reports zero-shot values only)",
        ));
    }
    key
}

/// Grouped bar charts (Fig. 8): one row per entry of `rows`, one panel per metric, ours
/// (blue, with interval whiskers) beside the paper's (grey). Each row's key sits under
/// its title, outside the panels.
pub fn grouped_bars(path: &Path, rows: &[BarRow<'_>]) -> Result<()> {
    let panels = rows.iter().map(|r| r.panels.len()).max().unwrap_or(1).max(1);
    let groups = rows
        .iter()
        .flat_map(|r| r.panels.iter().map(|p| p.labels.len()))
        .max()
        .unwrap_or(1);
    // Up to four methods, the panels stand in one line; more get twice the width each,
    // two panels to a line, so that their names stay legible under the bars.
    let columns = if groups > 4 { panels.min(2) } else { panels };
    let lines = panels.div_ceil(columns);
    let column_w = if groups > 4 { 660 } else { 330 };
    let width = (column_w * columns as u32).max(400);
    let key_h = rows
        .iter()
        .map(|r| key_flow_height(&r.key, width as i32 - 40))
        .max()
        .unwrap_or(0);
    let row_h = 60 + key_h as u32 + 360 * lines as u32;
    let height = row_h * rows.len().max(1) as u32;
    write_svg(path, (width, height), |root| {
        let areas = root.split_evenly((rows.len().max(1), 1));
        for (area, row) in areas.iter().zip(rows) {
            let below = titled(area, &row.title, 18.0)?;
            let key_w: i32 = key_rows(&row.key, width as i32 - 40)
                .first()
                .map_or(0, |r| r.iter().map(|e| e.width() + 12).sum());
            key_flow(&below, ((width as i32 - key_w) / 2).max(20), 0, &row.key)?;
            let (_, cells) = below.split_vertically(key_h + 6);
            let cells = cells.split_evenly((lines, columns));
            for (cell, panel) in cells.iter().zip(&row.panels) {
                bar_panel(cell, panel)?;
            }
        }
        Ok(())
    })
}

/// Draws one panel of [`grouped_bars`].
fn bar_panel(area: &Area<'_>, panel: &BarPanel<'_>) -> Result<()> {
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
    // Method names under their bars, staggered over as many rows as they need not to touch.
    const LABEL_FONT: f64 = 12.0;
    let group_px = (f64::from(area.dim_in_pixel().0) - 2.0 * 12.0 - 45.0) / n.max(1) as f64;
    let label_px = panel
        .labels
        .iter()
        .map(|l| text_width(l, LABEL_FONT))
        .fold(0.0, f64::max)
        + 8.0;
    let rows = ((label_px / group_px).ceil() as usize).clamp(1, 4);
    let y0 = lo - if lo < 0.0 { pad } else { 0.0 };
    // Room on the right for half a label wider than its group.
    let overhang = ((label_px - group_px) / 2.0).max(0.0).ceil() as u32;
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 16))
        .margin(12)
        .margin_right(12 + overhang)
        .x_label_area_size(10 + 15 * rows as u32)
        .y_label_area_size(45)
        .build_cartesian_2d(-0.5f64..(n as f64 - 0.5), y0..(hi + pad))
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_label_formatter(&|y| tick_label(*y))
        .draw()
        .map_err(plot_err)?;
    let names = panel.labels.iter().enumerate().map(|(i, label)| {
        let row = (i % rows) as i32;
        EmptyElement::at((i as f64, y0))
            + Text::new(
                label.clone(),
                (0, 6 + 15 * row),
                font(LABEL_FONT, HPos::Center, VPos::Top),
            )
    });
    chart.draw_series(names).map_err(plot_err)?;
    let ours = panel.ours.iter().enumerate().map(|(i, &v)| {
        let x = i as f64;
        Rectangle::new([(x - 0.38, 0.0), (x, v)], OURS.filled())
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
            Rectangle::new([(x, 0.0), (x + 0.38, v)], PAPER.filled())
        })
    });
    chart.draw_series(paper).map_err(plot_err)?;
    Ok(())
}

/// One line of a line chart.
pub struct Series<'a> {
    /// Key label (an empty label gets no key entry).
    pub label: &'a str,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBColor,
}

/// Width of the plotting column of [`line_panels`], px.
const LINE_PLOT_WIDTH: i32 = 760;

/// A stack of line charts sharing the x-axis description (one per entry), e.g. Fig. 9's
/// curves; each panel's key stands to the right of its chart.
pub fn line_panels(path: &Path, x_label: &str, panels: &[(&str, Vec<Series<'_>>)]) -> Result<()> {
    let keys: Vec<Vec<KeyEntry>> = panels
        .iter()
        .map(|(_, series)| {
            series
                .iter()
                .filter(|s| !s.label.is_empty())
                .map(|s| KeyEntry::new(Swatch::Line(s.color), s.label))
                .collect()
        })
        .collect();
    let key_w = keys.iter().map(|k| key_column_width(k)).max().unwrap_or(0);
    let key_w = if key_w > 0 { key_w + 24 } else { 0 };
    let most = keys.iter().map(Vec::len).max().unwrap_or(0) as i32;
    let panel_h = (260).max(60 + KEY_ROW * most);
    let height = panel_h as u32 * panels.len().max(1) as u32;
    let width = (LINE_PLOT_WIDTH + key_w) as u32;
    write_svg(path, (width, height), |root| {
        let areas = root.split_evenly((panels.len().max(1), 1));
        for ((area, (title, series)), key) in areas.iter().zip(panels).zip(&keys) {
            let (plot, key_area) = area.split_horizontally(LINE_PLOT_WIDTH);
            let xs = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
            let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
            let (x0, x1) = min_max(xs);
            // Fitted to the data; a single x value gets a unit-wide axis.
            let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
            // A little room either side, so that points on the first and last x show.
            let (x0, x1) = (x0 - 0.02 * (x1 - x0), x1 + 0.02 * (x1 - x0));
            let (y0, y1) = min_max(ys);
            // A flat series gets a readable span around its value, not a sliver of 1e-3.
            let ypad = if y1 - y0 > 1e-9 {
                (y1 - y0) * 0.08
            } else {
                (0.1 * y0.abs()).max(0.05)
            };
            let mut chart = ChartBuilder::on(&plot)
                .caption(*title, ("sans-serif", 16))
                .margin(10)
                .x_label_area_size(34)
                .y_label_area_size(55)
                .build_cartesian_2d(x0..x1, (y0 - ypad)..(y1 + ypad))
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .x_labels(8)
                .y_labels(6)
                .x_label_formatter(&|x| tick_label(*x))
                .y_label_formatter(&|y| tick_label(*y))
                .draw()
                .map_err(plot_err)?;
            for s in series {
                // Points marked too, so that a series of one point still shows.
                let line = LineSeries::new(s.points.iter().copied(), s.color.stroke_width(2)).point_size(2);
                chart.draw_series(line).map_err(plot_err)?;
            }
            key_column(&key_area, 8, 36, key)?;
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

/// Colour of the reasoning ticks (theta plot shading, filmstrip car).
const REASONING: RGBColor = RGBColor(230, 140, 0);
/// Colour of the feed-forward car in the filmstrip.
const HABIT: RGBColor = RGBColor(40, 70, 230);

/// Normalized surprise theta against the threshold epsilon over an episode, with the
/// reasoning ticks shaded and the action of every tick written above the curve (paper
/// Figs. 6-7). `ticks` are (step, theta, reasoned, action label). The key stands to the
/// right of the chart; the actions take as many rows as they need not to touch.
pub fn theta_trace(path: &Path, title: &str, ticks: &[(u32, Option<f64>, bool, String)], epsilon: f64) -> Result<()> {
    // A method that measures no surprise (q-learning) gets no theta curve, not a curve at 0.
    let measured = ticks.iter().any(|t| t.1.is_some());
    let title = if measured {
        title.to_string()
    } else {
        format!("{title} (this method measures no surprise)")
    };
    let shade = REASONING.mix(0.35);
    let mut key = vec![
        KeyEntry::new(Swatch::Fill(shade), "reasoning tick"),
        KeyEntry::new(Swatch::Line(RED), format!("threshold epsilon = {epsilon}")),
    ];
    if measured {
        key.push(KeyEntry::new(Swatch::Line(BLUE), "theta (normalized surprise)"));
    }
    key.push(KeyEntry::new(Swatch::Blank, "at the top: each tick's action"));
    let key_w = key_column_width(&key) + 24;
    const PLOT_W: i32 = 900;
    const ACTION_FONT: f64 = 10.0;
    // Pixels of the plotting area (the chart minus margins and the y-label area).
    let plot_px = f64::from(PLOT_W - 2 * 12 - 50);
    let n = ticks.iter().map(|t| t.0).max().map_or(1.0, |m| f64::from(m) + 1.0);
    let label_px = ticks.iter().map(|t| text_width(&t.3, ACTION_FONT)).fold(0.0, f64::max) + 6.0;
    // x from -0.5 so that the last label, starting at its tick - 0.35, ends inside the plot.
    let span = ((n - 0.7) / (1.0 - (label_px / plot_px).min(0.5))).max(n);
    let spacing = plot_px / span;
    let rows = ((label_px / spacing).ceil() as usize).clamp(1, 12);
    let height = 380 + 15 * rows.saturating_sub(2) as u32;
    // Data units per action row: 15 px over the plotting area's height.
    let plot_h = f64::from(height) - 100.0;
    let y_band = 1.08;
    let row_units = 15.0 * y_band / (plot_h - 15.0 * rows as f64);
    let y_top = y_band + rows as f64 * row_units;
    write_svg(path, (PLOT_W as u32 + key_w as u32, height), |root| {
        let (plot, key_area) = root.split_horizontally(PLOT_W);
        let mut chart = ChartBuilder::on(&plot)
            .caption(&title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(35)
            .y_label_area_size(50)
            .build_cartesian_2d(-0.5f64..(span - 0.5), 0.0f64..y_top)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("decision tick")
            .y_desc("theta = 1 - exp(-Omega S)")
            .x_label_formatter(&|x| {
                if (x - x.round()).abs() < 1e-6 {
                    format!("{x:.0}")
                } else {
                    String::new()
                }
            })
            .y_label_formatter(&|y| {
                if *y <= 1.0 + 1e-9 {
                    format!("{y:.1}")
                } else {
                    String::new()
                }
            })
            .draw()
            .map_err(plot_err)?;
        chart
            .draw_series(
                ticks
                    .iter()
                    .filter(|t| t.2)
                    .map(|t| Rectangle::new([(t.0 as f64 - 0.5, 0.0), (t.0 as f64 + 0.5, 1.05)], shade.filled())),
            )
            .map_err(plot_err)?;
        chart
            .draw_series(LineSeries::new(
                [(-0.5, epsilon), (n - 0.5, epsilon)],
                RED.stroke_width(1),
            ))
            .map_err(plot_err)?;
        if measured {
            let points = ticks.iter().filter_map(|t| t.1.map(|th| (t.0 as f64, th)));
            chart
                .draw_series(LineSeries::new(points, BLUE.stroke_width(2)).point_size(3))
                .map_err(plot_err)?;
        }
        // Actions above the plot, in `rows` staggered rows so that neighbours never touch.
        chart
            .draw_series(ticks.iter().map(|t| {
                let row = t.0 as usize % rows;
                let y = y_top - 0.005 - row as f64 * row_units;
                Text::new(
                    t.3.clone(),
                    (t.0 as f64 - 0.35, y),
                    font(ACTION_FONT, HPos::Left, VPos::Top),
                )
            }))
            .map_err(plot_err)?;
        key_column(&key_area, 4, 40, &key)?;
        Ok(())
    })
}

/// The colour of road with friction `mu`: the asphalt's grey at the dry road's μ 0.8 and
/// above, shading to blue as the road gets slippery (ice, μ ≤ 0.1, the palest blue).
pub fn surface_tint(mu: f64) -> RGBColor {
    let slip = ((0.8 - mu) / 0.7).clamp(0.0, 1.0);
    let mix = |dry: f64, slick: f64| (dry + (slick - dry) * slip).round() as u8;
    RGBColor(mix(205.0, 150.0), mix(205.0, 200.0), mix(205.0, 245.0))
}

/// The colour of a head showing `lamp` in the filmstrip.
fn lamp_colour(lamp: crate::reports::Lamp) -> RGBColor {
    use crate::reports::Lamp;
    match lamp {
        Lamp::Green => GREEN,
        Lamp::Amber => AMBER,
        Lamp::Red => RED,
        Lamp::Walk => WHITE,
        Lamp::DontWalk => DONT_WALK,
        Lamp::Dark => DARK_HEAD,
    }
}

/// Amber heads.
const AMBER: RGBColor = RGBColor(255, 170, 0);
/// A pedestrian head showing don't walk.
const DONT_WALK: RGBColor = RGBColor(255, 110, 0);
/// A dark head (an outage).
const DARK_HEAD: RGBColor = RGBColor(70, 70, 70);
/// The other vehicles.
const VEHICLE: RGBColor = RGBColor(20, 150, 140);
/// A vehicle in the car's path.
const VEHICLE_IN_PATH: RGBColor = RGBColor(200, 30, 90);

/// Top-down filmstrip of an episode: a title, a key, then one strip per decision tick
/// showing the road, the crosswalk, the light's colour, the car (orange on ticks that
/// reasoned, blue on feed-forward ticks), the pedestrians and the road's surface patches
/// on that tick (tinted by their friction, [`surface_tint`]); left of each strip the
/// tick, the action taken and the discrete state. A map with a junction adds the cross
/// street (its lanes, sidewalks, crosswalks and stop lines), every signal head (round:
/// vehicles', square: pedestrians'; grey when dark) and the other vehicles (teal,
/// raspberry when in the car's path), as [`crate::reports::junction_scene`] lays them
/// out, in taller strips that reach [`crate::reports::CROSS_VIEW`] m along the cross
/// street; a map with traffic and no junction adds the vehicles.
pub fn filmstrip(
    path: &Path,
    title: &str,
    map: &unforeseen_sim::Map,
    ticks: &[crate::episodes::runner::Tick],
) -> Result<()> {
    use crate::reports::{FRONT_BAND, Lamp, junction_scene, vehicle_quad};
    const WIDTH: u32 = 1000;
    const LABEL_W: u32 = 150;
    let junction = junction_scene(map);
    let road_half = f64::from(map.road.lanes) * map.road.lane_width / 2.0;
    let (y_span, strip) = match &junction {
        // About 5 px per metre across, as the straight road's strips.
        Some(j) => (j.reach, (10.0 * j.reach).round() as u32 + 6),
        None => (road_half + map.road.sidewalk_width, 60),
    };
    let car_y = -road_half + map.road.lane_width / 2.0;
    let x0 = map.vehicle.start_x - map.vehicle.length - 2.0;
    let x1 = map.road.goal_x + 4.0;
    let verge = RGBColor(190, 225, 180);
    let asphalt = surface_tint(map.road.friction);
    let walk = RGBColor(245, 245, 245);
    let mut key = vec![
        KeyEntry::new(Swatch::Fill(HABIT.to_rgba()), "car, acting on its habit (feed-forward)"),
        KeyEntry::new(Swatch::Fill(REASONING.to_rgba()), "car, reasoning on this tick"),
        KeyEntry::new(Swatch::Dot(BLACK), "pedestrian"),
        KeyEntry::new(Swatch::Dot(GREEN), "light green"),
        KeyEntry::new(Swatch::Dot(AMBER), "amber"),
        KeyEntry::new(Swatch::Dot(RED), "red"),
        KeyEntry::new(Swatch::Fill(walk.to_rgba()), "crosswalk"),
        KeyEntry::new(Swatch::Fill(BLACK.to_rgba()), "destination"),
        KeyEntry::new(Swatch::Fill(asphalt.to_rgba()), "road"),
        KeyEntry::new(Swatch::Fill(surface_tint(0.4).to_rgba()), "wet (μ 0.4)"),
        KeyEntry::new(Swatch::Fill(surface_tint(0.1).to_rgba()), "ice (μ 0.1)"),
        KeyEntry::new(Swatch::Fill(verge.to_rgba()), "sidewalk"),
    ];
    if junction.is_some() || !map.traffic.is_empty() {
        key.extend([
            KeyEntry::new(Swatch::Fill(VEHICLE.to_rgba()), "vehicle"),
            KeyEntry::new(Swatch::Fill(VEHICLE_IN_PATH.to_rgba()), "vehicle in the car's path"),
        ]);
    }
    if junction.is_some() {
        key.extend([
            KeyEntry::new(Swatch::Dot(DARK_HEAD), "head dark (outage)"),
            KeyEntry::new(Swatch::Fill(DONT_WALK.to_rgba()), "pedestrian head: don't walk"),
            KeyEntry::new(Swatch::Blank, "white square: walk; white bar: stop line"),
        ]);
    }
    let note =
        "left of each strip: tick, action taken, state (d distance bin, v speed bin, L light 1 = green, p pedestrian)";
    let title_h = 36;
    let key_h = key_flow_height(&key, WIDTH as i32 - 20);
    let head = title_h + key_h + 26;
    let height = head as u32 + strip * ticks.len().max(1) as u32;
    write_svg(path, (WIDTH, height), |root| {
        let below = titled(root, title, 18.0)?;
        key_flow(&below, 10, 0, &key)?;
        below
            .draw(&Text::new(note, (10, key_h + 4), font(KEY_FONT, HPos::Left, VPos::Top)))
            .map_err(plot_err)?;
        let (_, strips) = root.split_vertically(head);
        let rows = strips.split_evenly((ticks.len().max(1), 1));
        for (i, (area, t)) in rows.iter().zip(ticks).enumerate() {
            let (label, scene) = area.split_horizontally(LABEL_W);
            let action = if i + 1 == ticks.len() {
                "(end)".to_string()
            } else {
                t.action.to_string()
            };
            label
                .draw(&Text::new(
                    format!("t={}  {action}", t.step),
                    (8, 10),
                    font(14.0, HPos::Left, VPos::Top),
                ))
                .map_err(plot_err)?;
            label
                .draw(&Text::new(
                    format!("d{} v{} L{} p{}", t.state.d, t.state.v, t.state.l, t.state.p),
                    (8, 30),
                    font(KEY_FONT, HPos::Left, VPos::Top),
                ))
                .map_err(plot_err)?;
            let mut chart = ChartBuilder::on(&scene)
                .margin(3)
                .build_cartesian_2d(x0..x1, -y_span..y_span)
                .map_err(plot_err)?;
            chart
                .draw_series([
                    Rectangle::new([(x0, -y_span), (x1, y_span)], verge.filled()),
                    Rectangle::new([(x0, -road_half), (x1, road_half)], asphalt.filled()),
                ])
                .map_err(plot_err)?;
            if let Some(j) = &junction {
                let (k0, k1) = j.cross_kerbs;
                chart
                    .draw_series([Rectangle::new([(k0, -y_span), (k1, y_span)], asphalt.filled())])
                    .map_err(plot_err)?;
            }
            chart
                .draw_series(t.snapshot.surface.iter().map(|p| {
                    Rectangle::new(
                        [(p.from.max(x0), -road_half), (p.to.min(x1), road_half)],
                        surface_tint(p.friction).filled(),
                    )
                }))
                .map_err(plot_err)?;
            chart
                .draw_series([
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
            if let Some(j) = &junction {
                chart
                    .draw_series(
                        j.crosswalks
                            .iter()
                            .map(|(_, r)| Rectangle::new([(r.x0, r.y0), (r.x1, r.y1)], walk.filled())),
                    )
                    .map_err(plot_err)?;
                let white = WHITE.stroke_width(3);
                chart
                    .draw_series(j.stop_lines.iter().map(|l| PathElement::new(l.to_vec(), white)))
                    .map_err(plot_err)?;
                let dash = WHITE.mix(0.8).stroke_width(1);
                chart
                    .draw_series(j.cross_lane_lines.iter().flat_map(|&x| {
                        [
                            PathElement::new(vec![(x, road_half), (x, y_span)], dash),
                            PathElement::new(vec![(x, -y_span), (x, -road_half)], dash),
                        ]
                    }))
                    .map_err(plot_err)?;
            }
            let s = &t.snapshot;
            let car = Rectangle::new(
                [
                    (s.car_x - map.vehicle.length, car_y - map.vehicle.width / 2.0),
                    (s.car_x, car_y + map.vehicle.width / 2.0),
                ],
                if t.reasoned { REASONING.filled() } else { HABIT.filled() },
            );
            chart
                .draw_series([Circle::new(
                    (
                        map.crosswalk.x - map.crosswalk.width,
                        -road_half - map.road.sidewalk_width / 2.0,
                    ),
                    4,
                    lamp_colour(Lamp::of_aspect(s.signals.road)).filled(),
                )])
                .map_err(plot_err)?;
            if let Some(j) = &junction {
                for h in &j.heads {
                    let colour = lamp_colour(h.lamp(&s.signals));
                    let at = EmptyElement::at((h.x, h.y));
                    if h.pedestrian() {
                        chart
                            .draw_series([at
                                + Rectangle::new([(-4, -4), (4, 4)], BLACK.filled())
                                + Rectangle::new([(-3, -3), (3, 3)], colour.filled())])
                            .map_err(plot_err)?;
                    } else {
                        chart
                            .draw_series([at
                                + Circle::new((0, 0), 5, BLACK.filled())
                                + Circle::new((0, 0), 4, colour.filled())])
                            .map_err(plot_err)?;
                    }
                }
            }
            // Vehicles in view (one beyond it would be drawn squashed onto its edge).
            let in_view = |v: &&unforeseen_sim::VehicleSnapshot| {
                let r = v.length.hypot(v.width) / 2.0;
                v.x + r > x0 && v.x - r < x1 && v.y.abs() - r < y_span
            };
            chart
                .draw_series(s.vehicles.iter().filter(in_view).flat_map(|v| {
                    let colour = if v.in_path { VEHICLE_IN_PATH } else { VEHICLE };
                    [
                        Polygon::new(vehicle_quad(v, 0.0, v.length).to_vec(), colour.filled()),
                        Polygon::new(
                            vehicle_quad(v, v.length - FRONT_BAND, v.length).to_vec(),
                            WHITE.mix(0.6).filled(),
                        ),
                    ]
                }))
                .map_err(plot_err)?;
            chart.draw_series([car]).map_err(plot_err)?;
            chart
                .draw_series(s.pedestrians.iter().map(|p| Circle::new((p.x, p.y), 4, BLACK.filled())))
                .map_err(plot_err)?;
        }
        Ok(())
    })
}
