//! The tie-break between actions the world model cannot tell apart (docs/ARCHITECTURE.md
//! §4.9): in the top speed bin "maintain" and "speed up" predict the same next state, the
//! crash model still tells them apart, and the agent maintains where the habit speeds up.

use unforeseen_agent::controller::Controller;
use unforeseen_agent::model::{CrashModel, WorldModel};
use unforeseen_agent::params::{CompetenceCheck, ModelPriors, QParams, ScaledParams, TieBreak};
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_agent::structure::Structure;

const MAINTAIN: usize = 0;
const SPEED_UP: usize = 1;
const SLOW_DOWN: usize = 2;

/// States `(d, v, L, p)`: from the approach at top speed, maintain and speed up both reach
/// the crosswalk bin at top speed, slow down stays in the approach one bin slower; at the
/// crosswalk a pedestrian sometimes appears, and a tick there crashes with a probability
/// that grows with the action's speed. The habit prefers speeding up.
fn setup() -> (Structure, WorldModel, QLearning) {
    let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
    let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
    let approach = st.encode(&[2, 3, 1, 0]);
    let crosswalk = st.encode(&[1, 3, 1, 0]);
    for _ in 0..30 {
        w.observe_transition(approach, MAINTAIN, crosswalk);
        w.observe_transition(approach, SPEED_UP, crosswalk);
        w.observe_transition(approach, SLOW_DOWN, st.encode(&[2, 2, 1, 0]));
        for u in [MAINTAIN, SPEED_UP] {
            w.observe_transition(crosswalk, u, st.encode(&[0, 3, 1, 0]));
            w.observe_transition(crosswalk, u, st.encode(&[1, 3, 1, 1]));
        }
    }
    w.materialize();
    let hazard = [0.6, 0.9, 0.3]
        .iter()
        .map(|h| {
            (0..64)
                .map(|s| {
                    let x = st.decode(s);
                    if x[0] == 1 && x[1] > 0 && x[3] == 1 { *h } else { 0.0 }
                })
                .collect()
        })
        .collect();
    let mut rewards = vec![0.0; 64];
    for s in (0..64).filter(|&s| st.decode(s)[0] == 0) {
        rewards[s] = 10.0;
    }
    w.set_preferences(&rewards, 1.0).unwrap();
    w.set_crash_model(Some(CrashModel {
        hazard,
        crashed: -30.0,
        neutral: -5.0,
    }))
    .unwrap();
    let mut q = QLearning::new(64, 3, QParams::default()).unwrap();
    for _ in 0..50 {
        q.update(approach, SPEED_UP, 1.0, crosswalk, true);
    }
    (st, w, q)
}

/// The first action of an episode from the approach at top speed, and whether it reasoned.
fn first_action(tie_break: TieBreak) -> (usize, bool) {
    let (st, w, q) = setup();
    let mut params = ScaledParams::default();
    params.gate.competence = CompetenceCheck::SurpriseOnly;
    params.scaling.tie_break = tie_break;
    let mut agent = ScaledAgent::new(w, &q, params).unwrap();
    agent.begin_episode(0);
    let decision = agent.act(st.encode(&[2, 3, 1, 0]));
    (decision.action, decision.reasoned)
}

#[test]
fn where_the_model_cannot_tell_speeding_up_from_maintaining_the_agent_maintains() {
    // The habit's own choice, taken on a feed-forward tick as chosen (the ablation).
    assert_eq!(first_action(TieBreak::Chosen), (SPEED_UP, false));
    // The safest of the actions tied with it: maintain (slow down predicts another state).
    assert_eq!(first_action(TieBreak::Safest), (MAINTAIN, false));
}
