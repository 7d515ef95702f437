//! The request of an estimate ([`EstimateRequest`]): every choice its user makes, as one
//! serde value the command line builds from its flags; its planning
//! ([`EstimateRequest::plan`]) owns the defaults and the checks (those of the search's
//! space, method and agents, [`SearchRequest::setup`], then the estimator's), takes the
//! output guard and returns the job.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

use crate::episodes::Method;
use crate::episodes::Protocol;
use crate::error::Error;
use crate::progress::Progress;
use crate::runs::batch::{AgentChoice, Shard};
use crate::runs::outputs::Guarded;
use crate::runs::search::{Evaluator, SearchConfig, SearchRequest, SearchSetup};
use crate::training::TimeoutAs;
use crate::training::seed_agents::{Agent, TrainSeeds};

use super::{MAX_BUDGET, MIN_BLOCK, Report};

/// An estimator of a failure probability (module doc of [`super`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Estimator {
    /// Plain Monte Carlo, the reference.
    Mc,
    /// Cross-entropy importance sampling aimed at failures on fair scenarios (P(fails | fair)).
    Is,
    /// Cross-entropy importance sampling aimed at failures on any scenario (P(fails)).
    IsFails,
}

impl Estimator {
    /// Every estimator.
    pub const ALL: [Estimator; 3] = [Estimator::Mc, Estimator::Is, Estimator::IsFails];

    /// Whether it samples by importance (`is`, `is-fails`).
    pub fn weighted(self) -> bool {
        self != Estimator::Mc
    }

    /// Its name (`mc`, `is`, `is-fails`).
    pub fn name(self) -> &'static str {
        match self {
            Estimator::Mc => "mc",
            Estimator::Is => "is",
            Estimator::IsFails => "is-fails",
        }
    }

    /// One line on what it does.
    pub fn summary(self) -> &'static str {
        match self {
            Estimator::Mc => "plain Monte Carlo: uniform draws, Wilson interval",
            Estimator::Is => {
                "cross-entropy importance sampling toward failures on fair scenarios (P(fails | fair)), \
                 weighted interval"
            }
            Estimator::IsFails => {
                "cross-entropy importance sampling toward failures on any scenario (P(fails)), weighted interval"
            }
        }
    }

    /// The fewest draws it runs with: one block (`mc`), or two cross-entropy rounds and
    /// two final blocks (`is`, `is-fails`: the rounds take at most half the budget).
    pub fn min_budget(self) -> usize {
        match self {
            Estimator::Mc => MIN_BLOCK,
            Estimator::Is | Estimator::IsFails => 4 * MIN_BLOCK,
        }
    }
}

impl std::fmt::Display for Estimator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Estimator {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Estimator::ALL
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| format!("unknown estimator '{s}': expected mc, is or is-fails"))
    }
}

/// Every choice of an estimate, with its defaults ([`EstimateRequest::default`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EstimateRequest {
    /// The space file (RON; maps/README.md, "Space files"). Required.
    pub space: PathBuf,
    /// The base map (file or embedded name) that the space varies. Default `jaywalk`.
    pub map: String,
    /// The method whose failures are counted. Default `scaled`.
    pub method: Method,
    /// Its evaluation protocol on each draw. Default zero-shot.
    pub protocol: Protocol,
    /// The estimator. Default `mc`, the one that measured narrower on the project's
    /// spaces (EXPERIMENTS.md, "How rare is a failure").
    pub estimator: Estimator,
    /// Stop once the relative half-width of what the estimator aims at (both probabilities
    /// for `mc`, P(fails | fair) for `is`, P(fails) for `is-fails`) is at most this, in (0, 1).
    /// Default 0.3.
    pub target_rel_error: f64,
    /// Most draws (points of the space evaluated). Default 2000.
    pub budget: usize,
    /// Episodes per draw, for each witness and for the method (per training seed).
    /// Default 4.
    pub episodes: u64,
    /// Run seed: every draw and episode derive from it. Default 7.
    pub seed: u64,
    /// Worker threads; results do not depend on it. Default: every core.
    pub jobs: Option<usize>,
    /// Evaluate only this shard's part of the next stage (module doc of [`super`],
    /// "Shards"): the draws `≡ I − 1 (mod N)` of the first stage that the draws in `out`
    /// (with `resume`) do not complete. Default: none.
    pub shard: Option<Shard>,
    /// Keep the draws of the same request in `out` and evaluate the rest. Default false.
    pub resume: bool,
    /// Output folder. Default `out/estimate`.
    pub out: PathBuf,
    /// Replace files in `out` that an estimate did not write. Default false.
    pub force: bool,
    /// An agent file (from `unforeseen train`). Default: none.
    pub agent: Option<PathBuf>,
    /// One agent per training seed, each trained on `train_map` (a list, or text such as
    /// `1..10`). Default: none.
    pub train_seeds: Option<TrainSeeds>,
    /// The training map (file or embedded name) of agents trained here. Default as the
    /// search's (`intersection`).
    pub train_map: String,
    /// Training episodes of agents trained here. Default as the search's.
    pub train_episodes: u64,
    /// What a training episode's time-out is to the learners. Default truncation.
    pub timeout_as: TimeoutAs,
    /// The folder of the agent cache of `train_seeds`; none: no cache. Default as the
    /// search's.
    pub cache: Option<PathBuf>,
}

impl Default for EstimateRequest {
    fn default() -> Self {
        let search = SearchRequest::default();
        EstimateRequest {
            space: PathBuf::new(),
            map: search.map,
            method: search.method,
            protocol: search.protocol,
            estimator: Estimator::Mc,
            target_rel_error: 0.3,
            budget: 2000,
            episodes: 4,
            seed: search.seed,
            jobs: None,
            shard: None,
            resume: false,
            out: PathBuf::from("out/estimate"),
            force: false,
            agent: None,
            train_seeds: None,
            train_map: search.train_map,
            train_episodes: search.train_episodes,
            timeout_as: search.timeout_as,
            cache: search.cache,
        }
    }
}

/// An estimate request checked and resolved, before any file is written.
#[derive(Debug, Clone)]
pub struct EstimateSetup {
    /// The request.
    pub request: EstimateRequest,
    /// The search's setup of the same space, method, agents, episodes and seed.
    pub search: SearchSetup,
}

impl EstimateRequest {
    /// The search request of the same space, method, agents, episodes and seed (one
    /// candidate: the estimate has its own budget), whose candidates are the estimate's
    /// draws (what a distributed driver's tasks evaluate).
    pub fn search(&self) -> SearchRequest {
        SearchRequest {
            space: self.space.clone(),
            map: self.map.clone(),
            method: self.method,
            protocol: self.protocol,
            budget: 1,
            episodes: self.episodes,
            seed: self.seed,
            jobs: self.jobs,
            out: self.out.clone(),
            force: self.force,
            agent: self.agent.clone(),
            train_seeds: self.train_seeds.clone(),
            train_map: self.train_map.clone(),
            train_episodes: self.train_episodes,
            timeout_as: self.timeout_as,
            cache: self.cache.clone(),
            ..SearchRequest::default()
        }
    }

    /// Checks the request and resolves it: the target, the budget, then the search's
    /// checks (the base map, the space, the agents). Writes nothing.
    pub fn setup(&self) -> Result<EstimateSetup, Error> {
        let r = self.target_rel_error;
        if !(r > 0.0 && r < 1.0) {
            return Err(Error::Request {
                field: "target_rel_error".into(),
                value: Some(r.to_string()),
                problem: "expected a relative half-width in (0, 1), e.g. 0.3".into(),
            });
        }
        let min = self.estimator.min_budget();
        if self.budget < min || self.budget > MAX_BUDGET {
            return Err(Error::Request {
                field: "budget".into(),
                value: Some(self.budget.to_string()),
                problem: format!(
                    "{} needs {min} to {MAX_BUDGET} draws (its first stage takes {min})",
                    self.estimator
                ),
            });
        }
        let search = self.search().setup(None)?;
        Ok(EstimateSetup {
            request: self.clone(),
            search,
        })
    }

    /// [`EstimateRequest::setup`], then the output guard (the folder `out`, none of the
    /// inputs in it; taken and held by the job). Trains and runs nothing.
    pub fn plan(&self) -> Result<EstimateJob, Error> {
        let setup = self.setup()?;
        let mut guard = super::output::outputs(&self.out)
            .input("map", &self.map)
            .input("space", &self.space);
        if let Some(agent) = &self.agent {
            guard = guard.input("agent", agent);
        }
        if matches!(setup.search.agents, AgentChoice::Trained { .. }) {
            guard = guard.input("train_map", &self.train_map);
        }
        let guard = guard.guard(self.force)?;
        Ok(EstimateJob { setup, guard })
    }
}

/// An estimate planned ([`EstimateRequest::plan`]), holding its output guard.
pub struct EstimateJob {
    /// The request resolved.
    pub setup: EstimateSetup,
    guard: Guarded,
}

impl EstimateJob {
    /// Runs the estimate with `agents` ([`SearchSetup::agents`]) into the request's `out`
    /// (`estimate.jsonl` and `summary.json`, [`super::output`]; a shard's
    /// `estimate.jsonl` alone).
    pub fn run(&self, agents: &[Agent], progress: &dyn Progress) -> Result<Report, Error> {
        let s = &self.setup.search;
        self.run_with(&s.config(agents, s.jobs, String::new()), progress, None)
    }

    /// [`EstimateJob::run`] on the configuration `cfg` (of [`EstimateSetup::search`]),
    /// with the draws evaluated by `remote` when given (a distributed driver's): the same
    /// files.
    pub fn run_with(
        &self,
        cfg: &SearchConfig<'_>,
        progress: &dyn Progress,
        remote: Option<&dyn Evaluator>,
    ) -> Result<Report, Error> {
        cfg.check()?;
        super::run(cfg, &self.setup.request, &self.guard, progress, remote)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(estimator: Estimator, budget: usize, target: f64) -> EstimateRequest {
        EstimateRequest {
            space: "maps/spaces/jaywalk.ron".into(),
            method: Method::BrakeOnPedestrian,
            estimator,
            budget,
            target_rel_error: target,
            ..EstimateRequest::default()
        }
    }

    #[test]
    fn bad_settings_are_named_by_their_field() {
        for target in [0.0, -0.1, 1.0, f64::NAN] {
            let e = request(Estimator::Mc, 100, target).setup().unwrap_err();
            assert!(e.to_string().starts_with("target_rel_error "), "{e}");
        }
        let e = request(Estimator::Is, 199, 0.3).setup().unwrap_err();
        assert!(e.to_string().contains("budget") && e.to_string().contains("200"), "{e}");
        assert!(e.is_user_input(), "{e}");
        let e = request(Estimator::Mc, 49, 0.3).setup().unwrap_err();
        assert!(e.to_string().contains("50"), "{e}");
        assert_eq!(
            "splitting".parse::<Estimator>().unwrap_err(),
            "unknown estimator 'splitting': expected mc, is or is-fails"
        );
        let e = EstimateRequest::default().setup().unwrap_err();
        assert!(e.to_string().starts_with("space: "), "{e}");
    }

    #[test]
    fn the_draws_agents_train_on_the_training_map() {
        let r = EstimateRequest {
            train_map: "junction_training".into(),
            ..EstimateRequest::default()
        };
        assert_eq!(r.search().train_map, "junction_training");
        assert_eq!(EstimateRequest::default().train_map, SearchRequest::default().train_map);
    }
}
