//! Times the planning tick of the general agent (`unforeseen_agent::aif`) on a model of
//! pymdp's environments as stored by `scripts/pymdp_envs_reference.py`: replays the
//! stored rollout's observations and actions (the prior back to `D` at each reset) and
//! times each tick, `infer_states` + `infer_policies` + `sample_action` +
//! `update_empirical_prior`, with the gate open. `scripts/pymdp_envs_bench.py` runs pymdp
//! on the same sequence.
//!
//! ```sh
//! cargo build --release --example aif_ticks
//! target/release/examples/aif_ticks agent/tests/data/pymdp/tmaze.json 3 20
//! ```
//!
//! Arguments: the reference JSON, the policy length (default: the file's), the passes
//! over the sequence (default 20). Prints one JSON line: the median and mean µs per tick
//! over the passes, and the action chosen at every tick of the last pass.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::model::Model;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or("usage: aif_ticks REFERENCE.json [POLICY_LEN] [PASSES]")?;
    let r: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    let policy_len = match args.get(1) {
        Some(t) => t.parse()?,
        None => r["model"]["policy_len"].as_u64().ok_or("no policy_len")? as usize,
    };
    let passes: usize = args.get(2).map_or(Ok(20), |p| p.parse())?;
    let params = AgentParams {
        policy_len,
        gamma: r["model"]["gamma"].as_f64().unwrap_or(1.0),
        ..AgentParams::default()
    };
    let agent = Agent::new(Model::from_json(&r["model"])?, params, None)?;
    let steps = r["rollout"].as_array().ok_or("no rollout")?;
    let seq: Vec<(bool, Vec<usize>, Vec<usize>)> = steps
        .iter()
        .map(|s| {
            let v = |k: &str| serde_json::from_value::<Vec<usize>>(s[k].clone());
            Ok((s["reset"].as_bool().unwrap_or(false), v("obs")?, v("action")?))
        })
        .collect::<Result<_, serde_json::Error>>()?;
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut per_pass = Vec::with_capacity(passes);
    let mut chosen = Vec::new();
    for _ in 0..passes.max(1) {
        chosen.clear();
        let mut prior = agent.initial_prior();
        let t0 = Instant::now();
        for (reset, obs, action) in &seq {
            if *reset {
                prior = agent.initial_prior();
            }
            let qs = agent.infer_states(obs, &prior)?;
            let post = agent.infer_policies(&qs);
            chosen.push(agent.sample_action(&post.q_pi, &mut rng));
            prior = agent.update_empirical_prior(action, &qs)?;
        }
        per_pass.push(t0.elapsed().as_secs_f64() * 1e6 / seq.len() as f64);
    }
    let mean = per_pass.iter().sum::<f64>() / per_pass.len() as f64;
    per_pass.sort_by(f64::total_cmp);
    let median = per_pass[per_pass.len() / 2];
    let out = serde_json::json!({
        "env": r["env"], "policy_len": policy_len, "policies": agent.policies().len(),
        "ticks": seq.len(), "passes": per_pass.len(), "tick_us_median": median, "tick_us_mean": mean,
        "actions": chosen,
    });
    println!("{out}");
    Ok(())
}
