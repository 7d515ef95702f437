//! The driving agent's planning model in pymdp's layout (`unforeseen_agent::aif::driving`):
//! the general agent on [`equivalent`] gives the EFE tree's `G` and first-action marginal
//! (root step through the learned `B`, crash hazard and risk), while [`exported`], which
//! leaves both out, does not; a transition cost is refused by name.

use unforeseen_agent::aif::action::marginals;
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::driving::{equivalent, exported};
use unforeseen_agent::model::{CrashModel, GenerativeModel, TransitionCost, WorldModel};
use unforeseen_agent::params::ModelPriors;
use unforeseen_agent::planning::EfeTree;
use unforeseen_agent::structure::Structure;

/// The paper's 4-factor model with learned ego dynamics (speed up / maintain / slow down
/// change v by +1 / 0 / -1; d falls by one bin at v = 3), arrival absorbing, and a crash
/// hazard where a pedestrian is on the crosswalk (d = 1, p = 1) and the car moves, larger
/// for faster actions.
fn model() -> WorldModel {
    let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
    let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
    for _ in 0..30 {
        for d in 1..4 {
            for v in 0..4 {
                for p in 0..2 {
                    for (u, dv) in [(0, 0i32), (1, 1), (2, -1)] {
                        let v2 = (v as i32 + dv).clamp(0, 3) as usize;
                        let d2 = if v2 == 3 { d - 1 } else { d };
                        w.observe_transition(st.encode(&[d, v, 1, p]), u, st.encode(&[d2, v2, 1, p]));
                    }
                }
            }
        }
    }
    let arrival: Vec<usize> = (0..64).filter(|&s| st.decode(s)[0] == 0).collect();
    w.set_terminal_states(&arrival).unwrap();
    let rewards: Vec<f64> = (0..64).map(|s| if st.decode(s)[0] == 0 { 10.0 } else { 0.0 }).collect();
    w.set_preferences(&rewards, 1.0).unwrap();
    let hazard = (0..3)
        .map(|u| {
            (0..64)
                .map(|s| {
                    let x = st.decode(s);
                    if x[0] == 1 && x[3] == 1 && x[1] > 0 {
                        [0.3, 0.5, 0.1][u]
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    w.set_crash_model(Some(CrashModel {
        hazard,
        crashed: -20.0,
        neutral: 0.0,
    }))
    .unwrap();
    w.plan_with_crash_model(true);
    w
}

/// Every one-hot belief and mixtures of two neighbouring states.
fn beliefs() -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    for s in 0..64 {
        let mut q = vec![0.0; 64];
        q[s] = 1.0;
        out.push(q.clone());
        q[s] = 0.6;
        q[(s + 5) % 64] += 0.4;
        out.push(q);
    }
    out
}

fn general(agent: &Agent, qs: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let post = agent.infer_policies(qs);
    let psi = marginals(&post.q_pi, agent.policies(), agent.model().num_controls()).swap_remove(0);
    (post.G, psi)
}

#[test]
fn the_equivalent_model_gives_the_trees_g_and_the_exported_one_does_not() {
    let w = model();
    let (plan, root) = (w.planning_generative(), w.generative());
    assert!(plan.crash.is_some());
    let params = AgentParams {
        policy_len: 3,
        gamma: 0.5,
        ..AgentParams::default()
    };
    let eqv = Agent::new(equivalent(plan, root).unwrap(), params, None).unwrap();
    let exp = Agent::new(exported(plan).unwrap(), params, None).unwrap();
    let mut tree = EfeTree::new(64, 64, 3, 3);
    let (mut worst_eqv, mut worst_exp) = (0.0f64, 0.0f64);
    for q in beliefs() {
        tree.evaluate(plan, root, &q, 0.5);
        let mut q1 = q.clone();
        q1.push(0.0);
        let (g, psi) = general(&eqv, &[q1, vec![1.0, 0.0]]);
        for (a, b) in g.iter().zip(&tree.g).chain(psi.iter().zip(&tree.psi)) {
            worst_eqv = worst_eqv.max((a - b).abs());
        }
        let (g, _) = general(&exp, &[q]);
        for (a, b) in g.iter().zip(&tree.g) {
            worst_exp = worst_exp.max((a - b).abs());
        }
    }
    assert!(worst_eqv < 1e-9, "equivalent: |ΔG|, |Δψ| up to {worst_eqv}");
    assert!(
        worst_exp > 1e-2,
        "exported: |ΔG| only {worst_exp}: the crash terms and root step should show"
    );
}

#[test]
fn a_transition_cost_or_a_size_mismatch_is_refused_by_name() {
    let w = model();
    let plan = w.planning_generative();
    let costly = GenerativeModel {
        transition_cost: Some(TransitionCost {
            from: vec![true; 64],
            to: vec![true; 64],
            cost: 1.0,
        }),
        ..plan.clone()
    };
    let err = equivalent(&costly, w.generative()).unwrap_err().to_string();
    assert!(err.contains("transition_cost"), "{err}");
    let other = WorldModel::new(
        Structure::paper_default([4, 4, 2, 2]).unwrap(),
        2,
        &ModelPriors::default(),
    )
    .unwrap();
    let err = equivalent(plan, other.generative()).unwrap_err().to_string();
    assert!(err.contains("root"), "{err}");
}
