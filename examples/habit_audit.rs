//! Audits the scaled agent around a habit on one map (issue 32, EXPERIMENTS.md "The
//! competence check"): success, collisions, time-outs and red-light entries, the share
//! of ticks that reasoned and of those the competence check added, and the time a
//! decision takes, for the habit alone and wrapped.
//!
//! ```sh
//! cargo build --release --example habit_audit
//! target/release/examples/habit_audit AGENT.ron MAP HABIT [EPISODES] [zero-shot|continual] [key=value ...]
//! ```
//!
//! `HABIT` is `q` (the agent's Q-table, the scaled agent itself), `maintain` (always
//! maintain), `standstill` (maintain at a standstill, else speed up) or `speed-up`
//! (always speed up). Prints one JSON object per line: the habit alone (`bare`, the
//! greedy action of the habit's table) and wrapped. Episodes are seeded as
//! `eval --seed 7` seeds them. `TRACE=N` prints episode N's ticks on stderr, `TRACE=all`
//! the ticks the competence check sent to reasoning. `HABIT = held` prints instead, for
//! every state, the check's `G_held(u)` and the regret of holding "maintain".

use std::path::Path;

use unforeseen_agent::controller::{Controller, Decision, Dist, Ending};
use unforeseen_agent::habit::TableHabit;
use unforeseen_agent::maths::argmax;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::eval_seeds;
use unforeseen_harness::episodes::{EpisodeResult, run_episode};

/// The greedy action of a per-state table: the habit alone.
struct Bare(Vec<f64>);

impl Controller for Bare {
    fn name(&self) -> &'static str {
        "bare"
    }
    fn begin_episode(&mut self, _seed: u64) {}
    fn act(&mut self, obs: usize) -> Decision {
        let row = &self.0[obs * 3..obs * 3 + 3];
        Decision {
            action: argmax(row),
            reasoned: false,
            surprise: None,
            theta: None,
            policy: Dist::from_slice(row),
            psi: None,
            scaling_iters: 0,
        }
    }
    fn observe(&mut self, _reward: f64, _next_obs: usize, _ending: Ending) {}
    fn end_episode(&mut self) {}
}

#[derive(Default)]
struct Tally {
    episodes: u64,
    success: u64,
    collision: u64,
    timeout: u64,
    red_lights: u64,
    ticks: u64,
    reasoning: u64,
    checked: u64,
    decide_ns: u64,
    /// Episodes that ended in a collision or a time-out.
    failed: Vec<u64>,
}

impl Tally {
    fn add(&mut self, r: &EpisodeResult, checked: u64) {
        if !r.success {
            self.failed.push(self.episodes);
        }
        self.episodes += 1;
        self.success += u64::from(r.success);
        self.collision += u64::from(r.collision);
        self.timeout += u64::from(r.timeout);
        self.red_lights += u64::from(r.red_lights);
        self.ticks += u64::from(r.ticks);
        self.reasoning += u64::from(r.reasoning_ticks);
        self.checked += checked;
        self.decide_ns += r.decide_ns;
    }
    fn json(&self, what: &str) -> serde_json::Value {
        let share = |x: u64, n: u64| x as f64 / n.max(1) as f64;
        serde_json::json!({
            "controller": what,
            "episodes": self.episodes,
            "success": share(self.success, self.episodes),
            "collision": share(self.collision, self.episodes),
            "timeout": share(self.timeout, self.episodes),
            "red_light": share(self.red_lights, self.episodes),
            "reasoning_share": share(self.reasoning, self.ticks),
            "checked_share": share(self.checked, self.ticks),
            "decision_us": self.decide_ns as f64 / self.ticks.max(1) as f64 / 1000.0,
            "failed_episodes": self.failed,
        })
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        return Err("usage: habit_audit AGENT.ron MAP HABIT [EPISODES] [zero-shot|continual] [key=value ...]".into());
    }
    let bundle = unforeseen_harness::training::agent_file::load(Path::new(&args[1]))?;
    let map = unforeseen_harness::maps::load(&args[2])?;
    let episodes: u64 = args.get(4).map_or(Ok(100), |s| s.parse())?;
    let continual = match args.get(5).map_or("continual", String::as_str) {
        "continual" => true,
        "zero-shot" => false,
        other => return Err(format!("protocol {other:?}: expected zero-shot or continual").into()),
    };
    let mut params = ScaledParams::default();
    for kv in args.iter().skip(6) {
        let (k, v) = kv.split_once('=').ok_or("expected key=value")?;
        params.set_str(k, v)?;
    }
    let mut model = bundle.world_model.clone();
    if args[3] == "held" {
        model.plan_with_crash_model(params.planning.crash_model == unforeseen_agent::params::CrashPlanning::Hazard);
        let mut c = unforeseen_agent::competence::Competence::new(model.n_states(), model.n_states(), 3);
        for s in 0..model.n_states() {
            let mut q = vec![0.0; model.n_states()];
            q[s] = 1.0;
            let r = c.regret(
                model.planning_generative(),
                model.generative(),
                &q,
                None,
                0,
                params.gate.competence_horizon,
            );
            let st = model.structure().decode(s);
            println!(
                "{st:?} G_held(maintain, speed-up, slow-down) = {:.3?} regret(maintain) {r:.3}",
                c.held()
            );
        }
        return Ok(());
    }
    let structure = model.structure().clone();
    let nu0 = params.learning.nu0;
    let table: Vec<f64> = match args[3].as_str() {
        "q" => TableHabit::from_q(bundle.q_learning.table(), 3, 1.0, params.learning.nu_temperature)
            .nu()
            .to_vec(),
        habit => (0..model.n_states())
            .flat_map(|s| {
                let v = structure.decode(s)[1];
                let a = match habit {
                    "maintain" => 0,
                    "standstill" if v == 0 => 0,
                    "standstill" | "speed-up" => 1,
                    _ => 3,
                };
                (0..3).map(move |u| f64::from(u8::from(u == a)))
            })
            .collect(),
    };
    if table.chunks(3).any(|r| r.iter().sum::<f64>() == 0.0) {
        return Err(format!("habit {:?}: expected q, maintain, standstill or speed-up", args[3]).into());
    }
    let mut env = Env::new(&map, EnvConfig::default())?;
    let build = || -> Result<ScaledAgent<TableHabit>, Box<dyn std::error::Error>> {
        let habit = TableHabit::from_probs(&table, 3, nu0)?;
        Ok(ScaledAgent::with_habit(model.clone(), habit, params.clone().check()?)?)
    };
    let mut bare = Tally::default();
    let mut wrapped = Tally::default();
    let mut agent = build()?;
    for ep in 0..episodes {
        let seeds = eval_seeds(7, &map, Method::Scaled, ep);
        let (r, _) = run_episode(&mut env, &mut Bare(table.clone()), seeds, false)?;
        bare.add(&r, 0);
        if !continual {
            agent = build()?;
        }
        let traced = std::env::var("TRACE").is_ok_and(|t| t == ep.to_string() || t == "all");
        let (r, ticks) = run_episode(&mut env, &mut agent, seeds, traced)?;
        for (t, c) in ticks.iter().zip(agent.checked_history()) {
            if std::env::var("TRACE").is_ok_and(|t| t == "all") && !*c {
                continue;
            }
            eprintln!(
                "t={} state(d,v,L,p)=({},{},{},{}) action={:?} reasoned={} checked={c} theta={:?} policy={:?}",
                t.step, t.state.d, t.state.v, t.state.l, t.state.p, t.action, t.reasoned, t.theta, t.policy
            );
        }
        let checked = agent.checked_history().iter().filter(|c| **c).count() as u64;
        wrapped.add(&r, checked);
    }
    println!("{}", bare.json("bare"));
    println!("{}", wrapped.json("wrapped"));
    Ok(())
}
