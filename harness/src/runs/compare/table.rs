//! `compare`'s printed tables (§VI, Fig. 8), one per protocol, built from its report.

use crate::episodes::methods::{Method, PaperFigures};
use crate::episodes::protocol::Protocol;
use crate::files::num;
use crate::reports::tables::{Document, Grid, cell, range_cell, seed_text};
use crate::runs::compare::{CompareReport, MethodSummary, ProtocolTable};

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
pub fn compare_table(report: &CompareReport) -> Document {
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
