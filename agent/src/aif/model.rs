//! A discrete generative model in pymdp's layout (pymdp 1.0.4, `Agent(A, B, C, D, E, pA,
//! pB, A_dependencies, B_dependencies)`), validated once when built.
//!
//! | array | layout |
//! |---|---|
//! | `A[m]` | `[o, s_{d_1}, s_{d_2}, ...]` over the factors `A_dependencies[m]`, normalised over axis 0 |
//! | `B[f]` | `[s_next, s_{d_1}, ..., u]` over the parents `B_dependencies[f]`, normalised over axis 0; the last axis is factor f's control |
//! | `C[m]` | `[o]`, or `[t, o]` time-indexed over the horizon: log-preferences |
//! | `D[f]` | `[s]`: the prior over the first state |
//! | `E` | `[policy]`: the prior over policies (habits); uniform when absent |
//! | `pA`, `pB` | as `A`, `B`: Dirichlet concentrations |

use super::error::ModelError;
use super::tensor::Tensor;
use super::validate;
pub use super::validate::ModelParts;
use serde_json::Value;

/// A validated model: every array has the shape its dependencies imply, every
/// distribution sums to one, and every count is finite and non-negative.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub(crate) a: Vec<Tensor>,
    pub(crate) b: Vec<Tensor>,
    pub(crate) c: Vec<Tensor>,
    pub(crate) d: Vec<Vec<f64>>,
    pub(crate) e: Option<Vec<f64>>,
    pub(crate) pa: Option<Vec<Tensor>>,
    pub(crate) pb: Option<Vec<Tensor>>,
    pub(crate) a_deps: Vec<Vec<usize>>,
    pub(crate) b_deps: Vec<Vec<usize>>,
    pub(crate) num_states: Vec<usize>,
    pub(crate) num_obs: Vec<usize>,
    pub(crate) num_controls: Vec<usize>,
}

impl Model {
    /// Validate `parts` (see [`validate`] for every rule) and build the model.
    pub fn new(parts: ModelParts) -> Result<Model, ModelError> {
        let v = validate::check(parts)?;
        Ok(Model {
            a: v.a,
            b: v.b,
            c: v.c,
            d: v.d,
            e: v.e,
            pa: v.pa,
            pb: v.pb,
            a_deps: v.a_deps,
            b_deps: v.b_deps,
            num_states: v.num_states,
            num_obs: v.num_obs,
            num_controls: v.num_controls,
        })
    }

    /// Read a model from pymdp-layout JSON: `{"A": [...], "B": [...], "C"?, "D"?, "E"?,
    /// "pA"?, "pB"?, "A_dependencies"?, "B_dependencies"?}` with nested arrays. Other
    /// keys are left to the caller (e.g. `obs`, `policy_len`).
    pub fn from_json(v: &Value) -> Result<Model, ModelError> {
        Model::new(parts_from_json(v)?)
    }

    /// The model as pymdp-layout JSON (the keys [`Model::from_json`] reads).
    pub fn to_json(&self) -> Value {
        let list = |ts: &[Tensor]| Value::Array(ts.iter().map(Tensor::to_json).collect());
        let mut m = serde_json::Map::new();
        m.insert("A".into(), list(&self.a));
        m.insert("B".into(), list(&self.b));
        m.insert("C".into(), list(&self.c));
        m.insert("D".into(), serde_json::json!(self.d));
        if let Some(e) = &self.e {
            m.insert("E".into(), serde_json::json!(e));
        }
        if let Some(p) = &self.pa {
            m.insert("pA".into(), list(p));
        }
        if let Some(p) = &self.pb {
            m.insert("pB".into(), list(p));
        }
        m.insert("A_dependencies".into(), serde_json::json!(self.a_deps));
        m.insert("B_dependencies".into(), serde_json::json!(self.b_deps));
        Value::Object(m)
    }

    /// `A[m]`.
    pub fn a(&self) -> &[Tensor] {
        &self.a
    }
    /// `B[f]`.
    pub fn b(&self) -> &[Tensor] {
        &self.b
    }
    /// `C[m]`, as given (rank 1, or rank 2 when time-indexed).
    pub fn c(&self) -> &[Tensor] {
        &self.c
    }
    /// `D[f]`.
    pub fn d(&self) -> &[Vec<f64>] {
        &self.d
    }
    /// `E`, if given.
    pub fn e(&self) -> Option<&[f64]> {
        self.e.as_deref()
    }
    /// `pA`, if given.
    pub fn pa(&self) -> Option<&[Tensor]> {
        self.pa.as_deref()
    }
    /// `pB`, if given.
    pub fn pb(&self) -> Option<&[Tensor]> {
        self.pb.as_deref()
    }
    /// `A_dependencies`.
    pub fn a_dependencies(&self) -> &[Vec<usize>] {
        &self.a_deps
    }
    /// `B_dependencies`.
    pub fn b_dependencies(&self) -> &[Vec<usize>] {
        &self.b_deps
    }
    /// States per factor.
    pub fn num_states(&self) -> &[usize] {
        &self.num_states
    }
    /// Observations per modality.
    pub fn num_obs(&self) -> &[usize] {
        &self.num_obs
    }
    /// Actions per control factor (one per state factor; 1 for an uncontrolled one).
    pub fn num_controls(&self) -> &[usize] {
        &self.num_controls
    }
    /// Number of state factors.
    pub fn num_factors(&self) -> usize {
        self.b.len()
    }
    /// Number of modalities.
    pub fn num_modalities(&self) -> usize {
        self.a.len()
    }

    /// `obs` holds one valid index per modality.
    pub fn check_obs(&self, obs: &[usize]) -> Result<(), ModelError> {
        if obs.len() != self.num_modalities() {
            return Err(ModelError::invalid(
                "obs",
                format!(
                    "has {} entries, must have one per modality ({})",
                    obs.len(),
                    self.num_modalities()
                ),
            ));
        }
        for (m, (&o, &n)) in obs.iter().zip(&self.num_obs).enumerate() {
            if o >= n {
                return Err(ModelError::invalid(
                    format!("obs[{m}]"),
                    format!("is {o}, must be < {n} (A[{m}].shape[0])"),
                ));
            }
        }
        Ok(())
    }

    /// `u` holds one valid action per factor.
    pub fn check_action(&self, u: &[usize]) -> Result<(), ModelError> {
        if u.len() != self.num_factors() {
            return Err(ModelError::invalid(
                "action",
                format!(
                    "has {} entries, must have one per state factor ({})",
                    u.len(),
                    self.num_factors()
                ),
            ));
        }
        for (f, (&a, &n)) in u.iter().zip(&self.num_controls).enumerate() {
            if a >= n {
                return Err(ModelError::invalid(
                    format!("action[{f}]"),
                    format!("is {a}, must be < {n} (B[{f}].shape[-1])"),
                ));
            }
        }
        Ok(())
    }

    /// `qs` (named `name` in the error: `qs`, `empirical_prior`) holds one distribution
    /// per factor, of that factor's length, with finite non-negative entries.
    pub fn check_marginals(&self, name: &str, qs: &[Vec<f64>]) -> Result<(), ModelError> {
        if qs.len() != self.num_factors() || qs.iter().zip(&self.num_states).any(|(q, &n)| q.len() != n) {
            return Err(ModelError::invalid(
                name,
                format!(
                    "has lengths {:?}, must hold one distribution per factor of lengths {:?}",
                    qs.iter().map(Vec::len).collect::<Vec<_>>(),
                    self.num_states
                ),
            ));
        }
        for (f, q) in qs.iter().enumerate() {
            if let Some(x) = q.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
                return Err(ModelError::invalid(
                    format!("{name}[{f}]"),
                    format!("holds {x}, must be finite and >= 0"),
                ));
            }
        }
        Ok(())
    }

    /// The utility of `obs` under `C`: `Σ_m C_m[o_m]` (a time-indexed `C`'s first row).
    pub fn utility(&self, obs: &[usize]) -> Result<f64, ModelError> {
        self.check_obs(obs)?;
        Ok(obs.iter().zip(&self.c).map(|(&o, cm)| cm.data[o]).sum())
    }
}

/// The arrays of a pymdp-layout JSON object, named for errors (`A[1]`, `pB[0]`, ...).
pub fn parts_from_json(v: &Value) -> Result<ModelParts, ModelError> {
    let obj = v.as_object().ok_or_else(|| {
        ModelError::invalid(
            "model",
            "must be a JSON object with keys A, B (and C, D, E, pA, pB, A_dependencies, B_dependencies)",
        )
    })?;
    let list = |key: &str| -> Result<Option<Vec<Tensor>>, ModelError> {
        match obj.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Array(items)) => items
                .iter()
                .enumerate()
                .map(|(i, x)| Tensor::from_json(&format!("{key}[{i}]"), x))
                .collect::<Result<Vec<_>, _>>()
                .map(Some),
            Some(_) => Err(ModelError::invalid(
                key,
                "must be a list of arrays (one per modality or factor)",
            )),
        }
    };
    let deps = |key: &str| -> Result<Option<Vec<Vec<usize>>>, ModelError> {
        match obj.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(x) => serde_json::from_value(x.clone())
                .map(Some)
                .map_err(|e| ModelError::invalid(key, format!("must be a list of lists of factor indices ({e})"))),
        }
    };
    let vector = |name: &str, t: Tensor| -> Result<Vec<f64>, ModelError> {
        if t.ndim() != 1 {
            return Err(ModelError::Shape {
                array: name.to_string(),
                axis: "rank".into(),
                found: t.ndim(),
                expected: 1,
                why: "a vector".into(),
            });
        }
        Ok(t.data)
    };
    let a = list("A")?.ok_or_else(|| ModelError::invalid("A", "missing (one likelihood array per modality)"))?;
    let b = list("B")?.ok_or_else(|| ModelError::invalid("B", "missing (one transition array per factor)"))?;
    let d = match list("D")? {
        None => None,
        Some(ts) => Some(
            ts.into_iter()
                .enumerate()
                .map(|(f, t)| vector(&format!("D[{f}]"), t))
                .collect::<Result<Vec<_>, _>>()?,
        ),
    };
    let e = match obj.get("E") {
        None | Some(Value::Null) => None,
        Some(x) => Some(vector("E", Tensor::from_json("E", x)?)?),
    };
    Ok(ModelParts {
        A: a,
        B: b,
        C: list("C")?,
        D: d,
        E: e,
        pA: list("pA")?,
        pB: list("pB")?,
        A_dependencies: deps("A_dependencies")?,
        B_dependencies: deps("B_dependencies")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(shape: &[usize], data: &[f64]) -> Tensor {
        Tensor {
            shape: shape.to_vec(),
            data: data.to_vec(),
        }
    }

    /// Two factors (3 and 2 states), factor 1 depends on both; one modality on factor 0.
    fn parts() -> ModelParts {
        let a = t(&[2, 3], &[1.0, 0.5, 0.0, 0.0, 0.5, 1.0]);
        let b0 = Tensor {
            shape: vec![3, 3, 1],
            data: (0..9).map(|i| if i / 3 == i % 3 { 1.0 } else { 0.0 }).collect(),
        };
        // B[1][s1', s0, s1, u]: shape [2, 3, 2, 2], uniform over s1'.
        let b1 = Tensor::filled(vec![2, 3, 2, 2], 0.5);
        ModelParts {
            A: vec![a],
            B: vec![b0, b1],
            A_dependencies: Some(vec![vec![0]]),
            B_dependencies: Some(vec![vec![0], vec![0, 1]]),
            ..ModelParts::default()
        }
    }

    fn err(p: ModelParts) -> String {
        Model::new(p).unwrap_err().to_string()
    }

    #[test]
    fn a_valid_model_builds_with_pymdp_defaults() {
        let m = Model::new(parts()).unwrap();
        assert_eq!(m.num_states(), &[3, 2]);
        assert_eq!(m.num_controls(), &[1, 2]);
        assert_eq!(m.num_obs(), &[2]);
        assert_eq!(m.d()[1], vec![0.5, 0.5]);
        assert_eq!(m.c()[0].data, vec![0.0, 0.0]);
    }

    #[test]
    fn bad_models_are_refused_with_the_array_axis_and_rule() {
        let mut p = parts();
        p.B[1].data[12 + 4] = 0.2; // s1'=1, s0=1, s1=0, u=0
        assert_eq!(
            err(p),
            "B[1] column (s0=1, s1=0, u=0) sums to 0.7, must be 1 (within 1e-6)"
        );
        let mut p = parts();
        p.B[0].data.iter_mut().for_each(|v| *v *= 0.7);
        assert!(err(p).starts_with("B[0] column (s=0, u=0) sums to 0.7"));
        let mut p = parts();
        p.A[0].data[1] = f64::NAN;
        assert!(err(p).contains("A[0] entry [0, 1] is NaN"));
        let mut p = parts();
        p.A[0].data[0] = -0.5;
        p.A[0].data[3] = 1.5;
        assert!(err(p).contains("A[0] entry [0, 0] is -0.5, must be >= 0"));
        let mut p = parts();
        p.B_dependencies = Some(vec![vec![0], vec![0, 2]]);
        assert_eq!(
            err(p),
            "B_dependencies[1] lists factor 2, but the model has 2 factors (0..2)"
        );
        let mut p = parts();
        p.A_dependencies = Some(vec![vec![1]]);
        assert!(
            err(p).contains("A[0] axis 1 has length 3, must be 2"),
            "{}",
            err(parts_a1())
        );
        let mut p = parts();
        p.D = Some(vec![vec![1.0, 0.0, 0.0], vec![0.5, 0.5, 0.0]]);
        assert!(err(p).starts_with("D[1] axis 0 has length 3, must be 2"));
        let mut p = parts();
        p.C = Some(vec![t(&[3], &[0.0, 1.0, 2.0])]);
        assert!(err(p).starts_with("C[0] axis 0 has length 3, must be 2"));
        let mut p = parts();
        p.pB = Some(vec![p.B[0].clone(), Tensor::filled(vec![2, 3, 2, 2], 0.0)]);
        assert!(err(p).contains("pB[1]: column (s0=0, s1=0, u=0) sums to 0, must be > 0"));
    }

    fn parts_a1() -> ModelParts {
        let mut p = parts();
        p.A_dependencies = Some(vec![vec![1]]);
        p
    }

    #[test]
    fn a_joint_state_space_beyond_the_bound_is_refused_before_anything_is_read() {
        // Five factors of 100 states each: 10^10 joint states. The arrays are not even
        // full size (B[f] is [100, 1, 1] short of its parents), the bound comes first.
        let b = Tensor::filled(vec![100, 100, 1], 0.01);
        let p = ModelParts {
            A: vec![Tensor::filled(vec![1, 100], 1.0)],
            B: vec![b; 5],
            A_dependencies: Some(vec![vec![0]]),
            ..ModelParts::default()
        };
        assert!(err(p).starts_with(
            "the joint state space [100, 100, 100, 100, 100] is 10000000000, more than the bound 100000000"
        ));
    }
}
