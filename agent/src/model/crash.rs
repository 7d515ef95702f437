//! The crosswalk's crash model (beyond the paper; docs/ARCHITECTURE.md §4.3): the
//! probability that a tick ends in a collision, per action and state, and the check of a
//! stored one.

use crate::error::FieldError;
use crate::maths::ln;
use crate::stored_values;
use serde::{Deserialize, Serialize};

/// The crosswalk's crash model (beyond the paper; docs/ARCHITECTURE.md §4.3): the
/// probability that one tick ends in a collision, per action and state, and what a crashed
/// episode is worth to the planner.
///
/// The paper's planner treats a pedestrian on the crosswalk while the car moves in the
/// crosswalk's distance bin as a crash, whatever the car does, so braking there earns
/// nothing and dashing to the goal looks like the shortest way out. With this model the
/// crash happens on a transition: a tick from a state with `hazard[u][s] > 0` ends in a
/// collision with that probability, which grows with the distance the car covers in the
/// tick under `u`; the crashed mass leaves the drive (it can reach nothing else) and is
/// worth `crashed` nats of preference for the rest of the horizon.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrashModel {
    /// Per action, per state: the probability in [0, 1] that a tick ends in a collision.
    pub hazard: Vec<Vec<f64>>,
    /// The log preference of a crashed episode, on the scale of `C` (nats).
    pub crashed: f64,
    /// The log preference planning gives the hazard states themselves (where the paper's
    /// model has its crash preference): that of a state with no reward, on `C`'s scale.
    pub neutral: f64,
}

impl CrashModel {
    /// States with a hazard under some action.
    pub fn hazard_states(&self) -> Vec<usize> {
        let n = self.hazard.first().map_or(0, Vec::len);
        (0..n).filter(|&s| self.hazard.iter().any(|h| h[s] > 0.0)).collect()
    }

    /// The mass of belief `x` that crashes in one tick of `u`: `Σ_s x[s] hazard[u][s]`,
    /// and `survive = x ⊙ (1 - hazard[u])`.
    pub fn split(&self, u: usize, x: &[f64], survive: &mut [f64]) -> f64 {
        let mut crashed = 0.0;
        for ((out, xs), h) in survive.iter_mut().zip(x).zip(&self.hazard[u]) {
            let hit = xs * h;
            crashed += hit;
            *out = xs - hit;
        }
        crashed
    }

    /// The risk term of a crashed mass `m`, `m (ln m - crashed)`: the crashed episode as
    /// one more outcome of the step's KL risk (Prop. 1).
    pub fn risk(&self, m: f64) -> f64 {
        if m > 0.0 { m * (ln(m) - self.crashed) } else { 0.0 }
    }
}

/// A crash model fits `n` states and `n_actions` actions, with probabilities in [0, 1] and
/// finite preferences.
pub(super) fn check_crash(c: &CrashModel, n: usize, n_actions: usize) -> Result<(), FieldError> {
    stored_values::len("crash.hazard", c.hazard.len(), n_actions, "one row per action")?;
    for (u, h) in c.hazard.iter().enumerate() {
        stored_values::len(&format!("crash.hazard[{u}]"), h.len(), n, "one probability per state")?;
        if let Some(s) = h.iter().position(|p| !(0.0..=1.0).contains(p)) {
            return Err(FieldError::new(
                format!("crash.hazard[{u}][{s}]"),
                format!("{} is not a probability in [0, 1]", h[s]),
            ));
        }
    }
    for (name, v) in [("crash.crashed", c.crashed), ("crash.neutral", c.neutral)] {
        if !v.is_finite() {
            return Err(FieldError::new(name, format!("{v} is not finite")));
        }
    }
    Ok(())
}
