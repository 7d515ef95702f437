//! Candidates (points of the space laid over the base map), the stage that made each,
//! their lines in `candidates.jsonl` and what their evaluation found.

use super::*;

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
    /// The careful cruise that decided whether the candidate is survivable: the one where
    /// brake-on-pedestrian did worst (the survivable witness's line holds its figures).
    /// Absent from lines written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub careful_cruise: Option<CarefulCruise>,
    /// The evaluation, as a batch line.
    #[serde(flatten)]
    pub result: ResultLine,
}

/// The careful cruise that decided a candidate's survivability
/// ([`careful_witness`](crate::episodes::survivability::careful_witness): the worst of them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CarefulCruise {
    /// The cruise, as a fraction of the car's top speed.
    pub fraction: f64,
    /// The top speed brake-on-pedestrian drove at there, m/s.
    pub speed_mps: f64,
    /// brake-on-pedestrian's success rate at that cruise.
    pub success_rate: f64,
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
pub(super) struct RawLine {
    pub(super) raw: String,
    pub(super) parsed: CandidateLine,
}
