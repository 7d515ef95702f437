//! The printed tables of the reports: what `compare`, `eval` and `batch` print, built
//! here once from their report types and rendered as plain text (what the command line
//! prints and Python's `str(result)` gives), Markdown or HTML (a notebook's rich
//! display). The library renders to strings and never prints.
//!
//! A [`Document`] is a sequence of headings, lines and grids; a [`Grid`] is rows of cells
//! whose first column is left-aligned and the others right-aligned. Each report builds
//! its document in one function: [`compare`], [`eval`], [`eval_stream`] and
//! [`batch_summary`].

use std::fmt::{self, Display, Write as _};

use crate::episodes::experiments::EvalReport;
use crate::episodes::methods::{Method, PaperFigures};
use crate::episodes::protocol::Protocol;
use crate::reports::files::num;
use crate::runs::batch::{SummaryRow, stream_learning};
use crate::runs::compare::{CompareReport, MethodSummary, ProtocolTable};
use crate::runs::stream::StreamEvalReport;
use crate::stats::Stat;

/// A summarized figure as a cell: `mean` with one value, `mean ± half-width` of the 95%
/// interval with more; as a percentage when `percent`.
pub fn cell(s: &Stat, digits: usize, percent: bool) -> String {
    let k = if percent { 100.0 } else { 1.0 };
    let unit = if percent { "%" } else { "" };
    match s.half_width() {
        Some(h) => format!("{}{unit} ± {}", num(k * s.mean, digits), num(k * h, digits)),
        None => format!("{}{unit}", num(k * s.mean, digits)),
    }
}

/// `min .. max` of a summarized figure as a cell.
pub fn range_cell(s: &Stat, digits: usize, percent: bool) -> String {
    let k = if percent { 100.0 } else { 1.0 };
    let unit = if percent { "%" } else { "" };
    format!("{}{unit} .. {}{unit}", num(k * s.min, digits), num(k * s.max, digits))
}

/// Optional training seed as text (`?` when unknown).
pub fn seed_text(seed: Option<u64>) -> String {
    seed.map_or("?".into(), |s| s.to_string())
}

/// Rows of cells shown as aligned columns: the first `header_rows` rows are the header
/// (several when a second line names, say, the map each column was measured on).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Grid {
    /// How many of the first rows are the header.
    pub header_rows: usize,
    /// Every row, header first; all rows have as many cells as the first.
    pub rows: Vec<Vec<String>>,
}

impl Grid {
    /// A grid with one header row.
    pub fn new(header: Vec<String>) -> Self {
        Grid {
            header_rows: 1,
            rows: vec![header],
        }
    }
}

/// The grid as aligned text lines: columns two spaces apart, the first left-aligned and
/// the others right-aligned, trailing spaces removed, no newline after the last line.
impl Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Some(first) = self.rows.first() else {
            return Ok(());
        };
        let widths: Vec<usize> = (0..first.len())
            .map(|c| self.rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
            .collect();
        for (i, r) in self.rows.iter().enumerate() {
            let cells: Vec<String> = r
                .iter()
                .zip(&widths)
                .enumerate()
                .map(|(c, (cell, &w))| {
                    // Padded by hand: `format!`'s width stops at 65,535 (a longer cell
                    // would panic), and a cell may hold a user's long label.
                    let pad = " ".repeat(w - cell.chars().count());
                    if c == 0 {
                        format!("{cell}{pad}")
                    } else {
                        format!("{pad}{cell}")
                    }
                })
                .collect();
            if i > 0 {
                f.write_str("\n")?;
            }
            f.write_str(cells.join("  ").trim_end())?;
        }
        Ok(())
    }
}

/// One part of a [`Document`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Block {
    /// A heading: in text an empty line, then `== heading`.
    Heading(String),
    /// A line of text.
    Line(String),
    /// A table.
    Grid(Grid),
}

/// A report as printed: headings, lines and tables, rendered as text ([`Display`], what
/// the command line prints), [`Document::markdown`] or [`Document::html`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Document {
    /// The parts, in order.
    pub blocks: Vec<Block>,
}

impl Document {
    fn heading(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Heading(text.into()));
    }

    fn line(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Line(text.into()));
    }

    fn grid(&mut self, grid: Grid) {
        self.blocks.push(Block::Grid(grid));
    }

    /// The document as Markdown: headings as `####`, lines as paragraphs, grids as pipe
    /// tables (several header rows joined into one header cell per column).
    pub fn markdown(&self) -> String {
        let mut out = String::new();
        for block in &self.blocks {
            match block {
                Block::Heading(h) => {
                    let _ = writeln!(out, "#### {}\n", md_escape(h));
                }
                Block::Line(l) => {
                    let _ = writeln!(out, "{}\n", md_escape(l));
                }
                Block::Grid(g) => {
                    let Some(first) = g.rows.first() else { continue };
                    let header_rows = g.header_rows.clamp(1, g.rows.len());
                    let header: Vec<String> = (0..first.len())
                        .map(|c| {
                            let parts: Vec<&str> = g.rows[..header_rows]
                                .iter()
                                .map(|r| r[c].as_str())
                                .filter(|s| !s.is_empty())
                                .collect();
                            md_escape(&parts.join(" "))
                        })
                        .collect();
                    let _ = writeln!(out, "| {} |", header.join(" | "));
                    let align: Vec<&str> = (0..first.len()).map(|c| if c == 0 { ":---" } else { "---:" }).collect();
                    let _ = writeln!(out, "|{}|", align.join("|"));
                    for r in &g.rows[header_rows..] {
                        let cells: Vec<String> = r.iter().map(|c| md_escape(c)).collect();
                        let _ = writeln!(out, "| {} |", cells.join(" | "));
                    }
                    out.push('\n');
                }
            }
        }
        out
    }

    /// The document as an HTML fragment: headings as `<h4>`, lines as paragraphs, grids
    /// as tables (header rows in `<thead>`, numbers right-aligned).
    pub fn html(&self) -> String {
        let mut out = String::from("<div>\n");
        for block in &self.blocks {
            match block {
                Block::Heading(h) => {
                    let _ = writeln!(out, "<h4>{}</h4>", html_escape(h));
                }
                Block::Line(l) => {
                    let _ = writeln!(out, "<p>{}</p>", html_escape(l));
                }
                Block::Grid(g) => {
                    let header_rows = g.header_rows.min(g.rows.len());
                    let row = |out: &mut String, r: &[String], tag: &str| {
                        out.push_str("<tr>");
                        for (c, cell) in r.iter().enumerate() {
                            let align = if c == 0 { "left" } else { "right" };
                            let _ = write!(
                                out,
                                "<{tag} style=\"text-align: {align}\">{}</{tag}>",
                                html_escape(cell)
                            );
                        }
                        out.push_str("</tr>\n");
                    };
                    out.push_str("<table>\n<thead>\n");
                    for r in &g.rows[..header_rows] {
                        row(&mut out, r, "th");
                    }
                    out.push_str("</thead>\n<tbody>\n");
                    for r in &g.rows[header_rows..] {
                        row(&mut out, r, "td");
                    }
                    out.push_str("</tbody>\n</table>\n");
                }
            }
        }
        out.push_str("</div>\n");
        out
    }
}

/// The document as plain text, what the command line prints: lines separated by
/// newlines, with no newline after the last.
impl Display for Document {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut lines: Vec<String> = Vec::new();
        for block in &self.blocks {
            match block {
                Block::Heading(h) => {
                    lines.push(String::new());
                    lines.push(format!("== {h}"));
                }
                Block::Line(l) => lines.push(l.clone()),
                Block::Grid(g) => lines.push(g.to_string()),
            }
        }
        f.write_str(&lines.join("\n"))
    }
}

/// Text with Markdown's special characters escaped.
fn md_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        if matches!(ch, '\\' | '`' | '*' | '_' | '[' | ']' | '<' | '>' | '#' | '|') {
            out.push('\\');
        }
        out.push(ch);
    }
    out
}

/// Text with HTML's special characters escaped.
fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(ch),
        }
    }
    out
}

/// The paper's figures for a method by name, if it reports them.
fn paper_of(method: &str) -> Option<PaperFigures> {
    method.parse::<Method>().ok().and_then(Method::paper)
}

/// Who the agents are, in words.
fn agents_line(m: &MethodSummary) -> String {
    let n = m.train_seeds.len();
    let episodes = m.train_episodes.map_or("?".into(), |e| e.to_string());
    let seeds: Vec<String> = m.train_seeds.iter().map(|&s| seed_text(s)).collect();
    let agents = if n == 1 {
        "1 agent".into()
    } else {
        format!("{n} agents")
    };
    format!(
        "{agents} (training seed{} {}, {episodes} training episodes each), {} evaluation episodes per method, map and agent, evaluation seed {}",
        if n == 1 { "" } else { "s" },
        seeds.join(","),
        m.episodes,
        m.seed
    )
}

/// `compare`'s tables (§VI, Fig. 8), one per protocol: the figures (the paper's in
/// parentheses under zero-shot), then, over several agents, their range and the worst
/// seed. A second header line names the map each column was measured on.
pub fn compare(report: &CompareReport) -> Document {
    let mut doc = Document::default();
    for table in &report.tables {
        protocol_table(&mut doc, report, table);
    }
    doc
}

/// One protocol's table of [`compare`].
fn protocol_table(doc: &mut Document, report: &CompareReport, table: &ProtocolTable) {
    let Some(first) = table.methods.first() else { return };
    let (train_map, test_map) = (&report.train_map, &report.test_map);
    let n = first.train_seeds.len();
    doc.heading(format!("{} protocol: {}", table.protocol, table.meaning));
    doc.line(agents_line(first));
    doc.line(format!(
        "train reward: on the training map '{train_map}'; every other column: on the test map '{test_map}'"
    ));
    let (train_reward, test_reward) = &report.reward_described;
    if train_reward == test_reward {
        doc.line(format!("reward on both maps: {train_reward}"));
    } else {
        doc.line(format!("reward: training map {train_reward}; test map {test_reward}"));
    }
    if n > 1 {
        doc.line(format!(
            "each figure: mean ± half-width of the 95% interval over the {n} agents (Student t, {} df)",
            n - 1
        ));
    }
    let mut grid = compare_header("µs/tick", train_map, test_map, &format!("({test_map})"));
    let with_paper = |ours: String, paper: Option<String>| match paper {
        Some(p) if table.protocol == Protocol::ZeroShot => format!("{ours} ({p})"),
        _ => ours,
    };
    let rate_digits = if n > 1 { 1 } else { 0 };
    for m in &table.methods {
        let p = paper_of(&m.method);
        let mark = if m.computed_under != m.protocol { "*" } else { "" };
        grid.rows.push(vec![
            format!("{}{mark}", m.method),
            with_paper(cell(&m.train_reward, 1, false), p.map(|p| num(p.train_reward, 1))),
            with_paper(cell(&m.test_reward, 1, false), p.map(|p| num(p.test_reward, 1))),
            with_paper(
                cell(&m.success_rate, rate_digits, true),
                p.map(|p| format!("{:.0}%", 100.0 * p.success_rate)),
            ),
            with_paper(cell(&m.collision_rate, rate_digits, true), p.map(|_| "n/a".to_string())),
            cell(&m.red_light_rate, rate_digits, true),
            cell(&m.inference_rate, 1, true),
            cell(&m.reasoning_us_per_tick, 2, false),
        ]);
    }
    doc.grid(grid);
    if table.protocol == Protocol::ZeroShot {
        doc.line(
            "(paper's values in parentheses, §VI; n/a: the paper gives no collision rate; red lights: episodes entering the crosswalk on red, not in the paper; its inference rate is relative, below)",
        );
    }
    let copied: Vec<&str> = table
        .methods
        .iter()
        .filter(|m| m.computed_under != m.protocol)
        .map(|m| m.method.as_str())
        .collect();
    if !copied.is_empty() {
        let verb = if copied.len() == 1 { "does" } else { "do" };
        doc.line(format!(
            "* {} {verb} not learn across episodes: identical under both protocols, run once ({}) and repeated here",
            copied.join(", "),
            Protocol::ZeroShot
        ));
    }
    if let Some(rel) = &table.scaled_inference_relative_to_bayes_rl {
        doc.line(format!(
            "scaled reasons on {} of the ticks Bayesian RL does (paper: 63.3%)",
            cell(rel, 1, true)
        ));
    }
    if n > 1 {
        doc.line("over the agents: min .. max, and the worst seed (lowest test success; its success and test reward)");
        let mut grid = compare_header("worst seed", train_map, test_map, "");
        for m in &table.methods {
            let w = &m.worst_seed;
            grid.rows.push(vec![
                m.method.clone(),
                range_cell(&m.train_reward, 1, false),
                range_cell(&m.test_reward, 1, false),
                range_cell(&m.success_rate, 0, true),
                range_cell(&m.collision_rate, 0, true),
                range_cell(&m.red_light_rate, 0, true),
                range_cell(&m.inference_rate, 1, true),
                format!(
                    "{} ({:.0}%, {})",
                    seed_text(w.train_seed),
                    100.0 * w.success_rate,
                    num(w.test_reward, 1)
                ),
            ]);
        }
        doc.grid(grid);
    }
}

/// The two header rows of `compare`'s grids: the method, the table's figures, then
/// `last`; below them the map each figure was measured on, then `last_map`.
fn compare_header(last: &str, train_map: &str, test_map: &str, last_map: &str) -> Grid {
    let figures = [
        "train reward",
        "test reward",
        "success",
        "collisions",
        "red lights",
        "inference rate",
    ];
    let names = std::iter::once("method")
        .chain(figures)
        .chain([last])
        .map(String::from)
        .collect();
    let test = format!("({test_map})");
    let maps = [
        "",
        &format!("({train_map})"),
        &test,
        &test,
        &test,
        &test,
        &test,
        last_map,
    ]
    .map(String::from)
    .to_vec();
    Grid {
        header_rows: 2,
        rows: vec![names, maps],
    }
}

/// `eval`'s line: the method on the map under its protocol (noting a method that does
/// not learn across episodes), and its figures over every episode.
pub fn eval(report: &EvalReport) -> Document {
    let agg = &report.aggregate;
    let mut doc = Document::default();
    doc.line(format!(
        "{} on '{}' ({}): reward {:.2}, success {:.1}%, collisions {:.1}%, red lights {:.1}%, timeouts {:.1}%, inference rate {:.1}%, {:.2} µs/tick over {} episodes",
        report.method,
        report.map,
        protocol_note(report.method, report.protocol, report.learns_across_episodes),
        agg.mean_reward,
        100.0 * agg.success_rate,
        100.0 * agg.collision_rate,
        100.0 * agg.red_light_rate,
        100.0 * agg.timeout_rate,
        100.0 * agg.inference_rate,
        agg.us_per_tick,
        agg.episodes
    ));
    doc
}

/// `eval --stream`'s lines: the method on the stream under its protocol, then one line
/// per map within the stream.
pub fn eval_stream(report: &StreamEvalReport) -> Document {
    let mut doc = Document::default();
    doc.line(format!(
        "{} on stream '{}' ({}), per map:",
        report.method,
        report.stream,
        protocol_note(report.method, report.protocol, report.learns_across_episodes)
    ));
    for r in &report.per_map {
        let a = &r.aggregate;
        doc.line(format!(
            "  {:<20} {:>4} episodes: success {:.1}%, collisions {:.1}%, reward {:.2}, inference rate {:.1}%",
            r.map,
            a.episodes,
            100.0 * a.success_rate,
            100.0 * a.collision_rate,
            a.mean_reward,
            100.0 * a.inference_rate
        ));
    }
    doc
}

/// The protocol in words, noting a method that does not learn across episodes (so both
/// protocols give its results).
fn protocol_note(method: Method, protocol: Protocol, learns_across_episodes: bool) -> String {
    if learns_across_episodes {
        protocol.to_string()
    } else {
        format!("{protocol}; {method} does not learn across episodes, so both protocols give these results")
    }
}

/// `batch`'s summary (and `merge`'s): one row per (scenario, method, parameters,
/// protocol) over its training seeds (a stream's row followed by one per map within it,
/// `STREAM/MAP`, with its episodes), then, for a stream run under both protocols, what
/// learning does to each map within it.
pub fn batch_summary(rows: &[SummaryRow]) -> Document {
    let mut doc = Document::default();
    let many = rows.iter().any(|r| r.train_seeds.len() > 1);
    let streams = rows.iter().any(|r| r.stream.is_some());
    let mut head = vec!["scenario", "method", "parameters", "protocol", "seeds"];
    if streams {
        head.push("episodes");
    }
    head.extend(["success", "collision", "red light", "reward", "inference", "worst seed"]);
    let mut grid = Grid::new(head.into_iter().map(String::from).collect());
    for r in rows {
        let protocols: Vec<&str> = r.covers.iter().map(|p| p.name()).collect();
        let w = &r.worst_seed;
        let mut row = vec![
            match &r.stream {
                Some(stream) => format!("{stream}/{}", r.scenario),
                None => r.scenario.clone(),
            },
            r.method.clone(),
            r.param_set.clone(),
            protocols.join("+"),
            r.train_seeds.len().to_string(),
        ];
        if streams {
            row.push(r.episodes.to_string());
        }
        row.extend([
            cell(&r.success_rate, 1, true),
            cell(&r.collision_rate, 1, true),
            cell(&r.red_light_rate, 1, true),
            cell(&r.mean_reward, 2, false),
            cell(&r.inference_rate, 1, true),
            format!("{} ({:.0}%)", seed_text(w.train_seed), 100.0 * w.success_rate),
        ]);
        grid.rows.push(row);
    }
    if many {
        doc.line("each figure: mean ± half-width of the 95% interval over training seeds (Student t)");
    }
    doc.grid(grid);
    let learning = stream_learning(rows);
    if learning.is_empty() {
        return doc;
    }
    doc.line(
        "learning within the stream, per map: continual against zero-shot on the same episodes (means over training seeds)",
    );
    let mut grid = Grid::new(
        [
            "map",
            "method",
            "parameters",
            "episodes",
            "success zero-shot",
            "continual",
            "reward zero-shot",
            "continual",
            "",
        ]
        .map(String::from)
        .to_vec(),
    );
    for l in &learning {
        grid.rows.push(vec![
            format!("{}/{}", l.stream, l.map),
            l.method.clone(),
            l.param_set.clone(),
            l.episodes.to_string(),
            format!("{:.1}%", 100.0 * l.zero_shot_success),
            format!("{:.1}%", 100.0 * l.continual_success),
            format!("{:.2}", l.zero_shot_reward),
            format!("{:.2}", l.continual_reward),
            if l.worse { "worse".into() } else { String::new() },
        ]);
    }
    doc.grid(grid);
    doc
}

/// One message per expectation of `batch`'s summary rows that fails on the mean, naming
/// the worst seed (what `batch`, `merge` and the Ray driver report).
pub fn expectation_failures(rows: &[SummaryRow]) -> Vec<String> {
    let mut out = Vec::new();
    for r in rows {
        for c in r.checks.iter().filter(|c| !c.pass) {
            let n = r.train_seeds.len();
            let over = if n == 1 {
                format!("training seed {}", seed_text(r.train_seeds[0]))
            } else {
                format!(
                    "mean over {n} training seeds; worst seed {}: {:.4}",
                    seed_text(c.worst_seed),
                    c.worst_value
                )
            };
            let protocols: Vec<&str> = r.covers.iter().map(|p| p.name()).collect();
            out.push(format!(
                "{} ({}): {} [{}] {} {} = {:.4} violates {} {} ({over})",
                r.scenario,
                r.source,
                r.method,
                r.param_set,
                protocols.join("+"),
                c.figure,
                c.mean,
                c.bound,
                c.limit
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_of_any_length_is_aligned_without_a_panic() {
        let long = "x".repeat(70_000);
        let mut grid = Grid::new(vec!["name".into(), "n".into()]);
        grid.rows.push(vec![long.clone(), "1".into()]);
        grid.rows.push(vec!["a".into(), long.clone()]);
        let text = grid.to_string();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[1], format!("{long}  {}1", " ".repeat(69_999)));
        assert_eq!(lines[2].chars().count(), 70_000 + 2 + 70_000);
    }

    #[test]
    fn cells_show_the_interval_only_over_several_values() {
        assert_eq!(cell(&Stat::of(&[0.5]), 0, true), "50%");
        assert_eq!(cell(&Stat::of(&[1.0, 3.0]), 1, false), "2.0 ± 12.7");
        assert_eq!(range_cell(&Stat::of(&[0.25, 0.5]), 0, true), "25% .. 50%");
    }

    fn sample() -> Document {
        let mut doc = Document::default();
        doc.heading("zero-shot protocol: from the trained agent");
        doc.line("a *note* <here>");
        doc.grid(Grid {
            header_rows: 2,
            rows: vec![
                vec!["method".into(), "success".into(), "".into()],
                vec!["".into(), "(jaywalk)".into(), "".into()],
                vec!["scaled*".into(), "95%".into(), "".into()],
                vec!["q-learning".into(), "5%".into(), "x|y".into()],
            ],
        });
        doc
    }

    #[test]
    fn text_aligns_columns_and_trims_trailing_spaces() {
        let text = sample().to_string();
        let expected = [
            "",
            "== zero-shot protocol: from the trained agent",
            "a *note* <here>",
            "method        success",
            "            (jaywalk)",
            "scaled*           95%",
            "q-learning         5%  x|y",
        ]
        .join("\n");
        assert_eq!(text, expected);
    }

    #[test]
    fn markdown_joins_the_header_rows_and_escapes() {
        let md = sample().markdown();
        assert!(md.starts_with("#### zero-shot protocol: from the trained agent\n\na \\*note\\* \\<here\\>\n\n"));
        assert!(md.contains("| method | success (jaywalk) |  |\n|:---|---:|---:|\n| scaled\\* | 95% |  |\n"));
        assert!(md.contains("| q-learning | 5% | x\\|y |\n"));
    }

    #[test]
    fn html_escapes_and_keeps_the_header_rows_in_thead() {
        let html = sample().html();
        assert!(html.contains("<h4>zero-shot protocol: from the trained agent</h4>"));
        assert!(html.contains("<p>a *note* &lt;here&gt;</p>"));
        let head = &html[html.find("<thead>").unwrap()..html.find("</thead>").unwrap()];
        assert_eq!(head.matches("<tr>").count(), 2);
        assert!(html.contains("<td style=\"text-align: right\">95%</td>"));
    }
}
