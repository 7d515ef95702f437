//! The files of a comparison study, written into its folder all four or none:
//! compare.json (the report, [`CompareReport`]), compare.csv (one row per protocol and
//! method, every metric summarized over agents), compare_seeds.csv (one row per agent)
//! and compare.svg (the table's bars beside the paper's, §VI Fig. 8).

use std::path::{Path, PathBuf};

use crate::episodes::methods::{Method, PaperFigures};
use crate::episodes::protocol::Protocol;
use crate::error::Error;
use crate::files::{Csv, all_or_none, num, write_json};
use crate::reports::figures::{BarPanel, BarRow, bar_key, grouped_bars};
use crate::reports::tables::seed_text;

use super::{CompareReport, METRICS, ProtocolTable};

/// The files a study writes into its folder, in order.
pub const COMPARE_FILES: [&str; 4] = ["compare.json", "compare.csv", "compare_seeds.csv", "compare.svg"];

/// Writes the report's four files into `dir` ([`COMPARE_FILES`]), all or none: a failed
/// write (a full disk) leaves the previous run's set. The paths written, in order.
pub fn write(dir: &Path, report: &CompareReport) -> Result<Vec<PathBuf>, Error> {
    let maps = (report.train_map.as_str(), report.test_map.as_str());
    let paths: Vec<PathBuf> = COMPARE_FILES.iter().map(|n| dir.join(n)).collect();
    all_or_none(|| -> Result<(), Error> {
        write_json(&paths[0], report)?;
        summary_csv(&report.tables, maps).write(&paths[1])?;
        seeds_csv(&report.tables, maps).write(&paths[2])?;
        plot(&paths[3], &report.tables)
    })?;
    Ok(paths)
}

/// Formats an optional number for CSV (empty when absent).
fn opt(x: Option<f64>, digits: usize) -> String {
    x.map(|x| num(x, digits)).unwrap_or_default()
}

/// Training seeds as one CSV cell, space-separated.
fn seeds_cell(seeds: &[Option<u64>]) -> String {
    let s: Vec<String> = seeds.iter().map(|&s| seed_text(s)).collect();
    s.join(" ")
}

/// `compare.csv`: one row per (protocol, method), every metric as mean, 95% interval,
/// min and max over agents, and the worst seed.
fn summary_csv(tables: &[ProtocolTable], (train_map, test_map): (&str, &str)) -> Csv {
    let mut header: Vec<String> = [
        "protocol",
        "method",
        "computed_under",
        "agents",
        "train_seeds",
        "train_episodes",
        "episodes",
        "seed",
        "train_map",
        "test_map",
    ]
    .map(String::from)
    .to_vec();
    for (name, _) in METRICS {
        for suffix in ["", "_ci95_low", "_ci95_high", "_min", "_max"] {
            header.push(format!("{name}{suffix}"));
        }
    }
    header.extend(["worst_seed", "worst_seed_success_rate", "worst_seed_test_reward"].map(String::from));
    let mut csv = Csv::new(&header.iter().map(String::as_str).collect::<Vec<_>>());
    for m in tables.iter().flat_map(|t| &t.methods) {
        let mut row = vec![
            m.protocol.to_string(),
            m.method.clone(),
            m.computed_under.to_string(),
            m.train_seeds.len().to_string(),
            seeds_cell(&m.train_seeds),
            m.train_episodes.map(|e| e.to_string()).unwrap_or_default(),
            m.episodes.to_string(),
            m.seed.to_string(),
            train_map.to_string(),
            test_map.to_string(),
        ];
        for (name, _) in METRICS {
            let s = m.stat(name);
            row.extend([
                num(s.mean, 4),
                opt(s.ci95_low, 4),
                opt(s.ci95_high, 4),
                num(s.min, 4),
                num(s.max, 4),
            ]);
        }
        row.extend([
            m.worst_seed.train_seed.map(|s| s.to_string()).unwrap_or_default(),
            num(m.worst_seed.success_rate, 4),
            num(m.worst_seed.test_reward, 4),
        ]);
        csv.row(row);
    }
    csv
}

/// `compare_seeds.csv`: one row per (protocol, method, training seed).
fn seeds_csv(tables: &[ProtocolTable], (train_map, test_map): (&str, &str)) -> Csv {
    let mut header = vec![
        "protocol",
        "method",
        "computed_under",
        "train_seed",
        "train_map",
        "test_map",
    ];
    header.extend(METRICS.iter().map(|(name, _)| *name));
    let mut csv = Csv::new(&header);
    for m in tables.iter().flat_map(|t| &t.methods) {
        for r in &m.per_seed {
            let mut row = vec![
                m.protocol.to_string(),
                m.method.clone(),
                m.computed_under.to_string(),
                r.train_seed.map(|s| s.to_string()).unwrap_or_default(),
                train_map.to_string(),
                test_map.to_string(),
            ];
            row.extend(METRICS.iter().map(|(_, f)| num(f(r), 4)));
            csv.row(row);
        }
    }
    csv
}

/// `compare.svg`: one row of bar panels per protocol (train reward, test reward, success,
/// inference rate), ours with 95% interval whiskers over agents beside the paper's.
fn plot(path: &Path, tables: &[ProtocolTable]) -> Result<(), Error> {
    type PaperOf = fn(&PaperFigures) -> f64;
    let panels: [(&str, &str, PaperOf); 4] = [
        ("train reward (training map)", "train_reward", |p| p.train_reward),
        ("test reward (test map)", "test_reward", |p| p.test_reward),
        ("success rate (test map)", "success_rate", |p| p.success_rate),
        ("inference rate (test map)", "inference_rate", |p| p.inference_rate),
    ];
    let labels: Vec<Vec<String>> = tables
        .iter()
        .map(|t| t.methods.iter().map(|m| m.method.clone()).collect())
        .collect();
    let rows: Vec<BarRow<'_>> = tables
        .iter()
        .zip(&labels)
        .map(|(t, labels)| {
            let n = t.methods.first().map_or(0, |m| m.train_seeds.len());
            BarRow {
                title: format!("{} protocol: {}", t.protocol, t.protocol.meaning()),
                key: bar_key(n, t.protocol == Protocol::ZeroShot),
                panels: panels
                    .iter()
                    .map(|&(title, metric, paper)| BarPanel {
                        title,
                        labels,
                        ours: t.methods.iter().map(|m| m.stat(metric).mean).collect(),
                        interval: t
                            .methods
                            .iter()
                            .map(|m| m.stat(metric).ci95_low.zip(m.stat(metric).ci95_high))
                            .collect(),
                        paper: t
                            .methods
                            .iter()
                            .map(|m| {
                                let p = m
                                    .method
                                    .parse::<Method>()
                                    .ok()
                                    .and_then(Method::paper)
                                    .filter(|_| t.protocol == Protocol::ZeroShot);
                                p.as_ref().map(paper)
                            })
                            .collect(),
                    })
                    .collect(),
            }
        })
        .collect();
    grouped_bars(path, &rows)
}
