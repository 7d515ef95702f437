//! `unforeseen learn`: test-time learning curves over repeated encounters (paper Fig. 9).

use clap::Args;
use plotters::style::{BLUE, GREEN, RED};
use std::path::PathBuf;

use super::{AgentArgs, out_dir};
use crate::experiments::learn;
use crate::maps;
use crate::plots::{Series, line_panels};
use crate::report::{Csv, num, write_json};

/// Arguments of `learn`.
#[derive(Debug, Clone, Args)]
pub struct LearnArgs {
    /// Map with the unforeseen scenario (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub map: String,
    /// Episodes of test-time learning.
    #[arg(long, default_value_t = 50)]
    pub episodes: u64,
    /// Output folder for learn.csv, learn.json and learn.svg.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

/// Runs `learn`.
pub fn run(args: LearnArgs) -> anyhow::Result<()> {
    let map = maps::load(&args.map)?;
    let params = args.agent.params()?;
    let bundle = args.agent.bundle()?;
    let points = learn(&bundle, &params, &map, args.episodes, args.agent.seed, args.agent.quiet)?;
    let mut csv = Csv::new(&[
        "episode",
        "jaywalk_surprise_bits",
        "p_appear_green_d2",
        "p_stay_green_d2",
        "p_slow_down",
        "inference_rate",
        "success",
        "reward",
    ]);
    for p in &points {
        csv.row(vec![
            p.episode.to_string(),
            p.jaywalk_surprise_bits.map(|s| num(s, 4)).unwrap_or_default(),
            num(p.p_appear_green_d2, 5),
            num(p.p_stay_green_d2, 5),
            num(p.p_slow_down, 5),
            num(p.inference_rate, 4),
            p.success.to_string(),
            num(p.reward, 3),
        ]);
    }
    if let (Some(first), Some(last)) = (points.first(), points.last()) {
        let bits = |x: Option<f64>| x.map(|b| format!("{b:.2} bits")).unwrap_or_else(|| "n/a".into());
        println!(
            "test-time learning on '{}' over {} episodes, continual protocol (paper's Fig. 9 in parentheses):",
            map.name,
            points.len()
        );
        println!(
            "  surprise at the jaywalk      {} -> {}   (1.95 -> ~0.2 bits)",
            bits(first.jaywalk_surprise_bits),
            bits(last.jaywalk_surprise_bits)
        );
        println!(
            "  P(p'=1 | p=1, L'=1, d'=2)    {:.3} -> {:.3}   (paper's P(pedestrian | L=1, d=2): 0.25 -> 0.9)",
            first.p_stay_green_d2, last.p_stay_green_d2
        );
        println!(
            "  P(p'=1 | p=0, L'=1, d'=2)    {:.3} -> {:.3}",
            first.p_appear_green_d2, last.p_appear_green_d2
        );
        println!(
            "  pi_o(slow down | jaywalk)    {:.3} -> {:.3}   (0.3 -> 0.92)",
            first.p_slow_down, last.p_slow_down
        );
        println!(
            "  inference rate               {:.1}% -> {:.1}%",
            100.0 * first.inference_rate,
            100.0 * last.inference_rate
        );
    }
    let dir = out_dir(&args.out, "out/learn");
    csv.write(&dir.join("learn.csv"))?;
    write_json(&dir.join("learn.json"), &points)?;
    let x = |f: &dyn Fn(&crate::experiments::LearnPoint) -> Option<f64>| -> Vec<(f64, f64)> {
        points
            .iter()
            .filter_map(|p| f(p).map(|y| (p.episode as f64, y)))
            .collect()
    };
    line_panels(
        &dir.join("learn.svg"),
        "episode of test-time learning",
        &[
            (
                "surprise at the jaywalk (bits)",
                vec![Series {
                    label: "S at first jaywalk tick",
                    points: x(&|p| p.jaywalk_surprise_bits),
                    color: RED,
                }],
            ),
            (
                "world model: pedestrian on green at d = 2",
                vec![
                    Series {
                        label: "P(p'=1 | p=1, L'=1, d'=2)",
                        points: x(&|p| Some(p.p_stay_green_d2)),
                        color: BLUE,
                    },
                    Series {
                        label: "P(p'=1 | p=0, L'=1, d'=2)",
                        points: x(&|p| Some(p.p_appear_green_d2)),
                        color: GREEN,
                    },
                ],
            ),
            (
                "policy: pi_o(slow down | jaywalk state)",
                vec![Series {
                    label: "P(slow down)",
                    points: x(&|p| Some(p.p_slow_down)),
                    color: BLUE,
                }],
            ),
        ],
    )?;
    println!("wrote {}/learn.csv, learn.json, learn.svg", dir.display());
    Ok(())
}
