//! The traffic light over time: the phase a map's cycle ([`Light`]) shows at a given
//! time. The phases themselves ([`LightPhase`]) are map data, defined in [`crate::map`].

use crate::map::Light;
pub use crate::map::LightPhase;

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
