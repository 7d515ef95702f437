//! The one trait all methods implement (linfa-style shared trait; docs/ARCHITECTURE.md §1, §5), so the
//! runner never cares whether it drives Q-learning, Bayesian RL or the scaled agent.

/// What a controller decided on one tick, and what it computed to get there.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Decision {
    /// Action index.
    pub action: usize,
    /// Whether this tick ran reasoning (planning); counts toward the inference rate.
    pub reasoned: bool,
    /// Surprise `S_t` in nats, if the method measures it (§II).
    pub surprise: Option<f64>,
    /// Normalised surprise `θ_t` (§IV), if measured.
    pub theta: Option<f64>,
    /// The distribution the action was taken from (π_o, π', or a one-hot greedy policy).
    pub policy: Dist,
    /// `ψ(u)` from planning (§IV), if planning ran and produces it.
    pub psi: Option<Dist>,
    /// Scaling iterations (eq. "gradient_descent_equations"); 0 if none.
    pub scaling_iters: u32,
}

/// How a tick left the episode: going on, ended in a terminal state of the task (goal or
/// collision: nothing follows, a value estimate stops there), or cut off by the tick limit
/// (the state is not terminal: a value estimate bootstraps through it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    /// The episode goes on.
    Continues,
    /// The episode reached a terminal state (goal or collision).
    Terminated,
    /// The episode ran out of ticks in a non-terminal state (time-out).
    Truncated,
}

impl Ending {
    /// From Gymnasium's two flags (`terminated` wins if both are set).
    pub fn from_flags(terminated: bool, truncated: bool) -> Self {
        if terminated {
            Ending::Terminated
        } else if truncated {
            Ending::Truncated
        } else {
            Ending::Continues
        }
    }

    /// Whether the episode is over (terminated or truncated).
    pub fn is_over(self) -> bool {
        self != Ending::Continues
    }

    /// Whether the next state is terminal (no bootstrap through it).
    pub fn is_terminal(self) -> bool {
        self == Ending::Terminated
    }
}

/// A method that acts on observations (docs/ARCHITECTURE.md §5).
pub trait Controller: Send {
    /// Method name, e.g. `"scaled"`.
    fn name(&self) -> &'static str;
    /// Clear beliefs and history; seed any sampling RNG (ChaCha8).
    fn begin_episode(&mut self, seed: u64);
    /// The observation of the coming tick as features (the env's kinematic vector,
    /// docs/ARCHITECTURE.md §3), given just before [`Controller::act`] when the episode's
    /// env observes in that form: for a controller that reads more than the discrete
    /// observation (a policy given from outside, e.g. from Python). The methods of the
    /// paper read the discrete observation alone and ignore it.
    fn see_features(&mut self, _features: &[f32]) {}
    /// Decide the action for observation `obs`.
    fn act(&mut self, obs: usize) -> Decision;
    /// Online evidence after acting: the reward, the next observation, and whether the
    /// tick ended the episode ([`Ending`]).
    fn observe(&mut self, _reward: f64, _next_obs: usize, _ending: Ending) {}
    /// End of episode (the scaled agent learns here, §V).
    fn end_episode(&mut self) {}
}

/// A distribution over actions, as a [`Decision`] carries it: stored inline (no heap
/// allocation) up to [`Dist::INLINE`] actions, on the heap beyond. It reads as a slice
/// (`Deref<Target = [f64]>`), so `d.policy[u]`, `d.policy.iter()` and `&d.policy[..]` work.
#[derive(Clone)]
pub struct Dist(DistRepr);

#[derive(Clone)]
enum DistRepr {
    Inline { len: u8, p: [f64; Dist::INLINE] },
    Heap(Vec<f64>),
}

impl Dist {
    /// Actions stored without allocating.
    pub const INLINE: usize = 8;

    /// A copy of `p`; allocates only beyond [`Dist::INLINE`] entries.
    pub fn from_slice(p: &[f64]) -> Self {
        if p.len() <= Self::INLINE {
            let mut a = [0.0; Self::INLINE];
            a[..p.len()].copy_from_slice(p);
            Dist(DistRepr::Inline {
                len: p.len() as u8,
                p: a,
            })
        } else {
            Dist(DistRepr::Heap(p.to_vec()))
        }
    }

    /// `n` zeros; allocates only beyond [`Dist::INLINE`] entries.
    pub fn zeros(n: usize) -> Self {
        if n <= Self::INLINE {
            Dist(DistRepr::Inline {
                len: n as u8,
                p: [0.0; Self::INLINE],
            })
        } else {
            Dist(DistRepr::Heap(vec![0.0; n]))
        }
    }

    /// The entries, mutable.
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        match &mut self.0 {
            DistRepr::Inline { len, p } => &mut p[..*len as usize],
            DistRepr::Heap(v) => v,
        }
    }

    /// The entries as a new vector.
    pub fn to_vec(&self) -> Vec<f64> {
        self[..].to_vec()
    }
}

impl Default for Dist {
    /// The empty distribution.
    fn default() -> Self {
        Dist::from_slice(&[])
    }
}

impl std::ops::Deref for Dist {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        match &self.0 {
            DistRepr::Inline { len, p } => &p[..*len as usize],
            DistRepr::Heap(v) => v,
        }
    }
}

impl From<Vec<f64>> for Dist {
    fn from(v: Vec<f64>) -> Self {
        Dist::from_slice(&v)
    }
}

impl From<&[f64]> for Dist {
    fn from(v: &[f64]) -> Self {
        Dist::from_slice(v)
    }
}

impl PartialEq for Dist {
    fn eq(&self, other: &Self) -> bool {
        self[..] == other[..]
    }
}

impl std::fmt::Debug for Dist {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self[..].fmt(f)
    }
}

/// One-hot distribution of length `n` at `i`.
pub(crate) fn one_hot(n: usize, i: usize) -> Dist {
    let mut d = Dist::zeros(n);
    if let Some(p) = d.as_mut_slice().get_mut(i) {
        *p = 1.0;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dist_reads_as_its_slice_inline_or_not() {
        let small = Dist::from_slice(&[0.25, 0.75]);
        assert_eq!(&small[..], &[0.25, 0.75]);
        assert_eq!(small, Dist::from(vec![0.25, 0.75]));
        assert_ne!(small, Dist::from_slice(&[0.25, 0.75, 0.0]));
        let big: Vec<f64> = (0..11).map(|i| i as f64).collect();
        assert_eq!(Dist::from_slice(&big).to_vec(), big);
        assert_eq!(&one_hot(3, 1)[..], &[0.0, 1.0, 0.0]);
        assert_eq!(&one_hot(12, 11)[11..], &[1.0]);
        assert!(Dist::default().is_empty());
        assert_eq!(format!("{:?}", small), "[0.25, 0.75]");
    }
}
