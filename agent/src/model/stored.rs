//! The world model as agent files store it (its counts, not the matrices derived from
//! them), and the checks a loaded one passes before anything is computed from it.

use crate::error::FieldError;
use crate::limits::{MAX_ACTIONS, MAX_STATES, MAX_VALUE};
use crate::params::ModelPriors;
use crate::stored_values;
use crate::structure::Structure;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::crash::check_crash;
use super::{CrashModel, TransitionCost};

#[derive(Serialize, Deserialize, Clone)]
#[serde(deny_unknown_fields, rename = "WorldModel")]
pub(super) struct WorldModelRepr {
    pub(super) structure: Structure,
    pub(super) n_actions: usize,
    pub(super) priors: ModelPriors,
    pub(super) cpt: Vec<Vec<f64>>,
    #[serde(deserialize_with = "checked_matrix")]
    pub(super) a_counts: DMatrix<f64>,
    pub(super) c: Vec<f64>,
    pub(super) d_counts: Vec<f64>,
    #[serde(default)]
    pub(super) terminal: Vec<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) transition_cost: Option<TransitionCost>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) crash: Option<CrashModel>,
}

/// A `DMatrix` stored as nalgebra writes it, `(data, nrows, ncols)` in column-major
/// order, checking `nrows * ncols` without overflow (nalgebra's own reader multiplies
/// unchecked: a damaged file could claim a `2^32 x 2^32` matrix with no data).
fn checked_matrix<'de, D: serde::Deserializer<'de>>(de: D) -> Result<DMatrix<f64>, D::Error> {
    use serde::de::Error;
    let (data, nrows, ncols): (Vec<f64>, usize, usize) = Deserialize::deserialize(de)?;
    if nrows.checked_mul(ncols) != Some(data.len()) {
        return Err(D::Error::custom(format!(
            "a {nrows} x {ncols} matrix needs {nrows} x {ncols} entries, found {}",
            data.len()
        )));
    }
    Ok(DMatrix::from_vec(nrows, ncols, data))
}

/// Checks the stored fields of a world model (names as in the file), before anything
/// is computed from them: sizes within [`crate::limits`], CPTs of the structure's
/// shape, `A`'s columns and `D` positive finite counts, `C` a normalised log distribution,
/// terminal states in range.
pub(super) fn check_repr(r: &WorldModelRepr) -> Result<(), FieldError> {
    let n = r.structure.joint_size();
    stored_values::size(
        "structure",
        n,
        1,
        MAX_STATES,
        "joint states: the product of the factor sizes",
    )?;
    stored_values::size("n_actions", r.n_actions, 1, MAX_ACTIONS, "the car's actions")?;
    r.priors.check().map_err(|e| FieldError::from(e).within("priors"))?;
    stored_values::finite("priors.transition_concentration", &[r.priors.transition_concentration])
        .and(stored_values::finite(
            "priors.a_concentration",
            &[r.priors.a_concentration],
        ))
        .map_err(|e| FieldError::new(e.path.trim_end_matches("[0]"), e.message))?;
    if let Some(d) = &r.priors.d {
        stored_values::len("priors.d", d.len(), n, "one prior probability per joint state")?;
    }
    let factors = r.structure.factors();
    stored_values::len(
        "cpt",
        r.cpt.len(),
        factors.len(),
        "one table per factor of the structure",
    )?;
    for (f, counts) in r.cpt.iter().enumerate() {
        let path = format!("cpt[{f}]");
        let configs = r.structure.n_configs(f, r.n_actions);
        let want = stored_values::product(&path, configs, factors[f].size)?;
        stored_values::len(
            &path,
            counts.len(),
            want,
            &format!(
                "{configs} parent configurations x {} values of factor `{}`",
                factors[f].size, factors[f].name
            ),
        )?;
        stored_values::counts(&path, counts)?;
    }
    let (no, ns) = (r.a_counts.nrows(), r.a_counts.ncols());
    if ns != n || !(1..=MAX_STATES).contains(&no) {
        return Err(FieldError::new(
            "a_counts",
            format!("is {no} x {ns}; must be n_obs x {n} (one column per joint state, 1..={MAX_STATES} observations)"),
        ));
    }
    for (s, col) in r.a_counts.column_iter().enumerate() {
        if let Some(o) = col.iter().position(|x| !(0.0..=MAX_VALUE).contains(x)) {
            return Err(FieldError::new(
                format!("a_counts[{o},{s}]"),
                format!("must be a finite count in [0, {MAX_VALUE:e}], found {}", col[o]),
            ));
        }
        let z: f64 = col.sum();
        if !(z > 0.0 && z.is_finite()) {
            return Err(FieldError::new(
                format!("a_counts[..,{s}]"),
                format!("column {s} sums to {z}; each state's observation counts need a positive finite total"),
            ));
        }
    }
    stored_values::len(
        "c",
        r.c.len(),
        no,
        "one log preference per observation (rows of a_counts)",
    )?;
    stored_values::finite("c", &r.c)?;
    let m = r.c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let lse = m + r.c.iter().map(|v| (v - m).exp()).sum::<f64>().ln();
    if lse.abs() > 1e-6 {
        return Err(FieldError::new(
            "c",
            format!("is not a normalised log distribution: ln Σ exp(C) = {lse}, must be 0 (± 1e-6)"),
        ));
    }
    stored_values::len("d_counts", r.d_counts.len(), n, "one count per joint state")?;
    stored_values::counts("d_counts", &r.d_counts)?;
    if r.d_counts.iter().sum::<f64>() <= 0.0 {
        return Err(FieldError::new(
            "d_counts",
            "all zero; the initial-state counts need a positive total",
        ));
    }
    if let Some(i) = r.terminal.iter().position(|&s| s >= n) {
        return Err(FieldError::new(
            format!("terminal[{i}]"),
            format!("state {} is out of range (0..{n})", r.terminal[i]),
        ));
    }
    if let Some(t) = &r.transition_cost {
        for (name, len) in [("from", t.from.len()), ("to", t.to.len())] {
            if len != n {
                return Err(FieldError::new(
                    format!("transition_cost.{name}"),
                    format!("{len} entries, expected one per state ({n})"),
                ));
            }
        }
        if !t.cost.is_finite() {
            return Err(FieldError::new(
                "transition_cost.cost",
                format!("{} is not finite", t.cost),
            ));
        }
    }
    if let Some(c) = &r.crash {
        check_crash(c, n, r.n_actions)?;
    }
    Ok(())
}
