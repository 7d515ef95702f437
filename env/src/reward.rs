//! The reward of one decision tick (§VI: "rapid goal approach with a crash penalty"),
//! term by term, from the map's `reward` section (maps/README.md).

use unforeseen_sim::{Map, StepOutcome};

/// The terms of one tick's reward; [`RewardTerms::total`] is the reward paid.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct RewardTerms {
    /// `progress_per_metre` × metres the car's front advanced.
    pub progress: f64,
    /// `-step_cost`, paid every tick.
    pub time: f64,
    /// `goal` on the tick the car arrives, else 0.
    pub goal: f64,
    /// `crash` on the tick the car hits a pedestrian, else 0.
    pub crash: f64,
    /// `red_light` on the tick the car's front enters the crosswalk on red, else 0
    /// (maps/README.md: the traffic-rule term; 0 on maps without it).
    #[serde(default)]
    pub red_light: f64,
}

impl RewardTerms {
    /// The terms of the tick that ended in `outcome` on `map`.
    pub fn of(map: &Map, outcome: &StepOutcome) -> Self {
        let r = &map.reward;
        Self {
            progress: r.progress_per_metre * outcome.progress,
            time: -r.step_cost,
            goal: if outcome.goal { r.goal } else { 0.0 },
            crash: if outcome.collision { r.crash } else { 0.0 },
            red_light: if outcome.red_light { r.red_light } else { 0.0 },
        }
    }

    /// The reward: `progress + time + goal + crash + red_light`, summed in that order (the
    /// last term is +0 on maps without the rule, and `x + 0.0` is `x` bit for bit for every
    /// `x` but -0.0, which the other terms never sum to: rewards on such maps are the
    /// same bits as before the term existed).
    pub fn total(&self) -> f64 {
        self.progress + self.time + self.goal + self.crash + self.red_light
    }
}
