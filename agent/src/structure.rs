//! State factors and their parents: the structure of the world model's dynamic
//! Bayesian network (§II-A world model; docs/ARCHITECTURE.md §4.2). The structure is data:
//! the paper's `v'|v,u; d'|d,v'; L'|L; p'|p,L',d'` is one value, [`Structure::paper_default`].
//!
//! Joint indexing: factors in order, first factor most significant. For the
//! default `[d, v, L, p]` with sizes `[4, 4, 2, 2]`, `s = ((d*4 + v)*2 + L)*2 + p`.

use crate::error::AgentError;
use serde::{Deserialize, Serialize};

/// A parent of a factor's next-time value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Parent {
    /// The previous-time value of factor `i`.
    Prev(usize),
    /// The next-time value of factor `i` (must precede the child in a topological order).
    Next(usize),
}

/// One state factor: name, number of values, parents, and whether the action is a parent.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Factor {
    /// Name, e.g. `"v"`.
    pub name: String,
    /// Number of values.
    pub size: usize,
    /// Parents (previous- or next-time factors).
    pub parents: Vec<Parent>,
    /// Whether the action `u` is a parent.
    pub action_parent: bool,
}

/// A validated factor structure with precomputed strides and a topological order.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "Vec<Factor>", into = "Vec<Factor>")]
pub struct Structure {
    factors: Vec<Factor>,
    /// Topological order over next-time factors.
    order: Vec<usize>,
    /// Stride of each factor in the joint index.
    strides: Vec<usize>,
    joint: usize,
}

impl From<Structure> for Vec<Factor> {
    fn from(s: Structure) -> Self {
        s.factors
    }
}

impl TryFrom<Vec<Factor>> for Structure {
    type Error = AgentError;
    fn try_from(f: Vec<Factor>) -> Result<Self, AgentError> {
        Structure::new(f)
    }
}

impl Structure {
    /// Validate factors (sizes >= 1, parent indices in range, no duplicate parents,
    /// next-time parents acyclic) and build the structure (§II-A).
    pub fn new(factors: Vec<Factor>) -> Result<Structure, AgentError> {
        let n = factors.len();
        if n == 0 {
            return Err(AgentError::Structure("no factors".into()));
        }
        if n > crate::limits::MAX_FACTORS {
            return Err(AgentError::Structure(format!(
                "{n} factors; at most {} (see limits::MAX_FACTORS)",
                crate::limits::MAX_FACTORS
            )));
        }
        for f in &factors {
            if f.size == 0 {
                return Err(AgentError::Structure(format!("factor `{}` has size 0", f.name)));
            }
            for (i, p) in f.parents.iter().enumerate() {
                let j = match p {
                    Parent::Prev(j) | Parent::Next(j) => *j,
                };
                if j >= n {
                    return Err(AgentError::Structure(format!(
                        "factor `{}` has parent index {j} out of range ({n} factors)",
                        f.name
                    )));
                }
                if f.parents[..i].contains(p) {
                    return Err(AgentError::Structure(format!(
                        "factor `{}` lists parent {p:?} twice",
                        f.name
                    )));
                }
            }
        }
        // Kahn's algorithm over Next edges.
        let mut indeg = vec![0usize; n];
        for (c, f) in factors.iter().enumerate() {
            for p in &f.parents {
                if let Parent::Next(j) = p {
                    if *j == c {
                        return Err(AgentError::Structure(format!(
                            "factor `{}` is its own next-time parent",
                            f.name
                        )));
                    }
                    indeg[c] += 1;
                }
            }
        }
        let mut order = Vec::with_capacity(n);
        let mut ready: Vec<usize> = (0..n).filter(|i| indeg[*i] == 0).collect();
        ready.reverse();
        while let Some(i) = ready.pop() {
            order.push(i);
            for (c, f) in factors.iter().enumerate() {
                if f.parents.contains(&Parent::Next(i)) {
                    indeg[c] -= 1;
                    if indeg[c] == 0 {
                        ready.push(c);
                    }
                }
            }
        }
        if order.len() != n {
            return Err(AgentError::Structure("next-time parents form a cycle".into()));
        }
        let mut strides = vec![1usize; n];
        let mut joint = 1usize;
        for i in (0..n).rev() {
            strides[i] = joint;
            joint = joint
                .checked_mul(factors[i].size)
                .ok_or_else(|| AgentError::Structure("joint state space too large".into()))?;
        }
        Ok(Structure {
            factors,
            order,
            strides,
            joint,
        })
    }

    /// The paper's structure (§VI): factors `d, v, L, p` with sizes `sizes`, and
    /// `v' <- (v, u); d' <- (d, v'); L' <- L; p' <- (p, L', d')`.
    pub fn paper_default(sizes: [usize; 4]) -> Result<Structure, AgentError> {
        let f = |name: &str, size, parents, action_parent| Factor {
            name: name.to_string(),
            size,
            parents,
            action_parent,
        };
        Structure::new(vec![
            f("d", sizes[0], vec![Parent::Prev(0), Parent::Next(1)], false),
            f("v", sizes[1], vec![Parent::Prev(1)], true),
            f("L", sizes[2], vec![Parent::Prev(2)], false),
            f(
                "p",
                sizes[3],
                vec![Parent::Prev(3), Parent::Next(2), Parent::Next(0)],
                false,
            ),
        ])
    }

    /// A single factor of `n` values with parents `(s, u)`: the flat joint model.
    pub fn flat(n: usize) -> Result<Structure, AgentError> {
        Structure::new(vec![Factor {
            name: "s".into(),
            size: n,
            parents: vec![Parent::Prev(0)],
            action_parent: true,
        }])
    }

    /// The factors.
    pub fn factors(&self) -> &[Factor] {
        &self.factors
    }

    /// A topological order of the next-time factors.
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// Number of joint states, the product of factor sizes.
    pub fn joint_size(&self) -> usize {
        self.joint
    }

    /// Joint index of factor values (first factor most significant). Values are
    /// taken modulo nothing: callers pass values in range.
    pub fn encode(&self, values: &[usize]) -> usize {
        values.iter().zip(&self.strides).map(|(v, s)| v * s).sum()
    }

    /// Factor values of a joint index.
    pub fn decode(&self, s: usize) -> Vec<usize> {
        let mut out = vec![0; self.factors.len()];
        self.decode_into(s, &mut out);
        out
    }

    /// Factor values of a joint index into `out` (no allocation).
    pub fn decode_into(&self, s: usize, out: &mut [usize]) {
        for (i, f) in self.factors.iter().enumerate() {
            out[i] = (s / self.strides[i]) % f.size;
        }
    }

    /// Number of values of every factor, in factor order.
    pub fn sizes(&self) -> Vec<usize> {
        self.factors.iter().map(|f| f.size).collect()
    }

    /// Number of values of each parent of factor `f`, in parent order.
    pub fn parent_sizes(&self, f: usize) -> Vec<usize> {
        self.factors[f]
            .parents
            .iter()
            .map(|p| match p {
                Parent::Prev(j) | Parent::Next(j) => self.factors[*j].size,
            })
            .collect()
    }

    /// Number of parent configurations of factor `f` (product of parent sizes, times
    /// the number of actions if the action is a parent).
    pub fn n_configs(&self, f: usize, n_actions: usize) -> usize {
        let p: usize = self.parent_sizes(f).iter().product();
        if self.factors[f].action_parent {
            p * n_actions
        } else {
            p
        }
    }

    /// Parent-configuration index of factor `f` given previous values `prev`, next
    /// values `next` and action `u` (mixed radix in parent order, action last).
    pub fn config_index(&self, f: usize, prev: &[usize], next: &[usize], u: usize, n_actions: usize) -> usize {
        let fac = &self.factors[f];
        let mut idx = 0;
        for p in &fac.parents {
            let (j, v) = match p {
                Parent::Prev(j) => (*j, prev[*j]),
                Parent::Next(j) => (*j, next[*j]),
            };
            idx = idx * self.factors[j].size + v;
        }
        if fac.action_parent { idx * n_actions + u } else { idx }
    }

    /// Parent-configuration index from explicit parent values (in parent order) and action.
    pub fn config_from_parent_values(
        &self,
        f: usize,
        parent_values: &[usize],
        action: Option<usize>,
        n_actions: usize,
    ) -> usize {
        let fac = &self.factors[f];
        let mut idx = 0;
        for (p, v) in fac.parents.iter().zip(parent_values) {
            let j = match p {
                Parent::Prev(j) | Parent::Next(j) => *j,
            };
            idx = idx * self.factors[j].size + v;
        }
        if fac.action_parent {
            idx * n_actions + action.unwrap_or(0)
        } else {
            idx
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_indexing() {
        let s = Structure::paper_default([4, 4, 2, 2]).unwrap();
        assert_eq!(s.joint_size(), 64);
        let (d, v, l, p) = (2, 3, 1, 0);
        let j = s.encode(&[d, v, l, p]);
        assert_eq!(j, ((d * 4 + v) * 2 + l) * 2 + p);
        assert_eq!(s.decode(j), vec![d, v, l, p]);
        for j in 0..64 {
            assert_eq!(s.encode(&s.decode(j)), j);
        }
        // v before d, L before p, d before p.
        let pos = |i| s.order().iter().position(|x| *x == i).unwrap();
        assert!(pos(1) < pos(0) && pos(2) < pos(3) && pos(0) < pos(3));
        assert_eq!(s.n_configs(1, 3), 12);
        assert_eq!(s.n_configs(3, 3), 16);
    }

    #[test]
    fn cycles_and_bad_indices_rejected() {
        let f = |parents| Factor {
            name: "x".into(),
            size: 2,
            parents,
            action_parent: false,
        };
        assert!(Structure::new(vec![f(vec![Parent::Next(1)]), f(vec![Parent::Next(0)])]).is_err());
        assert!(Structure::new(vec![f(vec![Parent::Prev(3)])]).is_err());
        assert!(Structure::paper_default([4, 0, 2, 2]).is_err());
    }
}
