//! Policies as pymdp builds them (`control._construct_policies_tuple`): every sequence of
//! `policy_len` multi-actions, one action per state factor (0 for an uncontrolled factor),
//! enumerated as `itertools.product` over `[t0 f0, t0 f1, ..., t1 f0, ...]`, so the first
//! step is the most significant digit. Or a list the user gives.

use super::error::ModelError;

/// A table of policies: `len() x policy_len x num_factors` actions.
#[derive(Debug, Clone, PartialEq)]
pub struct Policies {
    exhaustive: bool,
    policy_len: usize,
    num_factors: usize,
    actions: Vec<usize>,
}

impl Policies {
    /// All `Π_f num_controls[f] ^ policy_len` policies, in pymdp's order, if there are at
    /// most [`crate::limits::MAX_POLICIES`].
    pub fn exhaustive(num_controls: &[usize], policy_len: usize) -> Result<Policies, ModelError> {
        if policy_len == 0 {
            return Err(ModelError::invalid("policy_len", "is 0, must be at least 1"));
        }
        let per_step: f64 = num_controls.iter().map(|&n| n as f64).product();
        let count = per_step.powi(policy_len as i32);
        if count > crate::limits::MAX_POLICIES as f64 {
            return Err(ModelError::TooLarge {
                what: format!("the number of policies, {per_step} multi-actions ^ policy_len {policy_len},"),
                size: count,
                bound: crate::limits::MAX_POLICIES as f64,
                why: "every policy is evaluated on each planning tick (limits::MAX_POLICIES)",
            });
        }
        let count = count as usize;
        let nf = num_controls.len();
        let digits: Vec<usize> = (0..policy_len).flat_map(|_| num_controls.iter().copied()).collect();
        let mut actions = vec![0; count * digits.len()];
        for p in 0..count {
            let mut rest = p;
            for k in (0..digits.len()).rev() {
                actions[p * digits.len() + k] = rest % digits[k];
                rest /= digits[k];
            }
        }
        Ok(Policies {
            exhaustive: true,
            policy_len,
            num_factors: nf,
            actions,
        })
    }

    /// Given policies, `list[p][t][f]`, checked against the model's controls.
    pub fn given(list: &[Vec<Vec<usize>>], num_controls: &[usize]) -> Result<Policies, ModelError> {
        let first = list
            .first()
            .ok_or_else(|| ModelError::invalid("policies", "is empty, must hold at least one policy"))?;
        let policy_len = first.len();
        if policy_len == 0 {
            return Err(ModelError::invalid("policies[0]", "has no time steps"));
        }
        if list.len() > crate::limits::MAX_POLICIES {
            return Err(ModelError::TooLarge {
                what: "the number of policies".into(),
                size: list.len() as f64,
                bound: crate::limits::MAX_POLICIES as f64,
                why: "every policy is evaluated on each planning tick (limits::MAX_POLICIES)",
            });
        }
        let nf = num_controls.len();
        let mut actions = Vec::with_capacity(list.len() * policy_len * nf);
        for (p, pol) in list.iter().enumerate() {
            if pol.len() != policy_len {
                return Err(ModelError::invalid(
                    format!("policies[{p}]"),
                    format!(
                        "has {} steps, policies[0] has {policy_len}: all must have the same length",
                        pol.len()
                    ),
                ));
            }
            for (t, step) in pol.iter().enumerate() {
                if step.len() != nf {
                    return Err(ModelError::invalid(
                        format!("policies[{p}][{t}]"),
                        format!("has {} actions, must have one per state factor ({nf})", step.len()),
                    ));
                }
                for (f, &u) in step.iter().enumerate() {
                    if u >= num_controls[f] {
                        return Err(ModelError::invalid(
                            format!("policies[{p}][{t}][{f}]"),
                            format!("is {u}, must be < {} (B[{f}].shape[-1])", num_controls[f]),
                        ));
                    }
                }
                actions.extend_from_slice(step);
            }
        }
        Ok(Policies {
            exhaustive: false,
            policy_len,
            num_factors: nf,
            actions,
        })
    }

    /// Whether these are all policies in pymdp's order ([`Policies::exhaustive`]).
    pub fn is_exhaustive(&self) -> bool {
        self.exhaustive
    }

    /// Number of policies.
    pub fn len(&self) -> usize {
        self.actions.len() / (self.policy_len * self.num_factors)
    }

    /// Whether there are none (never, once built).
    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    /// Steps per policy.
    pub fn policy_len(&self) -> usize {
        self.policy_len
    }

    /// The multi-action of policy `p` at step `t` (one action per factor).
    pub fn step(&self, p: usize, t: usize) -> &[usize] {
        let k = (p * self.policy_len + t) * self.num_factors;
        &self.actions[k..k + self.num_factors]
    }

    /// Every policy as `[t][f]`.
    pub fn to_vec(&self) -> Vec<Vec<Vec<usize>>> {
        (0..self.len())
            .map(|p| (0..self.policy_len).map(|t| self.step(p, t).to_vec()).collect())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pymdp_order_first_step_most_significant() {
        let p = Policies::exhaustive(&[3], 2).unwrap();
        let v = p.to_vec();
        assert_eq!(v.len(), 9);
        assert_eq!(
            v[..4],
            [
                vec![vec![0], vec![0]],
                vec![vec![0], vec![1]],
                vec![vec![0], vec![2]],
                vec![vec![1], vec![0]]
            ]
        );
        let q = Policies::exhaustive(&[2, 1, 3], 1).unwrap().to_vec();
        assert_eq!(
            q,
            vec![
                vec![vec![0, 0, 0]],
                vec![vec![0, 0, 1]],
                vec![vec![0, 0, 2]],
                vec![vec![1, 0, 0]],
                vec![vec![1, 0, 1]],
                vec![vec![1, 0, 2]]
            ]
        );
        assert!(
            Policies::exhaustive(&[5], 8)
                .unwrap_err()
                .to_string()
                .contains("390625")
        );
        assert!(
            Policies::given(&[vec![vec![3]]], &[3])
                .unwrap_err()
                .to_string()
                .contains("policies[0][0][0]: is 3, must be < 3")
        );
    }
}
