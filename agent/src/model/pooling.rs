//! Persistence pooling (beyond the paper; docs/ARCHITECTURE.md §4.2): CPT rows of one
//! factor that share their counts, so that a pedestrian on the crosswalk stays or leaves
//! alike whatever the pooled parents (the car's distance, the light).

use crate::error::AgentError;
use crate::structure::{Parent, Structure};

/// Which CPT rows of one factor share their counts ([`WorldModel::set_persistence_pooling`](crate::model::WorldModel::set_persistence_pooling)).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Pooling {
    pub(super) factor: usize,
    /// Position of the factor's own previous value among its parents.
    own: usize,
    /// Positions of the pooled parents.
    over: Vec<usize>,
    /// Per parent position: its size and its stride in the configuration index.
    sizes: Vec<usize>,
    strides: Vec<usize>,
}

impl Pooling {
    pub(super) fn new(
        structure: &Structure,
        n_actions: usize,
        factor: &str,
        over: &str,
    ) -> Result<Pooling, AgentError> {
        let factors = structure.factors();
        let index = |name: &str| {
            factors.iter().position(|f| f.name == name).ok_or_else(|| {
                let names: Vec<&str> = factors.iter().map(|f| f.name.as_str()).collect();
                AgentError::Structure(format!(
                    "persistence pooling names factor `{name}`, not one of {names:?}"
                ))
            })
        };
        let f = index(factor)?;
        let names: Vec<&str> = over.split('+').collect();
        let gs = names
            .iter()
            .map(|n| index(n))
            .collect::<Result<Vec<usize>, AgentError>>()?;
        let parents = &factors[f].parents;
        let own = parents.iter().position(|p| *p == Parent::Prev(f)).ok_or_else(|| {
            AgentError::Structure(format!(
                "persistence pooling: factor `{factor}` does not depend on its own previous value"
            ))
        })?;
        let over = names
            .iter()
            .zip(gs)
            .map(|(name, g)| {
                parents.iter().position(|p| *p == Parent::Next(g)).ok_or_else(|| {
                    AgentError::Structure(format!(
                        "persistence pooling: `{name}` is not a next-time parent of factor `{factor}`"
                    ))
                })
            })
            .collect::<Result<Vec<usize>, AgentError>>()?;
        let sizes = structure.parent_sizes(f);
        // Mixed radix in parent order; an action parent, if any, is the least significant digit.
        let mut strides = vec![0; sizes.len()];
        let mut stride = if factors[f].action_parent { n_actions } else { 1 };
        for k in (0..sizes.len()).rev() {
            strides[k] = stride;
            stride *= sizes[k];
        }
        Ok(Pooling {
            factor: f,
            own,
            over,
            sizes,
            strides,
        })
    }

    /// The CPT counts of the pooled factor (`counts`, rows of `size` values, prior `b0`
    /// per cell) with the persistence rows pooled (see
    /// [`WorldModel::set_persistence_pooling`](crate::model::WorldModel::set_persistence_pooling)); the prior is counted once per row.
    pub(super) fn pooled(&self, counts: &[f64], size: usize, b0: f64) -> Vec<f64> {
        let pool = self;
        let n_cfg = counts.len() / size;
        // Key of a row: its configuration with the pooled parents' values set to 0.
        let value = |cfg: usize, k: usize| (cfg / pool.strides[k]) % pool.sizes[k];
        let key = |cfg: usize| {
            cfg - pool
                .over
                .iter()
                .map(|&k| value(cfg, k) * pool.strides[k])
                .sum::<usize>()
        };
        let mut sums = vec![0.0; counts.len()];
        for cfg in (0..n_cfg).filter(|&c| value(c, pool.own) != 0) {
            for x in 0..size {
                sums[key(cfg) * size + x] += (counts[cfg * size + x] - b0).max(0.0);
            }
        }
        let mut out = counts.to_vec();
        for cfg in (0..n_cfg).filter(|&c| value(c, pool.own) != 0) {
            for x in 0..size {
                out[cfg * size + x] = b0 + sums[key(cfg) * size + x];
            }
        }
        out
    }
}
