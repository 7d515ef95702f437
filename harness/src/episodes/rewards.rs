//! Rewards (§VI): the per-state reward R(s) behind the agent's preferences
//! C = log_softmax(R / tau_c) (§IV; docs/ARCHITECTURE.md §4.3), the episode-ending states
//! of its planning model, and a one-line description of a map's reward. The per-tick
//! reward the env pays is [`unforeseen_env::RewardTerms`].

use unforeseen_agent::maths::log_softmax;
use unforeseen_agent::model::{CrashModel, TransitionCost};
use unforeseen_discretizer::Discretizer;
use unforeseen_sim::{Action, Map};

/// One line naming a map's reward, for tables: its four numbers (and the red-light rule's,
/// where the map has it), and whether it pays
/// rapid approach (a tick at the car's top speed nets at most 0, so every slower tick
/// costs, §VI) or progress per metre (a tick at top speed earns, so waiting costs little).
pub fn describe(map: &Map) -> String {
    let r = &map.reward;
    let full_speed_tick = r.progress_per_metre * map.vehicle.max_speed * map.episode.decision_dt - r.step_cost;
    let kind = if full_speed_tick <= 1e-9 {
        "rapid approach"
    } else {
        "per metre"
    };
    let rule = if r.red_light != 0.0 {
        format!(", entering on red {:+}", r.red_light)
    } else {
        String::new()
    };
    format!(
        "{kind}: {}/m of progress, -{} per tick, goal {:+}, crash {:+}{rule}",
        r.progress_per_metre, r.step_cost, r.goal, r.crash
    )
}

/// Distance bins that overlap the crosswalk (the paper's "intersection at d = 1").
pub fn crosswalk_bins(map: &Map, disc: &Discretizer) -> Vec<usize> {
    let (a, b) = map.crosswalk_distance_to_goal();
    let (lo, hi) = (disc.distance_bin(a.min(b)), disc.distance_bin(a.max(b)));
    (lo..=hi).collect()
}

/// The states that end an episode in the agent's planning model: arrival (d = 0) and
/// the crash-risk states (see [`state_rewards`]). They are absorbing when planning.
pub fn terminal_states(map: &Map, disc: &Discretizer) -> Vec<usize> {
    let risky = crosswalk_bins(map, disc);
    (0..disc.n_states())
        .filter(|&s| {
            let st = disc.decode(s);
            st.d == 0 || (st.p == 1 && st.v > 0 && risky.contains(&st.d))
        })
        .collect()
}

/// Distance bins that lie wholly at or past the crosswalk's near edge and before the goal:
/// a car observed in one of them has entered the crosswalk (its front crossed the near
/// edge). Empty unless a distance edge lies at or before the near edge (e.g.
/// `Crosswalk(lead: 0.0, ...)`, the edges `[0, 26, 60]` for the default crosswalk: d = 1
/// is (0, 26] m, from the near edge on). docs/ARCHITECTURE.md §4.3.
pub fn entered_bins(map: &Map, disc: &Discretizer) -> Vec<usize> {
    let near = map.crosswalk_distance_to_goal().0;
    let edges = disc.distance_edges();
    // Bin d >= 1 holds distances (edges[d - 1], edges[d]]; the last bin is unbounded.
    (1..disc.factor_sizes()[0])
        .filter(|&d| edges.get(d).is_some_and(|&hi| hi <= near))
        .collect()
}

/// R(s) for every joint state: the goal reward where the car has arrived (d = 0), the
/// crash penalty in crash-risk states (a pedestrian on the crosswalk while the car is
/// moving in a crosswalk bin), and zero elsewhere. The red-light rule is not a state
/// preference but one over transitions ([`red_light_cost`]).
pub fn state_rewards(map: &Map, disc: &Discretizer) -> Vec<f64> {
    let risky = crosswalk_bins(map, disc);
    (0..disc.n_states())
        .map(|s| {
            let st = disc.decode(s);
            if st.d == 0 {
                map.reward.goal
            } else if st.p == 1 && st.v > 0 && risky.contains(&st.d) {
                map.reward.crash
            } else {
                0.0
            }
        })
        .collect()
}

/// The crosswalk's crash model for planning (beyond the paper; docs/ARCHITECTURE.md §4.3):
/// from a state with a pedestrian on the crosswalk and the car in a crosswalk bin, a tick
/// of action `u` ends in a collision with probability
///
/// ```text
/// hazard[u][s] = min(1, distance the car covers in the tick / (v_max Δt))
/// ```
///
/// the distance from the middle of the state's speed bin (the top bin's middle is
/// between its edge and the top speed) under `u`: maintain `v Δt`; speed up to
/// `min(v_max, v + a Δt)`, `Δt (v + v') / 2`; slow down, `Δt (v + v') / 2` with
/// `v' = v - b Δt`, or `v² / 2b` when the car stops within the tick. A car at top speed
/// crashes for sure (the paper's crash-risk state); a slower one, or one that brakes,
/// less. A crashed episode is worth the crash penalty and the goal it forfeits,
/// `R = crash - goal`, on the scale of `C = log_softmax(R / τ_c)`; the hazard states
/// themselves are worth what a state without reward is.
pub fn crash_model(map: &Map, disc: &Discretizer, tau_c: f64) -> CrashModel {
    let zone = crosswalk_bins(map, disc);
    let v = &map.vehicle;
    let dt = map.episode.decision_dt;
    let edges = &map.bins.speed_edges;
    let middle = |bin: usize| -> f64 {
        let lo = if bin == 0 { 0.0 } else { edges[bin - 1] };
        let hi = edges.get(bin).copied().unwrap_or(v.max_speed.max(lo));
        (lo + hi) / 2.0
    };
    let distance = |speed: f64, u: Action| -> f64 {
        match u {
            Action::SpeedUp => (speed + (speed + v.max_accel * dt).min(v.max_speed.max(speed))) / 2.0 * dt,
            Action::SlowDown if speed <= v.max_brake * dt => speed * speed / (2.0 * v.max_brake),
            Action::SlowDown => (2.0 * speed - v.max_brake * dt) / 2.0 * dt,
            Action::Maintain => speed * dt,
        }
    };
    let full = v.max_speed * dt;
    let hazard = Action::ALL
        .into_iter()
        .map(|u| {
            (0..disc.n_states())
                .map(|s| {
                    let st = disc.decode(s);
                    if st.p == 1 && zone.contains(&st.d) {
                        (distance(middle(st.v), u) / full).clamp(0.0, 1.0)
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    // C = R / τ_c - ln Z over the states: the same ln Z places the two new values.
    let scaled: Vec<f64> = state_rewards(map, disc).iter().map(|r| r / tau_c).collect();
    let ln_z = scaled[0] - log_softmax(&scaled)[0];
    CrashModel {
        hazard,
        crashed: (map.reward.crash - map.reward.goal) / tau_c - ln_z,
        neutral: -ln_z,
    }
}

/// The red-light rule as the planner's preference over transitions (docs/ARCHITECTURE.md
/// §4.3): a step from a state before the crosswalk's near edge on L = 0 (red or amber,
/// not arrived) to a state in an [`entered_bins`] bin on L = 0 costs `-red_light / tau_c`
/// nats of expected free energy, the scale of `C = log_softmax(R / tau_c)`. `None` on a
/// map without the rule, or whose bins cannot tell the approach from the crosswalk
/// (no [`entered_bins`]; the default bins).
pub fn red_light_cost(map: &Map, disc: &Discretizer, tau_c: f64) -> Option<TransitionCost> {
    if map.reward.red_light == 0.0 {
        return None;
    }
    let entered = entered_bins(map, disc);
    if entered.is_empty() {
        return None;
    }
    let states: Vec<_> = (0..disc.n_states()).map(|s| disc.decode(s)).collect();
    Some(TransitionCost {
        from: states
            .iter()
            .map(|st| st.d > 0 && st.l == 0 && !entered.contains(&st.d))
            .collect(),
        to: states.iter().map(|st| st.l == 0 && entered.contains(&st.d)).collect(),
        cost: -map.reward.red_light / tau_c,
    })
}

#[cfg(test)]
mod describe_tests {
    use super::describe;

    #[test]
    fn the_default_reward_is_named_rapid_approach_and_a_cheap_tick_per_metre() {
        let mut map = unforeseen_sim::embedded::load("intersection").unwrap();
        assert_eq!(
            describe(&map),
            "rapid approach: 0.5/m of progress, -4.5 per tick, goal +50, crash -25"
        );
        map.reward.red_light = -100.0;
        assert!(
            describe(&map).ends_with("crash -25, entering on red -100"),
            "{}",
            describe(&map)
        );
        map.reward.step_cost = 1.0;
        assert!(describe(&map).starts_with("per metre: "), "{}", describe(&map));
    }
}
