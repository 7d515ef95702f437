//! The safe hand-back (beyond the paper; docs/ARCHITECTURE.md §4.10): control goes back to
//! the habit `π_o` only where the world model does not predict that the habit crashes.
//!
//! The paper hands control back to the habit whenever `θ_t <= ε` (§II, §IV). With test-time
//! learning (§V), a situation can turn familiar (the gate's table learns that a pedestrian
//! at the crosswalk on green is common; the trigger's baseline learns where reasoning
//! endorsed the habit) in states where the habit was never taught what to do: the gate's
//! table is kept per `(L, d)` and carries across speeds, the habit is kept per joint state.
//! A hand-back that learning made possible is therefore checked first: the agent rolls
//! the car forward through the learned model for `H` ticks, holding one action `u`,
//!
//! ```text
//! x_1 = B[u] q_t                 (the root model: the learned B)
//! x_{k+1} = B_plan[u] x_k         (the planning model: episode ends absorbing)
//! risk(u) = Σ_{s harmful} x_H(s)
//! ```
//!
//! with the harmful states the episode-ending states the preferences rank below every
//! other state (the crash-risk states: a pedestrian on the crosswalk while the car moves in
//! a crosswalk bin). Since harmful states absorb, `risk(u)` is the probability of entering
//! one within `H` ticks of holding `u`. When the agent plans with a crash model
//! (`crash_model = hazard`, docs/ARCHITECTURE.md §4.3) its hazard states are not harmful
//! states, and `risk(u)` is the mass that crashes within `H` ticks instead. If holding the
//! habit's action `a_o` (the mode of
//! `π_o(·|q_t)`) is riskier than holding the safest action by more than `ρ`,
//! `risk(a_o) - min_u risk(u) > ρ`, the agent reasons instead of handing back.
//!
//! Two choices, both measured (EXPERIMENTS.md, "The safe hand-back"): the check is
//! *relative*, because some risk can no longer be avoided (a car at speed close to a
//! pedestrian), and where the habit already takes the safest action, handing the tick to
//! the planner buys nothing: with an absolute bound the planner, indifferent between
//! maintaining and braking at (d = 2, v = 2) with a runner ahead, maintained and crashed
//! where the habit would have braked (late_fast). And the action is *held*, not followed
//! by the habit: the habit's actions in the states after the first are what the check
//! cannot trust (at (d = 2, v = 3) with a walker ahead, "brake, then the habit" sped up
//! again and looked as risky as speeding up, so the check let a habit that sped up
//! through (crowd_slow)). The cost is `U H` predictions on the ticks that are checked,
//! fewer than one reasoning tick's (VMP plus `U + U² + … + U^H` predictions).
//!
//! Which ticks are checked: those where test-time learning changed the trigger's verdict.
//! A hand-back the trained agent would not have made (the trained gate's trigger,
//! [`crate::gate::StateGate::trained_surprise`], exceeds `ε` while the learned one no
//! longer does) goes to the habit only if the check passes. A reasoning tick the trained
//! agent would not have taken (the learned trigger exceeds `ε`, the trained one does not:
//! learning that pedestrians are common makes an empty road read as surprising) is
//! declined by default ([`crate::params::HandBackRule::DeclineLearned`]): the habit acts,
//! as the trained agent's would, so the agent reasons only where its trained trigger
//! fires. Such reasoning did harm on the crowd map for the shared test agent (600
//! training episodes; 11 of 40 continual episodes lost when it is taken): the planner
//! slowed a car on an empty road and brought it to the crosswalk in front of the next
//! walker. With [`crate::params::HandBackRule::RiskChecked`] the check decides this case
//! too, and the tick is taken where it finds the habit at risk (on red, where the habit
//! would run the light): on the rule-free maps that changes no episode's success for the
//! agents of seeds 1..20, on the rule-aware maps it saves cars the habit would take
//! through a red (EXPERIMENTS.md, "The safe hand-back"). Where learning changed nothing, the habit acts
//! as training left it, as in the paper; so the zero-shot agent, which has learned
//! nothing, decides exactly as before.

use crate::model::{GenerativeModel, WorldModel};

/// The crash-risk check of the habit under the learned model (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct HandBack {
    /// The harmful states (episode-ending states the preferences rank lowest).
    harmful: Vec<usize>,
    x: Vec<f64>,
    y: Vec<f64>,
    masked: Vec<f64>,
    part: Vec<f64>,
    scratch: Vec<f64>,
}

impl HandBack {
    /// The check for `model`: its harmful states are the terminal states
    /// ([`WorldModel::terminal_states`]) whose expected preference `Σ_o A[o, s] C[o]` is below
    /// that of every state that does not end the episode. A model without terminal states
    /// has none, and its habit is never found at risk.
    pub fn new(model: &WorldModel) -> HandBack {
        // The planning model's preferences: with a crash model its hazard states are
        // neither terminal nor crashes; the crash is a transition (`crash_risk`).
        let gm = model.planning_generative();
        let n = gm.n_states();
        let preference = |s: usize| -> f64 { (0..gm.n_obs()).map(|o| gm.a[(o, s)] * gm.c[o]).sum() };
        let hazard = gm.crash.as_ref().map(|c| c.hazard_states()).unwrap_or_default();
        let terminal: Vec<usize> = model
            .terminal_states()
            .iter()
            .copied()
            .filter(|s| !hazard.contains(s))
            .collect();
        let floor = (0..n)
            .filter(|s| !terminal.contains(s))
            .map(preference)
            .fold(f64::INFINITY, f64::min);
        let harmful = terminal.iter().copied().filter(|&s| preference(s) < floor).collect();
        HandBack {
            harmful,
            x: vec![0.0; n],
            y: vec![0.0; n],
            masked: vec![0.0; n],
            part: vec![0.0; n],
            scratch: Vec::new(),
        }
    }

    /// The harmful states, in increasing order of index.
    pub fn harmful(&self) -> &[usize] {
        &self.harmful
    }

    /// The probability that the car enters a harmful state within `horizon` ticks of belief
    /// `q`: its first action `first` goes through `root`, each later one, `then[s]` in state
    /// `s`, through `plan` (whose harmful states absorb). The check (module docs) holds
    /// one action: `then[s] = first` for every `s`.
    pub fn crash_risk(
        &mut self,
        root: &GenerativeModel,
        plan: &GenerativeModel,
        q: &[f64],
        first: usize,
        then: &[usize],
        horizon: usize,
    ) -> f64 {
        if (self.harmful.is_empty() && plan.crash.is_none()) || horizon == 0 {
            return 0.0;
        }
        // With a crash model, the part of the belief that crashes in a tick leaves it.
        let mut crashed = 0.0;
        match &plan.crash {
            Some(cm) => {
                crashed += cm.split(first, q, &mut self.masked);
                root.transition_into(first, &self.masked, &mut self.x, &mut self.scratch);
            }
            None => root.transition_into(first, q, &mut self.x, &mut self.scratch),
        }
        for _ in 1..horizon {
            self.y.fill(0.0);
            for u in 0..plan.n_actions() {
                let mut any = false;
                for (s, m) in self.masked.iter_mut().enumerate() {
                    *m = if then[s] == u && self.x[s] != 0.0 {
                        any = true;
                        let hit = plan.crash.as_ref().map_or(0.0, |cm| self.x[s] * cm.hazard[u][s]);
                        crashed += hit;
                        self.x[s] - hit
                    } else {
                        0.0
                    };
                }
                if any {
                    plan.transition_into(u, &self.masked, &mut self.part, &mut self.scratch);
                    self.y.iter_mut().zip(&self.part).for_each(|(y, p)| *y += p);
                }
            }
            std::mem::swap(&mut self.x, &mut self.y);
        }
        crashed + self.harmful.iter().map(|&s| self.x[s]).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::CrashModel;
    use crate::params::ModelPriors;
    use crate::structure::Structure;

    /// The paper's state space with one crash-risk state (d = 1, v = 1, green, pedestrian)
    /// and one arrival state as the terminal states, with the map's rewards as preferences.
    fn toy() -> WorldModel {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
        // States (d, v, L, p): the harmful one is (1, 1, 1, 1); a terminal goal (0, 0, 1, 0).
        let harm = st.encode(&[1, 1, 1, 1]);
        let goal = st.encode(&[0, 0, 1, 0]);
        w.set_terminal_states(&[harm, goal]).unwrap();
        let mut rewards = vec![0.0; 64];
        rewards[harm] = -25.0;
        rewards[goal] = 50.0;
        w.set_preferences(&rewards, 1.0).unwrap();
        w
    }

    #[test]
    fn harmful_states_are_the_terminal_states_ranked_lowest() {
        let w = toy();
        let st = w.structure().clone();
        assert_eq!(HandBack::new(&w).harmful(), &[st.encode(&[1, 1, 1, 1])]);
        // No terminal states: nothing is harmful and the risk is 0.
        let plain = WorldModel::new(st, 3, &ModelPriors::default()).unwrap();
        let mut hb = HandBack::new(&plain);
        assert!(hb.harmful().is_empty());
        let q = vec![1.0 / 64.0; 64];
        let gm = plain.generative();
        assert_eq!(hb.crash_risk(gm, gm, &q, 0, &[0; 64], 3), 0.0);
    }

    /// With a crash model the hazard state is no longer harmful (it is not a crash) and
    /// the risk is the mass that crashes: from the hazard state, `h` in the first tick,
    /// then `h` of what stays there.
    #[test]
    fn the_crash_model_risk_is_the_crashed_mass() {
        let mut w = toy();
        let st = w.structure().clone();
        let harm = st.encode(&[1, 1, 1, 1]);
        let mut hazard = vec![vec![0.0; 64]; 3];
        for h in &mut hazard {
            h[harm] = 0.25;
        }
        let crash = CrashModel {
            hazard,
            crashed: -100.0,
            neutral: -50.0,
        };
        w.set_crash_model(Some(crash)).unwrap();
        w.plan_with_crash_model(true);
        let mut hb = HandBack::new(&w);
        assert!(hb.harmful().is_empty());
        let mut q = vec![0.0; 64];
        q[harm] = 1.0;
        let (root, plan) = (w.generative(), w.planning_generative());
        let one = hb.crash_risk(root, plan, &q, 0, &[0; 64], 1);
        assert!((one - 0.25).abs() < 1e-12, "{one}");
        // Two ticks: 0.25, then 0.25 of the 0.75 that survived and is still (by B) there.
        let root_stay = root.b[0][(harm, harm)];
        let two = hb.crash_risk(root, plan, &q, 0, &[0; 64], 2);
        assert!((two - (0.25 + 0.25 * 0.75 * root_stay)).abs() < 1e-12, "{two}");
        // Without planning with it, the paper's harmful state is back.
        w.plan_with_crash_model(false);
        assert_eq!(HandBack::new(&w).harmful(), &[harm]);
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // the oracle spells the sums out index by index
    fn risk_by_brute_force_enumeration() {
        // The rollout equals the sum over every path of the habit through the dense B.
        let mut w = toy();
        let st = w.structure().clone();
        // Some data so that B is not uniform: speeding up at d = 2 often reaches d = 1.
        for k in 0..30 {
            let (s, u) = (st.encode(&[2, k % 4, 1, k % 2]), k % 3);
            let s2 = st.encode(&[1 + usize::from(k % 3 == 0), (k + 1) % 4, 1, (k / 2) % 2]);
            w.observe_transition(s, u, s2);
        }
        w.materialize();
        let mut hb = HandBack::new(&w);
        let habit: Vec<usize> = (0..64).map(|s| (s * 7) % 3).collect();
        let mut q = vec![0.0; 64];
        q[st.encode(&[2, 3, 1, 1])] = 0.7;
        q[st.encode(&[2, 2, 1, 1])] = 0.3;
        let (root, plan) = (w.generative(), w.planning_generative());
        for horizon in 1..=3 {
            let fast = hb.crash_risk(root, plan, &q, 1, &habit, horizon);
            // Brute force: distribution over paths.
            let mut x = vec![0.0; 64];
            for s in 0..64 {
                for s2 in 0..64 {
                    x[s2] += root.b[1][(s2, s)] * q[s];
                }
            }
            for _ in 1..horizon {
                let mut y = vec![0.0; 64];
                for s in 0..64 {
                    for s2 in 0..64 {
                        y[s2] += plan.b[habit[s]][(s2, s)] * x[s];
                    }
                }
                x = y;
            }
            let slow: f64 = hb.harmful().iter().map(|&s| x[s]).sum();
            assert!((fast - slow).abs() < 1e-12, "H = {horizon}: {fast} vs {slow}");
            assert!((0.0..=1.0 + 1e-12).contains(&fast));
        }
        // Absorbing harm: the risk never falls as the horizon grows.
        let risks: Vec<f64> = (1..=4).map(|h| hb.crash_risk(root, plan, &q, 1, &habit, h)).collect();
        assert!(risks.windows(2).all(|r| r[1] >= r[0] - 1e-12), "{risks:?}");
    }
}
