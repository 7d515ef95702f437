//! Printed tables: summarized figures as cells and aligned columns.

use unforeseen_harness::reports::files::num;
use unforeseen_harness::stats::Stat;

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

/// Prints rows of cells as aligned columns (first column left-aligned, others right).
pub fn print_grid(rows: &[Vec<String>]) {
    let Some(first) = rows.first() else { return };
    let widths: Vec<usize> = (0..first.len())
        .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
        .collect();
    for r in rows {
        let line: Vec<String> = r
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
        outln!("{}", line.join("  ").trim_end());
    }
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
}
