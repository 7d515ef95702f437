//! Evaluating candidates elsewhere (tasks of a cluster): what to send of a candidate
//! ([`CandidateWire`]) and what to run with it where the lines are made.

use super::*;

/// Evaluates candidates somewhere else than in this process (e.g. as tasks of a
/// cluster): what [`run_with`] calls in place of [`evaluate_candidate`]. Each candidate's lines
/// must be what [`evaluate_candidate`] gives for it (JSON text, one line each, ending in `\n`), in
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
    pub(crate) fn of(c: &Candidate) -> Self {
        CandidateWire {
            index: c.index,
            stage: c.stage,
            values: c.values.clone(),
        }
    }
}

/// The lines of a candidate sent as a [`CandidateWire`]: what [`evaluate_candidate`] writes for
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
    evaluate_candidate(cfg, &c, map, named, cancel)?
        .iter()
        .map(|l| {
            let mut raw = serde_json::to_string(l)?;
            raw.push('\n');
            Ok(raw)
        })
        .collect()
}
