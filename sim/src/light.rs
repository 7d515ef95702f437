//! The traffic light: a fixed cycle of phases with an offset.

use serde::{Deserialize, Serialize};

use crate::map::Light;

/// The colour the light shows. The discretizer maps amber to red.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum LightPhase {
    /// Go.
    Green,
    /// About to turn red (counts as red for the agent).
    Amber,
    /// Stop; pedestrians may cross.
    Red,
}

impl LightPhase {
    /// True for green only.
    pub fn is_green(self) -> bool {
        self == LightPhase::Green
    }
}

impl std::fmt::Display for LightPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LightPhase::Green => "green",
            LightPhase::Amber => "amber",
            LightPhase::Red => "red",
        })
    }
}

/// Phase shown at episode time `t` (s) with cycle offset `offset` (s), and the
/// seconds left in that phase. The map must have a non-empty cycle of positive
/// durations (checked by validation).
pub fn light_at(light: &Light, offset: f64, t: f64) -> (LightPhase, f64) {
    let total = light.cycle_length();
    if light.cycle.is_empty() || !(total > 0.0 && total.is_finite()) {
        // Only an unvalidated map gets here: treat it as a light stuck on green.
        return (LightPhase::Green, f64::INFINITY);
    }
    let mut pos = (offset + t).rem_euclid(total);
    for p in &light.cycle {
        if pos < p.duration {
            return (p.phase, p.duration - pos);
        }
        pos -= p.duration;
    }
    // Rounding can leave `pos` a hair past the last phase: wrap to the first.
    let first = light.cycle[0];
    (first.phase, first.duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_cycle_phases() {
        let l = Light::default();
        assert_eq!(light_at(&l, 0.0, 0.0), (LightPhase::Green, 12.0));
        assert_eq!(light_at(&l, 0.0, 12.5).0, LightPhase::Amber);
        assert_eq!(light_at(&l, 0.0, 14.0), (LightPhase::Red, 10.0));
        assert_eq!(light_at(&l, 0.0, 24.0).0, LightPhase::Green);
        assert_eq!(light_at(&l, 14.0, 0.0).0, LightPhase::Red);
        assert_eq!(light_at(&l, -1.0, 0.0).0, LightPhase::Red);
    }
}
