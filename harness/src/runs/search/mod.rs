//! The search for the unforeseen: the fair scenarios of a space of map variations
//! where a method fails (the paper's subject is what nobody foresaw; safety engineers
//! search for it: adaptive stress testing, falsification).
//!
//! A [`Space`] names which fields of a base map vary and over what ([`space`]). The
//! search evaluates *candidates*, points of the space laid over the base map, each with
//! K episodes of the two fairness witnesses (brake-on-pedestrian's line is the worst of
//! its careful cruises, [`careful_witness`]) and of the method (for each training seed),
//! in three stages. A fair candidate is a *failure* of the method when at least one of its
//! trained agents (training seeds) succeeds in under 50% of the episodes: each agent is
//! one draw of the method.
//!
//!
//! 1. **Sobol stage** (candidates `0..n1`, `n1 = ceil(budget × sobol_share)`): points of
//!    a scrambled Sobol sequence ([`sampler`]), uniform on the unit cube, so the share of
//!    its fair candidates the method fails is an unbiased estimate of
//!    P(the method fails | the candidate is fair), reported with a 95% Wilson interval
//!    per training seed, with the share of the space that is fair ([`fairness`]).
//! 2. **Adaptive stage** (candidates `n1..budget`, in [`SearchConfig::rounds`] rounds):
//!    the cross-entropy method ([`adaptive`]) fitted to the fair failures found so far.
//! 3. **Minimisation** ([`minimise`]): each of the best failures (up to
//!    [`SearchConfig::max_failures`], distinct by which parameters they change) is moved
//!    back toward the base map, one parameter at a time, while it still fails fairly.
//!
//! Every candidate's map is a valid map or is rejected with the map loader's reason
//! (counted and reported, never evaluated). Episode seeds derive from (seed, candidate
//! name, method, episode) and every stage's candidates from the seed and the results of
//! earlier stages, so the same seed gives the same candidates and results whatever the
//! number of threads.
//!
//! **Shards** cover the Sobol stage only: `--shard i/n` evaluates the i-th contiguous
//! slice of its candidates (the same contract as `batch`); the shards' `candidates.jsonl`
//! concatenated in order are the Sobol part of a single run's file. The adaptive stage
//! and minimisation depend on all of the first stage's results, so they run once, in a
//! run without `--shard` given the concatenated file with `--resume` (which keeps every
//! complete candidate and evaluates only what is missing). **Resume** refuses a file of
//! another run (its first line is the run's identity), keeps the complete candidates'
//! lines byte for byte and evaluates the rest.
//!
//! A search's request ([`SearchRequest`]) is every choice of its user; its planning
//! ([`SearchRequest::plan`]) is shared by the command line, the Python package and the
//! Ray driver.
//!
//! Outputs ([`output`]): `candidates.jsonl`, `failures/NAME.ron`, `summary.json` and
//! `search.svg`.

pub mod adaptive;
pub mod fairness;
pub mod minimise;
pub mod output;
pub mod request;
pub mod sampler;
pub mod space;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::sync::Mutex;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::Map;

use crate::episodes::experiments::{evaluate_scripted, evaluate_under};
use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::{Protocol, covered};
use crate::episodes::survivability::careful_witness;
use crate::error::Error;
use crate::progress::{CancelOnly, NoProgress, Progress};
use crate::runs::batch::{ResultLine, Shard, UnitLabel};
use crate::runs::outputs::Guarded;
use crate::training::seed_agents::Agent;

pub use fairness::Fairness;
pub use output::Summary;
pub use request::{SearchJob, SearchRequest, SearchSetup};
pub use space::{Space, Value};

/// Default share of the budget that the Sobol stage takes.
pub const DEFAULT_SOBOL_SHARE: f64 = 0.5;
/// Default rounds of the adaptive stage.
pub const DEFAULT_ROUNDS: usize = 5;
/// Default number of failures minimised and written as maps.
pub const DEFAULT_MAX_FAILURES: usize = 5;
/// Most candidates one search may have.
pub const MAX_BUDGET: usize = sampler::MAX_POINTS;

/// Everything a search needs.
pub struct SearchConfig<'a> {
    /// The space (with its base map).
    pub space: &'a Space,
    /// The method searched for failures.
    pub method: Method,
    /// Its trained agents (none for a scripted method), one per training seed.
    pub agents: &'a [Agent],
    /// The training seeds, in order (`[None]` for a scripted method).
    pub train_seeds: &'a [Option<u64>],
    /// What determines the agents (as in batch: an agent file's hash or the recipe).
    pub agents_identity: String,
    /// The evaluation protocol of the method.
    pub protocol: Protocol,
    /// Candidates of the Sobol and adaptive stages.
    pub budget: usize,
    /// Episodes per candidate and method (and training seed).
    pub episodes: u64,
    /// Run seed.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// A shard of the Sobol stage (then only that slice runs).
    pub shard: Option<Shard>,
    /// Share of the budget the Sobol stage takes, in (0, 1].
    pub sobol_share: f64,
    /// Rounds of the adaptive stage.
    pub rounds: usize,
    /// Failures minimised and written as maps.
    pub max_failures: usize,
    /// The command that ran the search, for the failure maps' comments.
    pub command: String,
}

impl SearchConfig<'_> {
    /// Candidates of the Sobol stage.
    pub fn sobol_count(&self) -> usize {
        ((self.budget as f64 * self.sobol_share).ceil() as usize).clamp(1, self.budget.max(1))
    }

    /// Sizes of the adaptive stage's rounds.
    pub fn round_sizes(&self) -> Vec<usize> {
        let rest = self.budget.saturating_sub(self.sobol_count());
        let rounds = self.rounds.max(1).min(rest.max(1));
        (0..rounds)
            .map(|r| rest * (r + 1) / rounds - rest * r / rounds)
            .filter(|&n| n > 0)
            .collect()
    }

    /// Checks the settings.
    pub fn check(&self) -> Result<(), Error> {
        Self::check_arguments(self.space, self.budget, self.sobol_share)?;
        if self.method.is_scripted() != self.agents.is_empty() && !self.method.is_scripted() {
            return Err(Error::MissingAgent { train_seed: None });
        }
        Ok(())
    }

    /// The checks of [`SearchConfig::check`] that need no agent, for a front to make
    /// before training any: the budget, the Sobol share and the space's dimensions.
    pub fn check_arguments(space: &Space, budget: usize, sobol_share: f64) -> Result<(), Error> {
        if budget == 0 || budget > MAX_BUDGET {
            return Err(Error::Request {
                field: "budget".into(),
                value: Some(budget.to_string()),
                problem: format!("expected 1 to {MAX_BUDGET} candidates"),
            });
        }
        if !(sobol_share > 0.0 && sobol_share <= 1.0) {
            return Err(Error::Request {
                field: "sobol_share".into(),
                value: Some(sobol_share.to_string()),
                problem: "expected a share in (0, 1]".into(),
            });
        }
        if space.params.len() > sampler::MAX_DIMENSIONS {
            return Err(Error::request("space", "too many parameters for the Sobol sequence"));
        }
        Ok(())
    }

    /// The run's identity (the first line of `candidates.jsonl`).
    pub fn identity(&self) -> SearchIdentity {
        let hash = |s: &str| crate::seeds::content_hash(s.as_bytes());
        SearchIdentity {
            program: format!(
                "unforeseen {} (code {})",
                env!("CARGO_PKG_VERSION"),
                env!("UNFORESEEN_CODE_FINGERPRINT")
            ),
            space: (self.space.name.clone(), hash(&self.space.text)),
            base: (
                self.space.base.name.clone(),
                hash(&serde_json::to_string(&self.space.base).unwrap_or_default()),
            ),
            method: self.method.name().to_string(),
            agents: self.agents_identity.clone(),
            train_seeds: self.train_seeds.to_vec(),
            protocol: self.protocol,
            budget: self.budget,
            episodes: self.episodes,
            seed: self.seed,
            sobol_share: self.sobol_share,
            rounds: self.rounds,
            max_failures: self.max_failures,
        }
    }
}

/// What determines a search's results (the first line of `candidates.jsonl`,
/// `{"search": {...}}`); the shard is not part of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SearchIdentity {
    /// Program version and code fingerprint.
    pub program: String,
    /// The space: name and a hash of its file.
    pub space: (String, String),
    /// The base map: name and a hash of its contents.
    pub base: (String, String),
    /// The method searched.
    pub method: String,
    /// The agents.
    pub agents: String,
    /// Training seeds.
    pub train_seeds: Vec<Option<u64>>,
    /// Protocol.
    pub protocol: Protocol,
    /// Budget.
    pub budget: usize,
    /// Episodes per evaluation.
    pub episodes: u64,
    /// Seed.
    pub seed: u64,
    /// Share of the Sobol stage.
    pub sobol_share: f64,
    /// Adaptive rounds.
    pub rounds: usize,
    /// Failures minimised.
    pub max_failures: usize,
}

impl SearchIdentity {
    /// One phrase per field that differs from `other` (`self` is the file's).
    pub fn differences(&self, other: &SearchIdentity) -> Vec<String> {
        let a = serde_json::to_value(self).unwrap_or_default();
        let b = serde_json::to_value(other).unwrap_or_default();
        let mut out = Vec::new();
        if let (Some(a), Some(b)) = (a.as_object(), b.as_object()) {
            for (k, va) in a {
                if *va != b[k] {
                    out.push(format!("{k}: the file has {va}, this run {}", b[k]));
                }
            }
        }
        out
    }
}

/// Which stage made a candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stage {
    /// The space-filling first stage.
    Sobol,
    /// Round `round` of the adaptive stage.
    Adaptive {
        /// 0-based round.
        round: usize,
    },
    /// Step `step` of minimising the failure of candidate `of`.
    Minimise {
        /// The failing candidate being minimised.
        of: usize,
        /// 0-based step.
        step: usize,
    },
}

/// A point of the space to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Its number (Sobol `0..n1`, adaptive `n1..budget`, minimisation steps above).
    pub index: usize,
    /// The stage that made it.
    pub stage: Stage,
    /// Its coordinates in the unit cube.
    pub point: Vec<f64>,
    /// Its parameter values.
    pub values: Vec<Value>,
    /// Its map, or why the point is not a valid map.
    pub map: Result<Map, space::Rejection>,
}

impl Candidate {
    /// The candidate at `point` (`values`, when given, override the point's).
    pub fn new(space: &Space, index: usize, stage: Stage, point: Vec<f64>, values: Option<Vec<Value>>) -> Self {
        let values = values.unwrap_or_else(|| space.values_at(&point));
        let map = space.apply(&values, &candidate_name(space, index));
        Candidate {
            index,
            stage,
            point,
            values,
            map,
        }
    }

    /// `(parameter, value)` pairs, in the space's order.
    pub fn named_values(&self, space: &Space) -> Vec<(String, Value)> {
        space
            .params
            .iter()
            .map(|p| p.name.clone())
            .zip(self.values.iter().cloned())
            .collect()
    }
}

/// The name of candidate `index`'s map: `SPACE_c0042`.
pub fn candidate_name(space: &Space, index: usize) -> String {
    format!("{}_c{index:04}", space.name)
}

/// The Sobol stage's candidates `range` of a search with run seed `seed`: pure and
/// deterministic.
pub fn sobol_candidates(space: &Space, seed: u64, range: std::ops::Range<usize>) -> Vec<Candidate> {
    range
        .map(|i| {
            let point = sampler::sobol_point(seed, i, space.params.len());
            Candidate::new(space, i, Stage::Sobol, point, None)
        })
        .collect()
}

/// The role of one evaluation of a candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// brake-on-pedestrian: is the candidate survivable?
    SurvivableWitness,
    /// never-brake: is the candidate dangerous?
    DangerousWitness,
    /// The method searched.
    Method,
}

/// One line of `candidates.jsonl`: a batch result line (every field of
/// [`ResultLine`], `scenario` the candidate's map) with the candidate's figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateLine {
    /// The candidate's number.
    pub candidate: usize,
    /// The stage that made it.
    pub stage: Stage,
    /// What this evaluation is for.
    pub role: Role,
    /// The candidate's parameter values.
    pub values: Vec<(String, Value)>,
    /// What the witnesses say of it.
    pub fairness: Fairness,
    /// For the method's line: the candidate is fair and this agent's success is under 50%.
    pub fails: bool,
    /// The evaluation, as a batch line.
    #[serde(flatten)]
    pub result: ResultLine,
}

/// One evaluated candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluated {
    /// The candidate.
    pub candidate: Candidate,
    /// Its lines (witnesses, then the method per training seed); none when rejected.
    pub lines: Vec<CandidateLine>,
}

impl Evaluated {
    /// What the witnesses say (None when rejected).
    pub fn fairness(&self) -> Option<Fairness> {
        self.lines.first().map(|l| l.fairness)
    }

    /// The method's success rates, one per training seed.
    pub fn method_success(&self) -> Vec<f64> {
        self.lines
            .iter()
            .filter(|l| l.role == Role::Method)
            .map(|l| l.result.success_rate)
            .collect()
    }

    /// The method's lowest success over training seeds (None when rejected): the agent
    /// that fares worst, since each trained agent is one draw of the method.
    pub fn worst_success(&self) -> Option<f64> {
        self.method_success().into_iter().reduce(f64::min)
    }

    /// Fair, and the method's success is under 50% for at least one training seed.
    pub fn fails_fairly(&self) -> bool {
        self.fairness().is_some_and(Fairness::is_fair) && self.worst_success().is_some_and(fairness::fails)
    }

    /// The adaptive stage's score: the worst seed's success when fair, +∞ otherwise.
    pub fn score(&self) -> f64 {
        match (self.fairness(), self.worst_success()) {
            (Some(Fairness::Fair), Some(s)) => s,
            _ => f64::INFINITY,
        }
    }

    /// A witness's success rate.
    pub fn witness(&self, role: Role) -> Option<f64> {
        self.lines
            .iter()
            .find(|l| l.role == role)
            .map(|l| l.result.success_rate)
    }
}

/// A finished line of `candidates.jsonl`, as written.
#[derive(Debug, Clone)]
struct RawLine {
    raw: String,
    parsed: CandidateLine,
}

/// Evaluates candidates somewhere else than in this process (e.g. as tasks of a
/// cluster): what [`run_with`] calls in place of [`evaluate`]. Each candidate's lines
/// must be what [`evaluate`] gives for it (JSON text, one line each, ending in `\n`), in
/// the same order as the candidates given; [`CandidateWire`] is what to send of a
/// candidate, and [`evaluate_wire`] what to run with it where the lines are made.
pub trait Evaluator: Sync {
    /// The lines of each candidate of `candidates` (valid maps not kept by `--resume`).
    fn evaluate(&self, candidates: &[CandidateWire]) -> Result<Vec<Vec<String>>, Error>;
}

/// What an [`Evaluator`] needs of a candidate to rebuild it: its map derives from the
/// space and its values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateWire {
    /// Its number.
    pub index: usize,
    /// The stage that made it.
    pub stage: Stage,
    /// Its parameter values, in the space's order.
    pub values: Vec<Value>,
}

impl CandidateWire {
    fn of(c: &Candidate) -> Self {
        CandidateWire {
            index: c.index,
            stage: c.stage,
            values: c.values.clone(),
        }
    }
}

/// The lines of a candidate sent as a [`CandidateWire`]: what [`evaluate`] writes for
/// it, as JSON text (one line each, with its `\n`); an error when its map is not valid.
pub fn evaluate_wire(cfg: &SearchConfig<'_>, wire: &CandidateWire) -> Result<Vec<String>, Error> {
    evaluate_wire_with(cfg, wire, &NoProgress)
}

/// [`evaluate_wire`], stopping between episodes ([`Error::Interrupted`]) when `cancel`
/// asks (the Python binding: a pending Ctrl-C).
pub fn evaluate_wire_with(
    cfg: &SearchConfig<'_>,
    wire: &CandidateWire,
    cancel: &dyn Progress,
) -> Result<Vec<String>, Error> {
    let c = Candidate::new(cfg.space, wire.index, wire.stage, Vec::new(), Some(wire.values.clone()));
    let map = c.map.as_ref().map_err(|r| Error::Results {
        path: cfg.space.source.clone().into(),
        problem: format!("candidate {}: not a valid map ({r:?})", wire.index),
    })?;
    let named = c.named_values(cfg.space);
    evaluate(cfg, &c, map, named, cancel)?
        .iter()
        .map(|l| {
            let mut raw = serde_json::to_string(l)?;
            raw.push('\n');
            Ok(raw)
        })
        .collect()
}

/// The shared state of a running search: the file being appended and the lines kept.
struct Runner<'a, 'b> {
    cfg: &'a SearchConfig<'b>,
    sink: Mutex<std::fs::File>,
    out: &'a Path,
    kept: BTreeMap<usize, Vec<RawLine>>,
    written: Mutex<BTreeMap<usize, Vec<RawLine>>>,
    progress: &'a dyn Progress,
    /// Where candidates are evaluated when not here.
    remote: Option<&'a dyn Evaluator>,
    /// Lines the remote evaluator made for a stage, taken by [`Runner::one`].
    prefetched: Mutex<BTreeMap<usize, Vec<RawLine>>>,
}

impl Runner<'_, '_> {
    /// Evaluates `candidates` in parallel (reusing kept lines), as one phase.
    fn stage(&self, name: &str, candidates: Vec<Candidate>) -> Result<Vec<Evaluated>, Error> {
        let todo = candidates
            .iter()
            .filter(|c| c.map.is_ok() && !self.kept.contains_key(&c.index))
            .count();
        self.progress.phase(name, todo as u64);
        if self.remote.is_some() {
            let todo: Vec<Candidate> = candidates
                .iter()
                .filter(|c| c.map.is_ok() && !self.kept.contains_key(&c.index))
                .cloned()
                .collect();
            self.fetch(&todo)?;
        }
        let done = candidates
            .into_par_iter()
            .map(|c| self.one(c, true))
            .collect::<Result<Vec<_>, Error>>();
        self.progress.finish();
        done
    }

    /// Evaluates one candidate (or takes its kept lines), appending fresh lines.
    fn one(&self, candidate: Candidate, advance: bool) -> Result<Evaluated, Error> {
        let Ok(map) = &candidate.map else {
            return Ok(Evaluated {
                candidate,
                lines: Vec::new(),
            });
        };
        let named = candidate.named_values(self.cfg.space);
        if let Some(kept) = self.kept.get(&candidate.index) {
            if let Some(bad) = kept
                .iter()
                .find(|l| l.parsed.values != named || l.parsed.stage != candidate.stage)
            {
                return Err(Error::Results {
                    path: self.out.to_path_buf(),
                    problem: format!(
                        "--resume: candidate {} in the file has other values or another stage than this run's ({:?} vs {:?}); \
                         give another --out, or leave out --resume to start over",
                        bad.parsed.candidate, bad.parsed.values, named
                    ),
                });
            }
            self.written
                .lock()
                .expect("lines lock")
                .insert(candidate.index, kept.clone());
            let lines = kept.iter().map(|l| l.parsed.clone()).collect();
            return Ok(Evaluated { candidate, lines });
        }
        let remote = if self.remote.is_some() {
            let got = self.prefetched.lock().expect("lines lock").remove(&candidate.index);
            match got {
                Some(raws) => Some(raws),
                None => {
                    self.fetch(std::slice::from_ref(&candidate))?;
                    self.prefetched.lock().expect("lines lock").remove(&candidate.index)
                }
            }
        } else {
            None
        };
        if let Some(raws) = remote {
            if let Some(bad) = raws
                .iter()
                .find(|l| l.parsed.values != named || l.parsed.stage != candidate.stage)
            {
                return Err(Error::Results {
                    path: self.out.to_path_buf(),
                    problem: format!(
                        "candidate {}: the evaluator returned lines of other values or another stage ({:?} vs {:?})",
                        candidate.index, bad.parsed.values, named
                    ),
                });
            }
            return self.write(candidate, raws, advance);
        }
        let lines = evaluate(self.cfg, &candidate, map, named, self.progress)?;
        let raws: Vec<RawLine> = lines
            .iter()
            .map(|l| {
                let mut raw = serde_json::to_string(l)?;
                raw.push('\n');
                Ok(RawLine { raw, parsed: l.clone() })
            })
            .collect::<Result<_, Error>>()?;
        self.write(candidate, raws, advance)
    }

    /// Appends a candidate's fresh lines to the file and keeps them.
    fn write(&self, candidate: Candidate, raws: Vec<RawLine>, advance: bool) -> Result<Evaluated, Error> {
        let lines = raws.iter().map(|r| r.parsed.clone()).collect();
        let text: String = raws.iter().map(|r| r.raw.as_str()).collect();
        {
            let mut f = self.sink.lock().expect("file lock");
            f.write_all(text.as_bytes())
                .and_then(|()| f.flush())
                .map_err(|e| Error::io("write", self.out, e))?;
        }
        self.written.lock().expect("lines lock").insert(candidate.index, raws);
        if advance {
            crate::progress::step(self.progress)?;
        }
        Ok(Evaluated { candidate, lines })
    }

    /// Has the remote evaluator make the lines of `candidates`, parsed, for [`Runner::one`].
    fn fetch(&self, candidates: &[Candidate]) -> Result<(), Error> {
        let Some(remote) = self.remote else { return Ok(()) };
        if candidates.is_empty() {
            return Ok(());
        }
        if self.progress.cancelled() {
            return Err(Error::Interrupted);
        }
        let wires: Vec<CandidateWire> = candidates.iter().map(CandidateWire::of).collect();
        let got = remote.evaluate(&wires)?;
        let bad = |problem: String| Error::Results {
            path: self.out.to_path_buf(),
            problem,
        };
        if got.len() != candidates.len() {
            return Err(bad(format!(
                "the evaluator returned {} candidates' lines for {}",
                got.len(),
                candidates.len()
            )));
        }
        let need = lines_per_candidate(self.cfg);
        let mut parsed = Vec::with_capacity(got.len());
        for (c, lines) in candidates.iter().zip(got) {
            if lines.len() != need {
                return Err(bad(format!(
                    "candidate {}: the evaluator returned {} lines, expected {need}",
                    c.index,
                    lines.len()
                )));
            }
            let raws = lines
                .into_iter()
                .map(|raw| {
                    let parsed: CandidateLine = serde_json::from_str(raw.trim_end()).map_err(|e| {
                        bad(format!(
                            "candidate {}: the evaluator returned a bad line ({e})",
                            c.index
                        ))
                    })?;
                    if parsed.candidate != c.index || !raw.ends_with('\n') {
                        return Err(bad(format!(
                            "candidate {}: the evaluator returned another candidate's line",
                            c.index
                        )));
                    }
                    Ok(RawLine { raw, parsed })
                })
                .collect::<Result<Vec<_>, Error>>()?;
            parsed.push((c.index, raws));
        }
        self.prefetched.lock().expect("lines lock").extend(parsed);
        Ok(())
    }
}

/// One evaluation of a candidate: its role, method, agent, training seed and figures.
type Run<'a> = (Role, Method, Option<&'a Agent>, Option<u64>, Aggregate);

/// Evaluates a candidate's map: the two witnesses, then the method for each training
/// seed, `episodes` episodes each; its lines carry the fairness and failure verdicts.
/// Stops between episodes ([`Error::Interrupted`]) when `cancel` asks; its phase is not
/// advanced.
pub fn evaluate(
    cfg: &SearchConfig<'_>,
    candidate: &Candidate,
    map: &Map,
    values: Vec<(String, Value)>,
    cancel: &dyn Progress,
) -> Result<Vec<CandidateLine>, Error> {
    let cancel = CancelOnly(cancel);
    let params = ScaledParams::default();
    let scripted = |m: Method| -> Result<Aggregate, Error> {
        Ok(Aggregate::of(&evaluate_scripted(
            map,
            m,
            cfg.episodes,
            cfg.seed,
            &cancel,
        )?))
    };
    let (_, brake) = careful_witness(map, cfg.episodes, cfg.seed, &cancel)?;
    let never = scripted(Method::NeverBrake)?;
    let fair = Fairness::of(brake.success_rate, never.success_rate);
    let mut runs: Vec<Run<'_>> = vec![
        (Role::SurvivableWitness, Method::BrakeOnPedestrian, None, None, brake),
        (Role::DangerousWitness, Method::NeverBrake, None, None, never),
    ];
    for &seed in cfg.train_seeds {
        let (agent, agg) = if cfg.method.is_scripted() {
            (None, scripted(cfg.method)?)
        } else {
            let agent = cfg
                .agents
                .iter()
                .find(|a| a.train_seed == seed)
                .ok_or(Error::MissingAgent { train_seed: seed })?;
            let results = evaluate_under(
                cfg.protocol,
                map,
                &agent.bundle,
                &params,
                cfg.method,
                cfg.episodes,
                cfg.seed,
                &cancel,
            )?;
            (Some(agent), Aggregate::of(&results))
        };
        runs.push((Role::Method, cfg.method, agent, seed, agg));
    }
    Ok(runs
        .into_iter()
        .map(|(role, method, agent, train_seed, agg)| {
            let result = result_line(cfg, candidate, map, method, agent, train_seed, &params, &agg);
            CandidateLine {
                candidate: candidate.index,
                stage: candidate.stage,
                role,
                values: values.clone(),
                fairness: fair,
                fails: role == Role::Method && fair.is_fair() && fairness::fails(agg.success_rate),
                result,
            }
        })
        .collect())
}

/// The batch line of one evaluation (the same fields `batch` writes).
#[allow(clippy::too_many_arguments)]
fn result_line(
    cfg: &SearchConfig<'_>,
    candidate: &Candidate,
    map: &Map,
    method: Method,
    agent: Option<&Agent>,
    train_seed: Option<u64>,
    params: &ScaledParams,
    agg: &Aggregate,
) -> ResultLine {
    let label = UnitLabel {
        unit: candidate.index,
        scenario: map.name.clone(),
        source: format!("search:{}", cfg.space.source),
        method: method.name().into(),
        param_set: "default".into(),
        params: Vec::new(),
        protocol: cfg.protocol,
        covers: covered(method, params, cfg.protocol, &[cfg.protocol]),
        train_seed,
        train_episodes: agent.and_then(|a| a.train_episodes),
        seed: cfg.seed,
    };
    ResultLine::new(label, agg, method.reasoning_tree(params), Vec::new(), Vec::new())
}

/// The lines of a candidate, complete: two witnesses and one method line per seed.
fn lines_per_candidate(cfg: &SearchConfig<'_>) -> usize {
    2 + cfg.train_seeds.len()
}

/// Reads the complete candidates of `out` for `--resume` (see the module doc).
fn resume_lines(cfg: &SearchConfig<'_>, out: &Path) -> Result<BTreeMap<usize, Vec<RawLine>>, Error> {
    let bad = |problem: String| Error::Results {
        path: out.to_path_buf(),
        problem,
    };
    let fix = "give another --out, or leave out --resume to start it over";
    let bytes = match std::fs::read(out) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(BTreeMap::new()),
        Err(e) => return Err(Error::io("read", out, e)),
        Ok(b) => b,
    };
    let identity = cfg.identity();
    let mut by: BTreeMap<usize, Vec<RawLine>> = BTreeMap::new();
    let mut seen_identity = false;
    for (i, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        if !raw.ends_with(b"\n") {
            break; // cut by a kill: that candidate runs again
        }
        let raw = std::str::from_utf8(raw).map_err(|_| bad(format!("line {}: not text; {fix}", i + 1)))?;
        if raw.starts_with("{\"search\":") {
            #[derive(Deserialize)]
            #[serde(deny_unknown_fields)]
            struct Head {
                search: SearchIdentity,
            }
            let head: Head = serde_json::from_str(raw.trim_end())
                .map_err(|e| bad(format!("line {}: not a search identity ({e}); {fix}", i + 1)))?;
            if head.search != identity {
                return Err(bad(format!(
                    "--resume: line {} was written by another search ({}); {fix}",
                    i + 1,
                    head.search.differences(&identity).join("; ")
                )));
            }
            seen_identity = true;
            continue;
        }
        if !seen_identity {
            return Err(bad(format!(
                "--resume: the file does not start with a search identity line; {fix}"
            )));
        }
        let parsed: CandidateLine = serde_json::from_str(raw.trim_end())
            .map_err(|e| bad(format!("line {}: not a candidate line ({e}); {fix}", i + 1)))?;
        if let Some(problem) = kept_line_problem(cfg, &parsed, raw) {
            return Err(bad(format!(
                "--resume: line {} (candidate {}, {:?}) {problem}; {fix}",
                i + 1,
                parsed.candidate,
                parsed.role
            )));
        }
        let entry = by.entry(parsed.candidate).or_default();
        if entry
            .iter()
            .any(|l| (l.parsed.role, l.parsed.result.train_seed) == (parsed.role, parsed.result.train_seed))
        {
            return Err(bad(format!(
                "line {}: candidate {} {:?} is in the file twice; remove one of its lines",
                i + 1,
                parsed.candidate,
                parsed.role
            )));
        }
        entry.push(RawLine {
            raw: raw.to_string(),
            parsed,
        });
    }
    // Only complete candidates are kept: a candidate cut by a kill runs again.
    let need = lines_per_candidate(cfg);
    by.retain(|_, v| v.len() == need);
    for (candidate, v) in by.iter_mut() {
        v.sort_by_key(|l| (l.parsed.role, l.parsed.result.train_seed));
        // The verdicts follow from the witnesses' figures, on every line alike.
        let fair = Fairness::of(v[0].parsed.result.success_rate, v[1].parsed.result.success_rate);
        if let Some(l) = v.iter().find(|l| {
            l.parsed.fairness != fair
                || l.parsed.values != v[0].parsed.values
                || l.parsed.stage != v[0].parsed.stage
                || l.parsed.fails
                    != (l.parsed.role == Role::Method
                        && fair.is_fair()
                        && fairness::fails(l.parsed.result.success_rate))
        }) {
            return Err(bad(format!(
                "--resume: candidate {candidate} ({:?} line): its fairness, failure verdict, stage or values do not follow from its lines (fairness {:?} from the witnesses); {fix}",
                l.parsed.role, fair
            )));
        }
    }
    Ok(by)
}

/// What is wrong with a kept candidate line `l` (read from `raw`) as a line of the
/// search `cfg`: fields this program does not write, a field of the batch line that is
/// not this search's (unit, scenario, source, method, protocol, training seed, seed,
/// episodes, parameters), or a figure out of range (as `batch --resume` checks them).
fn kept_line_problem(cfg: &SearchConfig<'_>, l: &CandidateLine, raw: &str) -> Option<String> {
    let written = serde_json::to_value(l).ok();
    if written != serde_json::from_str::<serde_json::Value>(raw.trim_end()).ok() {
        return Some("is not a line this program writes (an unknown or edited field)".into());
    }
    let r = &l.result;
    let method = match l.role {
        Role::SurvivableWitness => Method::BrakeOnPedestrian,
        Role::DangerousWitness => Method::NeverBrake,
        Role::Method => cfg.method,
    };
    let seed_ok = match l.role {
        Role::Method => cfg.train_seeds.contains(&r.train_seed),
        _ => r.train_seed.is_none(),
    };
    let expected = [
        ("unit", r.unit == l.candidate),
        ("scenario", r.scenario == candidate_name(cfg.space, l.candidate)),
        ("source", r.source == format!("search:{}", cfg.space.source)),
        ("method", r.method == method.name()),
        ("protocol", r.protocol == cfg.protocol && r.covers == [cfg.protocol]),
        ("train_seed", seed_ok),
        ("seed", r.seed == cfg.seed),
        ("episodes", r.episodes == cfg.episodes),
        ("param_set", r.param_set == "default" && r.params.is_empty()),
    ];
    if let Some((field, _)) = expected.iter().find(|(_, ok)| !ok) {
        return Some(format!("has a {field} that is not this search's"));
    }
    crate::runs::batch::results_file::figures_problem(r)
}

/// Everything a search found, in memory (what [`run`] writes).
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Every candidate of the Sobol and adaptive stages (rejected ones too), in order.
    pub candidates: Vec<Evaluated>,
    /// The minimised failures, best first.
    pub failures: Vec<minimise::Minimised>,
    /// The minimisation steps evaluated.
    pub minimise_steps: Vec<Evaluated>,
}

/// Runs the search into folder `out` (`candidates.jsonl`, `failures/`, `summary.json`,
/// `search.svg`); with `resume`, completes the search a file there holds. Progress: one
/// phase per stage (`search sobol`, `search adaptive N`, `search minimise`). `guard` is
/// the job's output guard: the earlier search's summary, figure and failure maps are
/// removed once the kept lines are checked ([`Guarded::clear_at_end`]).
pub fn run(
    cfg: &SearchConfig<'_>,
    out: &Path,
    resume: bool,
    guard: &Guarded,
    progress: &dyn Progress,
) -> Result<Summary, Error> {
    run_with(cfg, out, resume, guard, progress, None)
}

/// [`run`], with the candidates evaluated by `remote` when given (each stage's
/// candidates in one call, each minimisation try in its own; the stage logic, the files
/// and their order stay here, so the outputs equal [`run`]'s). Minimisation's failures
/// run on `cfg.jobs` threads, each waiting on its own calls.
pub fn run_with(
    cfg: &SearchConfig<'_>,
    out: &Path,
    resume: bool,
    guard: &Guarded,
    progress: &dyn Progress,
    remote: Option<&dyn Evaluator>,
) -> Result<Summary, Error> {
    cfg.check()?;
    std::fs::create_dir_all(out).map_err(|e| Error::io("create folder", out, e))?;
    let file = out.join(output::CANDIDATES);
    let kept = if resume {
        resume_lines(cfg, &file)?
    } else {
        BTreeMap::new()
    };
    guard.clear_at_end()?;
    let head: String = std::iter::once(output::identity_line(&cfg.identity()))
        .chain(kept.values().flatten().map(|l| l.raw.clone()))
        .collect();
    crate::reports::files::write_atomic(&file, head.as_bytes())?;
    let sink = std::fs::OpenOptions::new()
        .append(true)
        .open(&file)
        .map_err(|e| Error::io("append to", &file, e))?;
    let runner = Runner {
        cfg,
        sink: Mutex::new(sink),
        out: &file,
        kept,
        written: Mutex::new(BTreeMap::new()),
        progress,
        remote,
        prefetched: Mutex::new(BTreeMap::new()),
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    let outcome = pool.install(|| search(&runner))?;
    // Canonical order: by candidate, each candidate's lines in role and seed order.
    let written = runner.written.into_inner().expect("lines lock");
    let text: String = std::iter::once(output::identity_line(&cfg.identity()))
        .chain(written.values().flatten().map(|l| l.raw.clone()))
        .collect();
    // The candidates, failure maps, summary and figure appear together or not at all.
    crate::reports::files::all_or_none(|| {
        crate::reports::files::write_atomic(&file, text.as_bytes())?;
        output::write_all(cfg, out, &outcome)
    })
}

/// The stages (see the module doc).
fn search(runner: &Runner<'_, '_>) -> Result<Outcome, Error> {
    let cfg = runner.cfg;
    let space = cfg.space;
    let n1 = cfg.sobol_count();
    let range = cfg.shard.map_or(0..n1, |s| s.range(n1));
    let mut all = runner.stage("search sobol", sobol_candidates(space, cfg.seed, range))?;
    if cfg.shard.is_some() {
        return Ok(Outcome {
            candidates: all,
            failures: Vec::new(),
            minimise_steps: Vec::new(),
        });
    }
    let mut ce = adaptive::CrossEntropy::uniform(space);
    let mut next = n1;
    for (round, size) in cfg.round_sizes().into_iter().enumerate() {
        let scored: Vec<(Vec<f64>, f64)> = all.iter().map(|e| (e.candidate.point.clone(), e.score())).collect();
        ce.refit(&scored);
        let candidates: Vec<Candidate> = ce
            .sample(cfg.seed, round, size)
            .into_iter()
            .enumerate()
            .map(|(k, p)| Candidate::new(space, next + k, Stage::Adaptive { round }, p, None))
            .collect();
        next += size;
        all.extend(runner.stage(&format!("search adaptive {}", round + 1), candidates)?);
    }
    let (failures, steps) = minimise::minimise_all(runner, &all)?;
    Ok(Outcome {
        candidates: all,
        failures,
        minimise_steps: steps,
    })
}
