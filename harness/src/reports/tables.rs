//! Printed tables: a [`Document`] is a sequence of headings, lines and grids; a [`Grid`]
//! is rows of cells whose first column is left-aligned and the others right-aligned. A
//! document renders as plain text (what the command line prints and Python's
//! `str(result)` gives), Markdown or HTML (a notebook's rich display). The library renders
//! to strings and never prints.
//!
//! Each job builds its report's document in one function beside the report type:
//! `compare`'s in `runs::compare::table`, `eval`'s in `runs::evaluate`, `batch`'s in
//! `runs::batch::table`.

use std::fmt::{self, Display, Write as _};

use crate::files::num;
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
                    if c == 0 {
                        format!("{cell:<w$}")
                    } else {
                        format!("{cell:>w$}")
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
    /// Appends a heading.
    pub fn heading(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Heading(text.into()));
    }

    /// Appends a line of text.
    pub fn line(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Line(text.into()));
    }

    /// Appends a grid.
    pub fn grid(&mut self, grid: Grid) {
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

#[cfg(test)]
mod tests {
    use super::*;

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
