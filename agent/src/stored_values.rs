//! Checks of stored values when a learner is read back (see [`crate::persist`]): each
//! failure is a [`FieldError`] naming the field, e.g. `table[17]`.

use crate::error::FieldError;
use crate::limits::MAX_VALUE;

/// `found == expected`, else "`path` has `found` entries, expected `expected` (`why`)".
pub(crate) fn len(path: &str, found: usize, expected: usize, why: &str) -> Result<(), FieldError> {
    if found == expected {
        Ok(())
    } else {
        Err(FieldError::new(
            path,
            format!("has {found} entries, expected {expected} ({why})"),
        ))
    }
}

/// `lo <= n <= hi`.
pub(crate) fn size(path: &str, n: usize, lo: usize, hi: usize, why: &str) -> Result<(), FieldError> {
    if (lo..=hi).contains(&n) {
        Ok(())
    } else {
        Err(FieldError::new(path, format!("is {n}; must be in {lo}..={hi} ({why})")))
    }
}

/// `n_states` and `n_actions` of a stored learner within [`crate::limits`].
pub(crate) fn state_action_sizes(n_states: usize, n_actions: usize) -> Result<(), FieldError> {
    size(
        "n_states",
        n_states,
        1,
        crate::limits::MAX_STATES,
        "the joint states of the map's bins",
    )?;
    size(
        "n_actions",
        n_actions,
        1,
        crate::limits::MAX_ACTIONS,
        "the car's actions",
    )
}

/// `x` is finite and at most [`MAX_VALUE`] in size (false for NaN).
pub(crate) fn bounded(x: f64) -> bool {
    (-MAX_VALUE..=MAX_VALUE).contains(&x)
}

/// Every entry finite and at most [`MAX_VALUE`] in size (rewards, Q-values, log
/// preferences).
pub(crate) fn finite(path: &str, xs: &[f64]) -> Result<(), FieldError> {
    match xs.iter().position(|x| !bounded(*x)) {
        None => Ok(()),
        Some(i) => Err(FieldError::new(
            format!("{path}[{i}]"),
            format!("must be a finite number of size at most {MAX_VALUE:e}, found {}", xs[i]),
        )),
    }
}

/// Every entry a finite count in [0, [`MAX_VALUE`]], and their sum finite (Dirichlet
/// counts, visits).
pub(crate) fn counts(path: &str, xs: &[f64]) -> Result<(), FieldError> {
    if let Some(i) = xs.iter().position(|x| !(0.0..=MAX_VALUE).contains(x)) {
        return Err(FieldError::new(
            format!("{path}[{i}]"),
            format!("must be a finite count in [0, {MAX_VALUE:e}], found {}", xs[i]),
        ));
    }
    if !xs.iter().sum::<f64>().is_finite() {
        return Err(FieldError::new(path, "its counts sum to infinity"));
    }
    Ok(())
}

/// `a * b` without overflow, else an error naming `path`.
pub(crate) fn product(path: &str, a: usize, b: usize) -> Result<usize, FieldError> {
    a.checked_mul(b)
        .ok_or_else(|| FieldError::new(path, format!("{a} x {b} entries do not fit in memory")))
}
