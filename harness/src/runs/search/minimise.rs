//! Minimisation: the simplest failing scenario near each failure found. For a fair
//! failure, each parameter in the space's order is moved back to the base map's value
//! (in up to [`PASSES`] passes, stopping after a pass that kept nothing);
//! if the candidate there still fails fairly (fair, and the method's success under 50%
//! for at least one training seed) the move is kept, otherwise up to [`HALVINGS`] moves halfway toward the base are
//! tried, keeping each that still fails. Each try is a fresh candidate (new episodes),
//! evaluated and written like any other; the result is the last try that failed, or the
//! failure itself when none did, so a minimised scenario is always one measured to fail.
//!
//! The best failures (lowest worst-seed success, ties by candidate number) are minimised, up
//! to [`super::SearchConfig::max_failures`], in parallel; two whose minimised scenarios
//! change the same set of parameters count as one failure (the better one is kept).
//! Step `s` of the `r`-th failure is candidate `budget + r × steps + s`, where `steps`
//! bounds the tries per failure, so numbers never depend on the order of work.

use rayon::prelude::*;

use super::space::{Domain, Space, Value};
use super::{Candidate, Evaluated, Runner, Stage};
use crate::error::Error;

/// Moves halfway toward the base tried after a move all the way fails.
pub const HALVINGS: usize = 2;

/// Passes over the parameters (a move that failed in the first pass may succeed once
/// other parameters are back at the base).
pub const PASSES: usize = 2;

/// A failure and its minimised scenario.
#[derive(Debug, Clone)]
pub struct Minimised {
    /// The failing candidate minimisation started from.
    pub of: usize,
    /// The minimised scenario (a measured fair failure).
    pub result: Evaluated,
    /// The parameters whose values differ from the base's in it, by index.
    pub changed: Vec<usize>,
    /// Tries evaluated.
    pub tries: usize,
    /// Tries kept.
    pub kept: usize,
}

/// Tries per failure at most.
pub fn steps_per_failure(space: &Space) -> usize {
    space.params.len() * (1 + HALVINGS) * PASSES
}

/// The parameters of `values` that differ from the base's value (or that the base has
/// no value for).
pub fn changed(space: &Space, values: &[Value]) -> Vec<usize> {
    space
        .params
        .iter()
        .zip(values)
        .enumerate()
        .filter(|(_, (p, v))| p.base.as_ref() != Some(*v))
        .map(|(i, _)| i)
        .collect()
}

/// Halfway from `cur` toward `base` for a numeric parameter, or `None` when there is no
/// value strictly between them.
fn halfway(domain: &Domain, cur: &Value, base: &Value) -> Option<Value> {
    let (Value::Num(c), Value::Num(b)) = (cur, base) else {
        return None;
    };
    let mid = match domain {
        Domain::Range(..) => (((c + b) / 2.0) / super::space::VALUE_STEP).round() * super::space::VALUE_STEP,
        Domain::Count(..) => ((c + b) / 2.0).round(),
        Domain::Choose(_) => return None,
    };
    let mid: f64 = format!("{mid:.3}").parse().unwrap_or(mid);
    (mid != *c && mid != *b).then_some(Value::Num(mid))
}

/// Minimises the best fair failures of `all` (see the module doc); returns them, best
/// first, and every try evaluated.
pub(super) fn minimise_all(
    runner: &Runner<'_, '_>,
    all: &[Evaluated],
) -> Result<(Vec<Minimised>, Vec<Evaluated>), Error> {
    let cfg = runner.cfg;
    let mut failures: Vec<&Evaluated> = all.iter().filter(|e| e.fails_fairly()).collect();
    failures.sort_by(|a, b| {
        a.score()
            .total_cmp(&b.score())
            .then(a.candidate.index.cmp(&b.candidate.index))
    });
    failures.truncate(cfg.max_failures);
    runner.progress.phase("search minimise", failures.len() as u64);
    let done: Vec<(Minimised, Vec<Evaluated>)> = failures
        .par_iter()
        .enumerate()
        .map(|(rank, f)| {
            let r = minimise_one(runner, rank, f);
            crate::progress::step(runner.progress)?;
            r
        })
        .collect::<Result<_, Error>>()?;
    runner.progress.finish();
    let mut out: Vec<Minimised> = Vec::new();
    let mut tries = Vec::new();
    for (m, t) in done {
        tries.extend(t);
        if !out.iter().any(|o| o.changed == m.changed) {
            out.push(m);
        }
    }
    Ok((out, tries))
}

/// Minimises one failure, the `rank`-th best.
fn minimise_one(
    runner: &Runner<'_, '_>,
    rank: usize,
    failure: &Evaluated,
) -> Result<(Minimised, Vec<Evaluated>), Error> {
    let cfg = runner.cfg;
    let space = cfg.space;
    let first = cfg.budget + rank * steps_per_failure(space);
    let mut current = failure.clone();
    let mut tries = Vec::new();
    let mut kept = 0;
    let mut step = 0;
    let mut attempt = |current: &Evaluated, d: usize, v: Value, step: &mut usize| -> Result<Evaluated, Error> {
        let mut values = current.candidate.values.clone();
        values[d] = v;
        let point: Vec<f64> = space.params.iter().zip(&values).map(|(p, v)| p.coordinate(v)).collect();
        let stage = Stage::Minimise {
            of: failure.candidate.index,
            step: *step,
        };
        let c = Candidate::new(space, first + *step, stage, point, Some(values));
        *step += 1;
        let e = runner.one(c, false)?;
        tries.push(e.clone());
        Ok(e)
    };
    for _ in 0..PASSES {
        let before = kept;
        for (d, p) in space.params.iter().enumerate() {
            let Some(base) = p.base.clone() else { continue };
            if current.candidate.values[d] == base {
                continue;
            }
            let e = attempt(&current, d, base.clone(), &mut step)?;
            if e.fails_fairly() {
                current = e;
                kept += 1;
                continue;
            }
            for _ in 0..HALVINGS {
                let Some(mid) = halfway(&p.domain, &current.candidate.values[d], &base) else {
                    break;
                };
                let e = attempt(&current, d, mid, &mut step)?;
                if e.fails_fairly() {
                    current = e;
                    kept += 1;
                } else {
                    break;
                }
            }
        }
        if kept == before {
            break;
        }
    }
    let changed = changed(space, &current.candidate.values);
    Ok((
        Minimised {
            of: failure.candidate.index,
            result: current,
            changed,
            tries: step,
            kept,
        },
        tries,
    ))
}
