//! A world to act in: a generative process in pymdp's layout (`A`, `B`, `D` with their
//! dependencies; a [`Model`] whose `C`, `E`, `pA`, `pB` are unused), sampled state by
//! state like pymdp's `PymdpEnv` (`reset`: `s ~ D`, `o ~ A[:, s]`; `step`: `s' ~ B[..., u]`).

use super::error::ModelError;
use super::model::Model;
use rand::RngExt;

/// The true process and its current state (one index per factor).
#[derive(Debug, Clone)]
pub struct Process {
    world: Model,
    state: Vec<usize>,
}

/// An index drawn from the categorical distribution `p` (its cumulative sum against one
/// uniform draw; the last index if rounding leaves the sum below the draw).
pub fn sample(p: impl Iterator<Item = f64>, rng: &mut impl RngExt) -> usize {
    let r: f64 = rng.random();
    let mut acc = 0.0;
    let mut last = 0;
    for (i, pi) in p.enumerate() {
        acc += pi;
        last = i;
        if r < acc {
            return i;
        }
    }
    last
}

/// Entry `t[..., idx]` of the column at the multi-index `idx` over axes 1.. (axis 0 free).
fn column<'a>(t: &'a super::tensor::Tensor, idx: &[usize]) -> impl Iterator<Item = f64> + 'a {
    let strides = t.strides();
    let base: usize = idx.iter().zip(&strides[1..]).map(|(i, s)| i * s).sum();
    (0..t.shape[0]).map(move |o| t.data[base + o * strides[0]])
}

impl Process {
    /// A process on `world`, before its first reset.
    pub fn new(world: Model) -> Process {
        let state = vec![0; world.num_factors()];
        Process { world, state }
    }

    /// The world's arrays.
    pub fn world(&self) -> &Model {
        &self.world
    }

    /// The current hidden state.
    pub fn state(&self) -> &[usize] {
        &self.state
    }

    fn observe(&self, rng: &mut impl RngExt) -> Vec<usize> {
        self.world
            .a
            .iter()
            .zip(&self.world.a_deps)
            .map(|(a, deps)| {
                let idx: Vec<usize> = deps.iter().map(|&f| self.state[f]).collect();
                sample(column(a, &idx), rng)
            })
            .collect()
    }

    /// Draw the first state from `D` and return its observation.
    pub fn reset(&mut self, rng: &mut impl RngExt) -> Vec<usize> {
        self.state = self.world.d.iter().map(|d| sample(d.iter().copied(), rng)).collect();
        self.observe(rng)
    }

    /// Take `action` (one per factor) and return the next observation.
    pub fn step(&mut self, action: &[usize], rng: &mut impl RngExt) -> Result<Vec<usize>, ModelError> {
        self.world.check_action(action)?;
        let next = self
            .world
            .b
            .iter()
            .zip(&self.world.b_deps)
            .enumerate()
            .map(|(f, (b, deps))| {
                let mut idx: Vec<usize> = deps.iter().map(|&d| self.state[d]).collect();
                idx.push(action[f]);
                sample(column(b, &idx), rng)
            })
            .collect();
        self.state = next;
        Ok(self.observe(rng))
    }
}
