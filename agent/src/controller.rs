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
    pub policy: Vec<f64>,
    /// `ψ(u)` from planning (§IV), if planning ran and produces it.
    pub psi: Option<Vec<f64>>,
    /// Scaling iterations (eq. "gradient_descent_equations"); 0 if none.
    pub scaling_iters: u32,
}

/// A method that acts on observations (docs/ARCHITECTURE.md §5).
pub trait Controller: Send {
    /// Method name, e.g. `"scaled"`.
    fn name(&self) -> &'static str;
    /// Clear beliefs and history; seed any sampling RNG (ChaCha8).
    fn begin_episode(&mut self, seed: u64);
    /// Decide the action for observation `obs`.
    fn act(&mut self, obs: usize) -> Decision;
    /// Online evidence after acting (reward, next observation, terminal flag).
    fn observe(&mut self, _reward: f64, _next_obs: usize, _done: bool) {}
    /// End of episode (the scaled agent learns here, §V).
    fn end_episode(&mut self) {}
}

/// One-hot distribution of length `n` at `i`.
pub(crate) fn one_hot(n: usize, i: usize) -> Vec<f64> {
    let mut v = vec![0.0; n];
    if i < n {
        v[i] = 1.0;
    }
    v
}
