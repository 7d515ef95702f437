//! `unforeseen eval`: one method of a trained agent on a map.

use clap::Args;
use std::path::PathBuf;

use super::{AgentArgs, out_dir};
use crate::experiments::evaluate;
use crate::maps;
use crate::methods::Method;
use crate::metrics::Aggregate;
use crate::report::write_json;

/// Arguments of `eval`.
#[derive(Debug, Clone, Args)]
pub struct EvalArgs {
    /// Map to evaluate on (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub map: String,
    /// Method to evaluate (the scripted `brake-on-pedestrian` and `never-brake` need
    /// no agent: `--agent` is then ignored and nothing is trained).
    #[arg(long, value_enum, default_value_t = Method::Scaled)]
    pub method: Method,
    /// Episodes.
    #[arg(long, default_value_t = 100)]
    pub episodes: u64,
    /// Output folder for eval.json.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

/// Runs `eval`.
pub fn run(args: EvalArgs) -> anyhow::Result<()> {
    let map = maps::load(&args.map)?;
    let params = args.agent.params()?;
    let disc = unforeseen_discretizer::Discretizer::new(&map.bins)?;
    // The scripted references need no agent: they decode the map's own observations.
    let mut controller = match args.method.scripted_controller(&disc.factor_sizes())? {
        Some(scripted) => scripted,
        None => {
            let bundle = args.agent.bundle()?;
            crate::agent_file::check_compatible(&bundle, &map.name, disc.n_states())?;
            args.method.controller(&bundle, &params)?
        }
    };
    let results = evaluate(
        &map,
        controller.as_mut(),
        args.method,
        args.episodes,
        args.agent.seed,
        args.agent.quiet,
    )?;
    let agg = Aggregate::of(&results);
    println!(
        "{} on '{}': reward {:.2}, success {:.1}%, collisions {:.1}%, timeouts {:.1}%, inference rate {:.1}%, {:.2} µs/tick over {} episodes",
        args.method,
        map.name,
        agg.mean_reward,
        100.0 * agg.success_rate,
        100.0 * agg.collision_rate,
        100.0 * agg.timeout_rate,
        100.0 * agg.inference_rate,
        agg.us_per_tick,
        agg.episodes
    );
    let dir = out_dir(&args.out, "out/eval");
    write_json(
        &dir.join("eval.json"),
        &serde_json::json!({"method": args.method, "map": map.name, "seed": args.agent.seed, "aggregate": agg, "episodes": results}),
    )?;
    println!("wrote {}/eval.json", dir.display());
    Ok(())
}
