//! Bounds on what the agent crate builds, so that no input (a damaged agent file, a map
//! with huge bins) can ask for more memory or time than a run can give. Every learner
//! checks them when it is built or read, and the map validator applies the same state
//! bound to a map's bins.

/// Most joint states a world model, a Q-table or a Bayesian-RL posterior may have.
///
/// Reason: the world model and Bayesian RL keep dense `N x N` matrices per action (`B`,
/// `ln B`, their planning copies, `A`, the Dirichlet counts, the posterior-mean MDP), about
/// [`BYTES_PER_STATE_SQUARED`] bytes times `N²` for one trained agent with three actions:
/// 1024 states take about 400 MB, and each parallel episode clones the scaled agent's part.
pub const MAX_STATES: usize = 1024;

/// Most actions a learner may have (the intersection has three).
pub const MAX_ACTIONS: usize = 16;

/// Most factors a structure may have (the paper's has four).
pub const MAX_FACTORS: usize = 16;

/// Most policies the planner may enumerate, `n_actions ^ horizon` (the paper's 3 actions
/// at the largest horizon, 8, give 6561): the expected-free-energy tree keeps two numbers
/// per policy and visits every node on each reasoning tick.
pub const MAX_POLICIES: usize = 65_536;

/// `n_actions ^ horizon` if it is at most [`MAX_POLICIES`].
pub fn policies(n_actions: usize, horizon: usize) -> Option<usize> {
    u32::try_from(horizon)
        .ok()
        .and_then(|h| n_actions.checked_pow(h))
        .filter(|&p| p <= MAX_POLICIES)
}

/// Approximate memory of one trained agent (world model, flat and factored Bayesian RL,
/// with three actions) per squared joint state, in bytes: 46 dense `N x N` matrices of f64.
pub const BYTES_PER_STATE_SQUARED: usize = 46 * 8;

/// Largest magnitude of a stored value (a Q-value, a reward sum, a log preference, a
/// count): far beyond anything training produces (6000 episodes add about 10⁵ counts to
/// a cell, rewards are tens per tick), and small enough that planning's sums and
/// products never overflow to infinity.
pub const MAX_VALUE: f64 = 1e15;
