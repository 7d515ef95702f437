//! Recorded reasoning ticks: the ticks the scaled agent really reasons on, as
//! they occur in evaluation episodes, kept so that they can be replayed and timed alone.
//!
//! [`record`] runs zero-shot evaluation episodes (a fresh agent per episode, the seeds of
//! `eval`) of the scaled agent on a set of maps through the ordinary episode runner, and
//! keeps what the agent saw and did at every tick: the observation, the action and
//! whether the tick reasoned. The agent is deterministic given its episode seed and its
//! observations, so feeding the same observations to an agent built from the same
//! bundle with the same parameters rebuilds every reasoning tick exactly: the same VMP
//! window (observations, actions, the beliefs it starts from), the same `q_t`, the same
//! EFE tree. [`Recording::replay`] does that and times each tick alone; it checks that
//! every replayed tick takes the recorded action and reasons when the recording did.
//!
//! [`Recording::replay`] also folds every replayed decision (action, surprise, `θ`,
//! policy, `ψ`, and on reasoning ticks `G` and `q(π)`) into a 64-bit digest of their
//! bits: two builds that print the same digest computed the same numbers, bit for bit.

use std::time::{Duration, Instant};

use unforeseen_agent::controller::{Controller, Decision, Ending};
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::Map;

use crate::episodes::evaluation::eval_seeds;
use crate::episodes::methods::Method;
use crate::episodes::runner::run_episode;
use crate::error::Error;

/// One recorded episode.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedEpisode {
    /// The map's name.
    pub map: String,
    /// Evaluation episode index on that map.
    pub episode: u64,
    /// The controller's seed (`begin_episode`).
    pub controller_seed: u64,
    /// The observation of every tick.
    pub obs: Vec<usize>,
    /// The action of every tick.
    pub actions: Vec<usize>,
    /// Whether every tick reasoned.
    pub reasoned: Vec<bool>,
    /// Whether the episode reached the goal without a collision.
    pub success: bool,
}

/// The recorded episodes of one run of [`record`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Recording {
    /// The episodes, map by map, in episode order.
    pub episodes: Vec<RecordedEpisode>,
}

/// The maps of the jaywalk family: every embedded test map of the straight road (a
/// pedestrian on the road when the training map never showed one there), i.e. all
/// embedded maps but `intersection` and the junction's.
pub fn jaywalk_family() -> Result<Vec<Map>, Error> {
    let mut maps = Vec::new();
    for name in unforeseen_sim::embedded::names()
        .iter()
        .filter(|n| **n != "intersection")
    {
        let map = unforeseen_sim::embedded::load(name)?;
        if map.junction.is_none() {
            maps.push(map);
        }
    }
    Ok(maps)
}

/// Wraps a controller and keeps what it saw and did.
struct Recorder<'a> {
    inner: &'a mut ScaledAgent,
    obs: Vec<usize>,
    actions: Vec<usize>,
    reasoned: Vec<bool>,
}

impl Controller for Recorder<'_> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn begin_episode(&mut self, seed: u64) {
        self.inner.begin_episode(seed);
    }
    fn act(&mut self, obs: usize) -> Decision {
        let d = self.inner.act(obs);
        self.obs.push(obs);
        self.actions.push(d.action);
        self.reasoned.push(d.reasoned);
        d
    }
    fn observe(&mut self, reward: f64, next_obs: usize, ending: Ending) {
        self.inner.observe(reward, next_obs, ending);
    }
    fn end_episode(&mut self) {
        self.inner.end_episode();
    }
}

/// Runs `episodes` zero-shot evaluation episodes of the scaled agent (`bundle`, `params`)
/// on every map (the seeds of `eval --seed seed`) and records them.
pub fn record(
    bundle: &AgentBundle,
    params: &ScaledParams,
    maps: &[Map],
    episodes: u64,
    seed: u64,
) -> Result<Recording, Error> {
    let mut out = Recording::default();
    for map in maps {
        let mut env = Env::new(map, EnvConfig::default())?;
        for ep in 0..episodes {
            let mut agent = ScaledAgent::new(bundle.world_model.clone(), &bundle.q_learning, params.clone())?;
            let seeds = eval_seeds(seed, map, Method::Scaled, ep);
            let mut rec = Recorder {
                inner: &mut agent,
                obs: Vec::new(),
                actions: Vec::new(),
                reasoned: Vec::new(),
            };
            let (result, _) = run_episode(&mut env, &mut rec, seeds, false)?;
            out.episodes.push(RecordedEpisode {
                map: map.name.clone(),
                episode: ep,
                controller_seed: seeds.controller,
                obs: rec.obs,
                actions: rec.actions,
                reasoned: rec.reasoned,
                success: result.success,
            });
        }
    }
    Ok(out)
}

/// What one replay computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplayOutcome {
    /// Ticks replayed.
    pub ticks: usize,
    /// Of which reasoning ticks.
    pub reasoning_ticks: usize,
    /// The digest of every decision (see the module docs).
    pub digest: u64,
}

impl Recording {
    /// Ticks in all episodes.
    pub fn ticks(&self) -> usize {
        self.episodes.iter().map(|e| e.obs.len()).sum()
    }

    /// Reasoning ticks in all episodes.
    pub fn reasoning_ticks(&self) -> usize {
        self.episodes
            .iter()
            .map(|e| e.reasoned.iter().filter(|r| **r).count())
            .sum()
    }

    /// Replays every episode on `agent` (which must be built from the recording's bundle
    /// and parameters; its episode state is reset here, and `end_episode` is not called,
    /// so the model does not change), timing every tick alone. `on_tick(reasoned,
    /// elapsed)` receives each tick's wall-clock time inside `act`.
    ///
    /// # Panics
    /// If a replayed tick's action or reasoning differs from the recording's.
    pub fn replay(&self, agent: &mut ScaledAgent, mut on_tick: impl FnMut(bool, Duration)) -> ReplayOutcome {
        let mut digest = Digest::default();
        let mut out = ReplayOutcome {
            ticks: 0,
            reasoning_ticks: 0,
            digest: 0,
        };
        for e in 0..self.episodes.len() {
            let (ticks, reasoning) = self.replay_episode(e, agent, Some(&mut digest), &mut on_tick);
            out.ticks += ticks;
            out.reasoning_ticks += reasoning;
        }
        out.digest = digest.0;
        out
    }

    /// Replays episode `e` alone (see [`Recording::replay`]; no digest); returns its
    /// ticks and reasoning ticks.
    pub fn replay_one(
        &self,
        e: usize,
        agent: &mut ScaledAgent,
        mut on_tick: impl FnMut(bool, Duration),
    ) -> (usize, usize) {
        self.replay_episode(e, agent, None, &mut on_tick)
    }

    fn replay_episode(
        &self,
        e: usize,
        agent: &mut ScaledAgent,
        mut digest: Option<&mut Digest>,
        on_tick: &mut impl FnMut(bool, Duration),
    ) -> (usize, usize) {
        let e = &self.episodes[e];
        let mut reasoning = 0;
        agent.begin_episode(e.controller_seed);
        for (k, &o) in e.obs.iter().enumerate() {
            let started = Instant::now();
            let d = agent.act(o);
            let elapsed = started.elapsed();
            on_tick(d.reasoned, elapsed);
            assert!(
                d.action == e.actions[k] && d.reasoned == e.reasoned[k],
                "replay of {} episode {} tick {k} differs from the recording",
                e.map,
                e.episode
            );
            if let Some(digest) = digest.as_deref_mut() {
                digest.decision(&d);
                if d.reasoned {
                    let tr = agent.last_reasoning();
                    digest.floats(&tr.g);
                    digest.floats(&tr.q_pi);
                }
            }
            reasoning += usize::from(d.reasoned);
        }
        (e.obs.len(), reasoning)
    }
}

/// Wall-clock times of replayed ticks, split by kind, with their quantiles.
#[derive(Debug, Clone, Default)]
pub struct TickTimes {
    /// Nanoseconds of every reasoning tick.
    pub reasoning_ns: Vec<u64>,
    /// Nanoseconds of every feed-forward tick.
    pub feedforward_ns: Vec<u64>,
}

/// Quantiles of a set of tick times, in microseconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeSummary {
    /// Ticks.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// 10th percentile.
    pub p10: f64,
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
}

impl std::fmt::Display for TimeSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "median {:.2} us, p10-p90 {:.2}-{:.2} us, mean {:.2} us over {} ticks",
            self.p50, self.p10, self.p90, self.mean, self.n
        )
    }
}

impl TickTimes {
    /// Adds one tick (the callback of [`Recording::replay`]).
    pub fn push(&mut self, reasoned: bool, elapsed: Duration) {
        let ns = elapsed.as_nanos() as u64;
        if reasoned {
            self.reasoning_ns.push(ns);
        } else {
            self.feedforward_ns.push(ns);
        }
    }

    /// Quantiles of the reasoning ticks.
    pub fn reasoning(&self) -> TimeSummary {
        summary(&self.reasoning_ns)
    }

    /// Quantiles of the feed-forward ticks.
    pub fn feedforward(&self) -> TimeSummary {
        summary(&self.feedforward_ns)
    }
}

fn summary(ns: &[u64]) -> TimeSummary {
    let mut v = ns.to_vec();
    v.sort_unstable();
    let q = |p: f64| {
        if v.is_empty() {
            0.0
        } else {
            v[((v.len() - 1) as f64 * p).round() as usize] as f64 / 1e3
        }
    };
    TimeSummary {
        n: v.len(),
        mean: if v.is_empty() {
            0.0
        } else {
            v.iter().sum::<u64>() as f64 / v.len() as f64 / 1e3
        },
        p10: q(0.1),
        p50: q(0.5),
        p90: q(0.9),
    }
}

/// FNV-1a over the bits of what a controller decided.
struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Digest(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    fn word(&mut self, w: u64) {
        for b in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn floats(&mut self, x: &[f64]) {
        self.word(x.len() as u64);
        x.iter().for_each(|v| self.word(v.to_bits()));
    }
    fn decision(&mut self, d: &Decision) {
        self.word(d.action as u64);
        self.word(u64::from(d.reasoned));
        self.word(d.surprise.map_or(u64::MAX, f64::to_bits));
        self.word(d.theta.map_or(u64::MAX, f64::to_bits));
        self.floats(&d.policy);
        match &d.psi {
            Some(p) => self.floats(p),
            None => self.word(u64::MAX),
        }
        self.word(u64::from(d.scaling_iters));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jaywalk_family_has_every_test_map() {
        let maps = jaywalk_family().unwrap();
        assert!(maps.iter().any(|m| m.name == "jaywalk"));
        assert!(maps.iter().all(|m| m.name != "intersection" && m.junction.is_none()));
        assert_eq!(maps.len(), 10);
    }
}
