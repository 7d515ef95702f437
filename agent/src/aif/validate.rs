//! The rules a model in pymdp's layout must satisfy, checked once in
//! [`Model::new`](super::model::Model::new):
//!
//! * `A` and `B` are non-empty; every dependency names an existing factor, once;
//! * `B[f]` has rank `2 + |B_dependencies[f]|`, axis 0 of length `num_states[f]`
//!   (which `B[f]` defines), the parent axes of their factors' lengths, and at least one
//!   action; `A[m]` has rank `1 + |A_dependencies[m]|` and its factor axes the same lengths;
//! * every entry is finite and `>= 0`, and every column of `A`, `B` and every `D[f]` sums
//!   to 1 within [`NORM_TOL`] (pymdp's `validate_normalization` uses `isclose`);
//! * `C[m]` is `[num_obs[m]]` or `[T, num_obs[m]]`, finite; `E` is finite, `>= 0`, not all 0;
//! * `pA`, `pB` have the shapes of `A`, `B`, finite, `>= 0`, every column with a positive sum;
//! * the joint state space is at most [`MAX_JOINT_STATES`] and each array at most
//!   [`MAX_ARRAY_ENTRIES`] entries.

use super::error::ModelError;
use super::tensor::Tensor;

/// Tolerance on a distribution's sum.
pub const NORM_TOL: f64 = 1e-6;

/// Most joint states (`Π_f num_states[f]`) a model may have: inference and planning stay
/// factorised (mean field), but the exact surprise and pymdp's own tools sum over the
/// joint, and a model beyond 10⁸ joint states is not one a tick can plan on.
pub const MAX_JOINT_STATES: f64 = 1e8;

/// Most entries of one array (`A[m]`, `B[f]`, their counts): 2²⁶ f64 are 512 MiB.
pub const MAX_ARRAY_ENTRIES: usize = 1 << 26;

fn shape_err(
    array: &str,
    axis: impl Into<String>,
    found: usize,
    expected: usize,
    why: impl Into<String>,
) -> ModelError {
    ModelError::Shape {
        array: array.to_string(),
        axis: axis.into(),
        found,
        expected,
        why: why.into(),
    }
}

fn unravel(mut i: usize, shape: &[usize]) -> Vec<usize> {
    let mut idx = vec![0; shape.len()];
    for k in (0..shape.len()).rev() {
        idx[k] = i % shape[k];
        i /= shape[k];
    }
    idx
}

/// Every entry finite and `>= 0`.
fn check_entries(name: &str, t: &Tensor) -> Result<(), ModelError> {
    if let Some((i, &v)) = t.data.iter().enumerate().find(|(_, v)| !v.is_finite() || **v < 0.0) {
        let index = unravel(i, &t.shape);
        return Err(if v.is_finite() {
            ModelError::Negative {
                array: name.to_string(),
                index,
                value: v,
            }
        } else {
            ModelError::NotFinite {
                array: name.to_string(),
                index,
                value: v,
            }
        });
    }
    Ok(())
}

fn check_size(name: &str, t: &Tensor) -> Result<(), ModelError> {
    if t.data.len() > MAX_ARRAY_ENTRIES {
        return Err(ModelError::TooLarge {
            what: format!("{name}'s number of entries"),
            size: t.data.len() as f64,
            bound: MAX_ARRAY_ENTRIES as f64,
            why: "one array may take at most 512 MiB",
        });
    }
    Ok(())
}

/// Column sums over axis 0; `label(col_index)` names a column for the error.
/// `exact`: must sum to 1 (a distribution); otherwise to something > 0 (counts).
fn check_columns(name: &str, t: &Tensor, label: impl Fn(&[usize]) -> String, exact: bool) -> Result<(), ModelError> {
    let n0 = t.shape[0];
    let cols = t.data.len() / n0.max(1);
    for c in 0..cols {
        let sum: f64 = (0..n0).map(|o| t.data[o * cols + c]).sum();
        let ok = if exact {
            (sum - 1.0).abs() <= NORM_TOL
        } else {
            sum > 0.0
        };
        if !ok {
            let col = unravel(c, &t.shape[1..]);
            if !exact {
                return Err(ModelError::invalid(
                    name,
                    format!("{} sums to {sum}, must be > 0", label(&col)),
                ));
            }
            return Err(ModelError::Unnormalised {
                array: name.to_string(),
                column: label(&col),
                sum,
                tol: NORM_TOL,
            });
        }
    }
    Ok(())
}

fn check_deps(name: &str, deps: &[Vec<usize>], nf: usize) -> Result<(), ModelError> {
    for (i, d) in deps.iter().enumerate() {
        let array = format!("{name}[{i}]");
        if d.is_empty() {
            return Err(ModelError::invalid(array, "is empty, must list at least one factor"));
        }
        for (k, &f) in d.iter().enumerate() {
            if f >= nf {
                return Err(ModelError::MissingFactor {
                    array,
                    factor: f,
                    n_factors: nf,
                });
            }
            if d[..k].contains(&f) {
                return Err(ModelError::invalid(
                    array,
                    format!("lists factor {f} twice, must list each factor once"),
                ));
            }
        }
    }
    Ok(())
}

/// The column label of `B[f]`: `(s=3, u=0)` for a factor that depends on itself alone,
/// `(s0=3, s2=1, u=0)` otherwise.
fn b_label(f: usize, deps: &[usize]) -> impl Fn(&[usize]) -> String + '_ {
    move |col: &[usize]| {
        let (u, s) = col.split_last().expect("B has an action axis");
        let parts: Vec<String> = if deps == [f] {
            vec![format!("s={}", s[0])]
        } else {
            deps.iter().zip(s).map(|(d, i)| format!("s{d}={i}")).collect()
        };
        format!("column ({}, u={u})", parts.join(", "))
    }
}

fn a_label(deps: &[usize]) -> impl Fn(&[usize]) -> String + '_ {
    move |col: &[usize]| {
        let parts: Vec<String> = deps.iter().zip(col).map(|(d, i)| format!("s{d}={i}")).collect();
        format!("column ({})", parts.join(", "))
    }
}

/// The arrays of a model before validation (pymdp's argument names).
#[derive(Debug, Clone, Default, PartialEq)]
#[allow(non_snake_case)]
pub struct ModelParts {
    /// Likelihoods, one per modality.
    pub A: Vec<Tensor>,
    /// Transitions, one per state factor (the last axis is the factor's control).
    pub B: Vec<Tensor>,
    /// Log-preferences per modality (default: zeros, no preference).
    pub C: Option<Vec<Tensor>>,
    /// Initial priors per factor (default: uniform).
    pub D: Option<Vec<Vec<f64>>>,
    /// Prior over policies (default: uniform).
    pub E: Option<Vec<f64>>,
    /// Dirichlet concentrations over `A` (enables A learning).
    pub pA: Option<Vec<Tensor>>,
    /// Dirichlet concentrations over `B` (enables B learning).
    pub pB: Option<Vec<Tensor>>,
    /// The factors each modality depends on (default: all).
    pub A_dependencies: Option<Vec<Vec<usize>>>,
    /// The parents of each factor (default: itself).
    pub B_dependencies: Option<Vec<Vec<usize>>>,
}

/// The arrays of a model that passed every check, with the defaults filled in.
pub(crate) struct Checked {
    pub a: Vec<Tensor>,
    pub b: Vec<Tensor>,
    pub c: Vec<Tensor>,
    pub d: Vec<Vec<f64>>,
    pub e: Option<Vec<f64>>,
    pub pa: Option<Vec<Tensor>>,
    pub pb: Option<Vec<Tensor>>,
    pub a_deps: Vec<Vec<usize>>,
    pub b_deps: Vec<Vec<usize>>,
    pub num_states: Vec<usize>,
    pub num_obs: Vec<usize>,
    pub num_controls: Vec<usize>,
}

/// Dirichlet counts `ps` (`pA` or `pB`): the shapes of `like`, finite, `>= 0`, every
/// column with a positive sum.
fn check_counts(
    key: &str,
    ps: Option<&[Tensor]>,
    like: &[Tensor],
    deps: &[Vec<usize>],
    is_b: bool,
) -> Result<(), ModelError> {
    let Some(ps) = ps else { return Ok(()) };
    let of = &key[1..];
    if ps.len() != like.len() {
        return Err(shape_err(
            key,
            "length",
            ps.len(),
            like.len(),
            format!("one array per {of} array"),
        ));
    }
    for (i, (pt, t)) in ps.iter().zip(like).enumerate() {
        let name = format!("{key}[{i}]");
        if pt.shape != t.shape {
            return Err(ModelError::invalid(
                &name,
                format!(
                    "has shape {:?}, must be {:?} (the shape of {of}[{i}])",
                    pt.shape, t.shape
                ),
            ));
        }
        check_entries(&name, pt)?;
        let label = |c: &[usize]| {
            if is_b {
                b_label(i, &deps[i])(c)
            } else {
                a_label(&deps[i])(c)
            }
        };
        check_columns(&name, pt, label, false)?;
    }
    Ok(())
}

/// Validate and build (see the module doc for the rules).
pub(crate) fn check(p: ModelParts) -> Result<Checked, ModelError> {
    if p.B.is_empty() {
        return Err(ModelError::invalid(
            "B",
            "is empty, must hold one transition array per state factor",
        ));
    }
    if p.A.is_empty() {
        return Err(ModelError::invalid(
            "A",
            "is empty, must hold one likelihood array per modality",
        ));
    }
    let nf = p.B.len();
    let nm = p.A.len();
    let b_deps = p.B_dependencies.unwrap_or_else(|| (0..nf).map(|f| vec![f]).collect());
    let a_deps = p
        .A_dependencies
        .unwrap_or_else(|| (0..nm).map(|_| (0..nf).collect()).collect());
    if b_deps.len() != nf {
        return Err(shape_err(
            "B_dependencies",
            "length",
            b_deps.len(),
            nf,
            "one entry per state factor (len(B))",
        ));
    }
    if a_deps.len() != nm {
        return Err(shape_err(
            "A_dependencies",
            "length",
            a_deps.len(),
            nm,
            "one entry per modality (len(A))",
        ));
    }
    check_deps("B_dependencies", &b_deps, nf)?;
    check_deps("A_dependencies", &a_deps, nf)?;

    // States per factor come from axis 0 of B[f]; controls from its last axis.
    let mut num_states = Vec::with_capacity(nf);
    for (f, b) in p.B.iter().enumerate() {
        let name = format!("B[{f}]");
        let rank = 2 + b_deps[f].len();
        if b.ndim() != rank {
            return Err(shape_err(
                &name,
                "rank",
                b.ndim(),
                rank,
                format!(
                    "[s_next, one axis per parent in B_dependencies[{f}] = {:?}, u]",
                    b_deps[f]
                ),
            ));
        }
        if b.shape.contains(&0) {
            return Err(ModelError::invalid(
                name,
                format!("has an empty axis (shape {:?})", b.shape),
            ));
        }
        num_states.push(b.shape[0]);
    }
    let joint: f64 = num_states.iter().map(|&n| n as f64).product();
    if joint > MAX_JOINT_STATES {
        return Err(ModelError::TooLarge {
            what: format!("the joint state space {num_states:?}"),
            size: joint,
            bound: MAX_JOINT_STATES,
            why: "a model beyond 10^8 joint states is refused (the exact surprise sums over the joint)",
        });
    }
    let num_controls: Vec<usize> = p.B.iter().map(|b| *b.shape.last().unwrap_or(&1)).collect();
    for (f, b) in p.B.iter().enumerate() {
        let name = format!("B[{f}]");
        check_size(&name, b)?;
        for (k, &dep) in b_deps[f].iter().enumerate() {
            if b.shape[1 + k] != num_states[dep] {
                return Err(shape_err(
                    &name,
                    format!("axis {}", 1 + k),
                    b.shape[1 + k],
                    num_states[dep],
                    format!("the number of states of factor {dep} (B_dependencies[{f}][{k}]; B[{dep}].shape[0])"),
                ));
            }
        }
        check_entries(&name, b)?;
        check_columns(&name, b, b_label(f, &b_deps[f]), true)?;
    }
    let mut num_obs = Vec::with_capacity(nm);
    for (m, a) in p.A.iter().enumerate() {
        let name = format!("A[{m}]");
        let rank = 1 + a_deps[m].len();
        if a.ndim() != rank {
            return Err(shape_err(
                &name,
                "rank",
                a.ndim(),
                rank,
                format!("[o, one axis per factor in A_dependencies[{m}] = {:?}]", a_deps[m]),
            ));
        }
        check_size(&name, a)?;
        if a.shape[0] == 0 {
            return Err(ModelError::invalid(name, "has no observations (axis 0 is empty)"));
        }
        for (k, &dep) in a_deps[m].iter().enumerate() {
            if a.shape[1 + k] != num_states[dep] {
                return Err(shape_err(
                    &name,
                    format!("axis {}", 1 + k),
                    a.shape[1 + k],
                    num_states[dep],
                    format!("the number of states of factor {dep} (A_dependencies[{m}][{k}]; B[{dep}].shape[0])"),
                ));
            }
        }
        check_entries(&name, a)?;
        check_columns(&name, a, a_label(&a_deps[m]), true)?;
        num_obs.push(a.shape[0]);
    }

    let c = match p.C {
        None => num_obs.iter().map(|&n| Tensor::filled(vec![n], 0.0)).collect(),
        Some(c) => {
            if c.len() != nm {
                return Err(shape_err(
                    "C",
                    "length",
                    c.len(),
                    nm,
                    "one preference array per modality",
                ));
            }
            for (m, cm) in c.iter().enumerate() {
                let name = format!("C[{m}]");
                let last = cm.shape.last().copied().unwrap_or(0);
                if !(1..=2).contains(&cm.ndim()) {
                    return Err(shape_err(
                        &name,
                        "rank",
                        cm.ndim(),
                        1,
                        "[o], or [t, o] when time-indexed",
                    ));
                }
                if last != num_obs[m] {
                    return Err(shape_err(
                        &name,
                        format!("axis {}", cm.ndim() - 1),
                        last,
                        num_obs[m],
                        format!("the number of observations of modality {m} (A[{m}].shape[0])"),
                    ));
                }
                if let Some((i, v)) = cm.data.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Err(ModelError::NotFinite {
                        array: name,
                        index: unravel(i, &cm.shape),
                        value: *v,
                    });
                }
            }
            c
        }
    };

    let d = match p.D {
        None => num_states.iter().map(|&n| vec![1.0 / n as f64; n]).collect(),
        Some(d) => {
            if d.len() != nf {
                return Err(shape_err("D", "length", d.len(), nf, "one prior per state factor"));
            }
            for (f, df) in d.iter().enumerate() {
                let name = format!("D[{f}]");
                if df.len() != num_states[f] {
                    return Err(shape_err(
                        &name,
                        "axis 0",
                        df.len(),
                        num_states[f],
                        format!("the number of states of factor {f} (B[{f}].shape[0])"),
                    ));
                }
                let t = Tensor {
                    shape: vec![df.len()],
                    data: df.clone(),
                };
                check_entries(&name, &t)?;
                let sum: f64 = df.iter().sum();
                if (sum - 1.0).abs() > NORM_TOL {
                    return Err(ModelError::Unnormalised {
                        array: name,
                        column: "(the whole vector)".into(),
                        sum,
                        tol: NORM_TOL,
                    });
                }
            }
            d
        }
    };

    if let Some(e) = &p.E {
        let t = Tensor {
            shape: vec![e.len()],
            data: e.clone(),
        };
        check_entries("E", &t)?;
        if !e.iter().any(|v| *v > 0.0) {
            return Err(ModelError::invalid(
                "E",
                "is all zeros, must give some policy a positive prior",
            ));
        }
    }

    check_counts("pA", p.pA.as_deref(), &p.A, &a_deps, false)?;
    check_counts("pB", p.pB.as_deref(), &p.B, &b_deps, true)?;

    Ok(Checked {
        a: p.A,
        b: p.B,
        c,
        d,
        e: p.E,
        pa: p.pA,
        pb: p.pB,
        a_deps,
        b_deps,
        num_states,
        num_obs,
        num_controls,
    })
}
