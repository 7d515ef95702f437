//! `batch`'s printed summary (and `merge`'s), and the messages of its failed expectations.

use crate::reports::tables::{Document, Grid, cell, seed_text};
use crate::runs::batch::{SummaryRow, stream_learning};

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
            // A run without training seeds has no worst seed to name.
            match w.train_seed {
                Some(seed) => format!("{seed} ({:.0}%)", 100.0 * w.success_rate),
                None => "—".into(),
            },
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
