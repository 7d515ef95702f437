//! Records the scaled agent's reasoning ticks on the jaywalk family of maps and replays
//! them (see `unforeseen_harness::episodes::tick_recording`): prints the digest of every replayed decision (equal
//! digests = bit-identical results) and the distribution of the ticks' wall-clock times.
//! Built for profiles and instruction counts, which need a short run without criterion:
//!
//! ```sh
//! cargo build --release --example replay_ticks
//! target/release/unforeseen train --out agent7.ron          # the benches' agent
//! target/release/examples/replay_ticks --agent agent7.ron --horizon 3 --passes 20
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*replay_pass*' \
//!     target/release/examples/replay_ticks --agent agent7.ron --passes 1
//! ```
//!
//! Options: `--agent FILE` (default: train the default agent, 6000 episodes, seed 7),
//! `--horizon H` (3), `--episodes N` per map (10), `--seed S` (7), `--passes P` (5),
//! `--set key=value` (any `ScaledParams` key, repeatable), `--evict-kb K` (write K KiB
//! after every tick, untimed, as the physics of a real episode would), `--json FILE` (the figures as
//! JSON), `--write-sequence FILE` (every recorded tick as JSON: observation, action,
//! whether it reasoned, whether it starts an episode; `scripts/pymdp_bench.py` runs
//! pymdp on the same observations).

use std::path::PathBuf;
use std::time::Instant;

use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_harness::episodes::{Recording, ReplayOutcome, TickTimes, jaywalk_family, record};
use unforeseen_harness::training::agent_file;
use unforeseen_harness::training::{DEFAULT_TRAIN_EPISODES, TrainConfig, train};
use unforeseen_sim::embedded;

/// One replay of the whole recording (a named function, for callgrind's `--toggle-collect`).
/// With `evict` non-empty, every byte-line of it is written after each tick (untimed), the
/// way the physics between two ticks of a real episode pushes the agent's data out of
/// the caches.
#[inline(never)]
fn replay_pass(rec: &Recording, agent: &mut ScaledAgent, times: &mut TickTimes, evict: &mut [u8]) -> ReplayOutcome {
    rec.replay(agent, |r, e| {
        times.push(r, e);
        for b in evict.iter_mut().step_by(64) {
            *b = b.wrapping_add(1);
        }
    })
}

fn main() -> anyhow::Result<()> {
    let mut agent_path: Option<PathBuf> = None;
    let (mut horizon, mut episodes, mut seed, mut passes) = (3usize, 10u64, 7u64, 5usize);
    let mut sets: Vec<String> = Vec::new();
    let (mut json, mut sequence): (Option<PathBuf>, Option<PathBuf>) = (None, None);
    let mut evict_kb = 0usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| anyhow::anyhow!("{a} needs a value"));
        match a.as_str() {
            "--agent" => agent_path = Some(value()?.into()),
            "--horizon" => horizon = value()?.parse()?,
            "--episodes" => episodes = value()?.parse()?,
            "--seed" => seed = value()?.parse()?,
            "--passes" => passes = value()?.parse()?,
            "--set" => sets.push(value()?),
            "--json" => json = Some(value()?.into()),
            "--evict-kb" => evict_kb = value()?.parse()?,
            "--write-sequence" => sequence = Some(value()?.into()),
            other => anyhow::bail!("unknown argument {other} (see the example's docs)"),
        }
    }
    let bundle = match &agent_path {
        Some(p) => agent_file::load(p)?,
        None => {
            let map = embedded::load("intersection")?;
            train(&map, &TrainConfig::new(DEFAULT_TRAIN_EPISODES, 7))?.0
        }
    };
    let mut base = ScaledParams::default();
    base.planning.horizon = horizon;
    let params = unforeseen_harness::overrides::apply(base, &sets)?;
    let maps = jaywalk_family()?;
    let started = Instant::now();
    let rec = record(&bundle, &params, &maps, episodes, seed)?;
    let successes = rec.episodes.iter().filter(|e| e.success).count();
    println!(
        "recorded {} episodes on {} maps ({} successful) in {:.2} s: {} ticks, {} reasoning (H = {horizon})",
        rec.episodes.len(),
        maps.len(),
        successes,
        started.elapsed().as_secs_f64(),
        rec.ticks(),
        rec.reasoning_ticks()
    );
    if let Some(path) = &sequence {
        let (mut obs, mut actions): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
        let (mut reasoned, mut starts): (Vec<bool>, Vec<bool>) = (Vec::new(), Vec::new());
        for e in &rec.episodes {
            obs.extend(&e.obs);
            actions.extend(&e.actions);
            reasoned.extend(&e.reasoned);
            starts.extend((0..e.obs.len()).map(|k| k == 0));
        }
        let v = serde_json::json!({"horizon": horizon, "obs": obs, "actions": actions, "reasoned": reasoned, "episode_start": starts});
        std::fs::write(path, serde_json::to_string(&v)?)?;
    }
    let mut agent = ScaledAgent::new(bundle.world_model.clone(), &bundle.q_learning, params)?;
    let mut times = TickTimes::default();
    let mut evict = vec![0u8; evict_kb * 1024];
    let mut digest = None;
    // Per tick, the fastest of the passes: robust to other processes on a loaded machine.
    let mut fastest = TickTimes::default();
    for pass in 0..passes {
        let mut this = TickTimes::default();
        let out = replay_pass(&rec, &mut agent, &mut this, &mut evict);
        if pass == 0 {
            fastest = this.clone();
        } else {
            for (f, t) in fastest.reasoning_ns.iter_mut().zip(&this.reasoning_ns) {
                *f = (*f).min(*t);
            }
            for (f, t) in fastest.feedforward_ns.iter_mut().zip(&this.feedforward_ns) {
                *f = (*f).min(*t);
            }
        }
        times.reasoning_ns.extend(&this.reasoning_ns);
        times.feedforward_ns.extend(&this.feedforward_ns);
        if *digest.get_or_insert(out.digest) != out.digest {
            anyhow::bail!(
                "replays disagree: digest {:016x} vs {:016x}",
                out.digest,
                digest.unwrap_or(0)
            );
        }
    }
    if let Some(d) = digest {
        println!("digest {d:016x}");
        println!("reasoning ticks:    {}", times.reasoning());
        println!("feed-forward ticks: {}", times.feedforward());
        println!(
            "reasoning ticks, each the fastest of {passes} passes:    {}",
            fastest.reasoning()
        );
        println!(
            "feed-forward ticks, each the fastest of {passes} passes: {}",
            fastest.feedforward()
        );
        if let Some(path) = &json {
            let summary = |t: unforeseen_harness::episodes::TimeSummary| serde_json::json!({"n": t.n, "mean_us": t.mean, "p10_us": t.p10, "median_us": t.p50, "p90_us": t.p90});
            let v = serde_json::json!({
                "horizon": horizon,
                "passes": passes,
                "episodes": rec.episodes.len(),
                "ticks": rec.ticks(),
                "reasoning_ticks": rec.reasoning_ticks(),
                "digest": format!("{d:016x}"),
                "reasoning": summary(times.reasoning()),
                "reasoning_fastest_of_passes": summary(fastest.reasoning()),
                "feedforward": summary(times.feedforward()),
            });
            std::fs::write(path, serde_json::to_string_pretty(&v)?)?;
        }
    }
    Ok(())
}
