//! Persistence (format version, corrupt files), controllers behind the shared trait,
//! and inspect's input validation.

use std::collections::BTreeMap;
use unforeseen_agent::bayes_rl::BayesRl;
use unforeseen_agent::controller::{Controller, Ending};
use unforeseen_agent::error::{AgentError, InspectError, PersistError};
use unforeseen_agent::inspect::inspect_json;
use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::{BayesModel, BayesRlParams, ModelPriors, Planner, QParams, ReasoningMode, ScaledParams};
use unforeseen_agent::persist::{AgentBundle, FORMAT_VERSION};
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_agent::structure::Structure;

/// A toy chain: v' = v + 1 under action 1 (speed up), d decreases with v'.
fn trained() -> (WorldModel, QLearning, BayesRl) {
    let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
    let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
    let mut q = QLearning::new(64, 3, QParams::default()).unwrap();
    let mut b = BayesRl::new(64, 3, BayesRlParams::default()).unwrap();
    for _ in 0..20 {
        for d in 1..4 {
            let s = st.encode(&[d, 1, 1, 0]);
            let s2 = st.encode(&[d - 1, 1, 1, 0]);
            w.observe_transition(s, 0, s2);
            q.update(s, 0, 1.0, s2, d == 1);
            b.observe_transition(s, 0, 1.0, s2, d == 1);
        }
    }
    w.materialize();
    (w, q, b)
}

#[test]
fn bundle_round_trip_and_errors() {
    let (w, q, b) = trained();
    let mut meta = BTreeMap::new();
    meta.insert("map".to_string(), "test".to_string());
    let bundle = AgentBundle::new(q, w, b, meta);
    let text = bundle.to_ron_string();
    let back = AgentBundle::from_ron_str(&text).unwrap();
    assert_eq!(back, bundle);
    assert_eq!(back.world_model.b(0), bundle.world_model.b(0));
    let other = text.replacen(&format!("format_version: {FORMAT_VERSION}"), "format_version: 99", 1);
    assert_eq!(
        AgentBundle::from_ron_str(&other),
        Err(PersistError::VersionMismatch {
            found: 99,
            expected: FORMAT_VERSION
        })
    );
    let corrupt = &text[..text.len() / 2];
    match AgentBundle::from_ron_str(corrupt) {
        Err(PersistError::Corrupt { message }) => assert!(message.contains(':'), "{message}"),
        other => panic!("expected Corrupt, got {other:?}"),
    }
    // A stored value out of range is refused, naming its field from the top of the file
    // (the learner's own path joined to where it sits in the bundle).
    let nan = text.replacen("a_counts: ([\n            1000.0", "a_counts: ([\n            NaN", 1);
    assert_ne!(nan, text);
    match AgentBundle::from_ron_str(&nan) {
        Err(PersistError::Invalid(f)) => assert_eq!(f.path, "world_model.a_counts[0,0]", "{f}"),
        other => panic!("expected Invalid, got {other:?}"),
    }
    // Unknown fields are refused (a typo never passes for a default).
    let unknown = text.replacen("q_learning: (", "q_learning: (\n        alpha: 0.5,", 1);
    match AgentBundle::from_ron_str(&unknown) {
        Err(PersistError::Corrupt { message }) => assert!(message.contains("q_learning.alpha"), "{message}"),
        other => panic!("expected Corrupt, got {other:?}"),
    }
}

#[test]
fn controllers_share_the_trait() {
    let (w, q, b) = trained();
    let st = w.structure().clone();
    let scaled = ScaledAgent::new(w.clone(), &q, ScaledParams::default()).unwrap();
    let always = ScaledAgent::new(w.clone(), &q, {
        let mut p = ScaledParams::default();
        p.scaling.reasoning = ReasoningMode::Always;
        p
    })
    .unwrap();
    let factored = BayesRl::new(
        64,
        3,
        BayesRlParams {
            model: BayesModel::Factored(st.clone()),
            planner: Planner::Lookahead { horizon: 3 },
            ..Default::default()
        },
    )
    .unwrap();
    let mut methods: Vec<Box<dyn Controller>> = vec![
        Box::new(q),
        Box::new(b),
        Box::new(factored),
        Box::new(scaled),
        Box::new(always),
    ];
    for m in methods.iter_mut() {
        m.begin_episode(7);
        let mut reasoned = 0;
        for d in (1..4).rev() {
            let dec = m.act(st.encode(&[d, 1, 1, 0]));
            assert!(dec.action < 3);
            assert!((dec.policy.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{}", m.name());
            reasoned += dec.reasoned as usize;
            m.observe(1.0, st.encode(&[d - 1, 1, 1, 0]), Ending::from_flags(d == 1, false));
        }
        // A jaywalker appears on green: unforeseen for the scaled agent.
        let dec = m.act(st.encode(&[2, 1, 1, 1]));
        if m.name() == "scaled" {
            assert!(dec.reasoned && dec.theta.unwrap() > 0.2 && dec.psi.is_some());
        }
        if m.name() == "q-learning" {
            assert_eq!(reasoned, 0);
        }
        m.end_episode();
    }
}

#[test]
fn scaled_agent_learns_and_surprise_drops() {
    let (w, q, _) = trained();
    let st = w.structure().clone();
    let mut agent = ScaledAgent::new(w, &q, ScaledParams::default()).unwrap();
    let s = st.encode(&[3, 1, 1, 0]);
    let s2 = st.encode(&[2, 1, 1, 1]);
    let mut first = None;
    for ep in 0..30 {
        agent.begin_episode(ep);
        agent.act(s);
        agent.act(s2);
        let sur = agent.last_surprise_history()[1];
        first.get_or_insert(sur);
        agent.end_episode();
        if ep == 29 {
            assert!(sur < first.unwrap() * 0.5, "surprise {sur} vs first {first:?}");
        }
    }
    let p = agent.model().cpt_prob(3, 1, &[0, 1, 2], None);
    assert!(p > 0.5, "P(p'=1 | p=0, L'=1, d'=2) = {p}");
    assert!((agent.pi_o(s).iter().sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn bad_parameters_are_errors() {
    let (w, q, _) = trained();
    assert!(
        ScaledAgent::new(w.clone(), &q, {
            let mut p = ScaledParams::default();
            p.planning.gamma = 0.0;
            p
        })
        .is_err()
    );
    let small = QLearning::new(10, 3, QParams::default()).unwrap();
    assert!(ScaledAgent::new(w, &small, ScaledParams::default()).is_err());
    assert!(
        QLearning::try_new(
            4,
            3,
            QParams {
                bias_action: Some(5),
                ..Default::default()
            }
        )
        .is_err()
    );
    assert!(
        BayesRl::new(
            64,
            3,
            BayesRlParams {
                model: BayesModel::Factored(Structure::paper_default([2, 2, 2, 2]).unwrap()),
                ..Default::default()
            }
        )
        .is_err()
    );
}

/// `QLearning::new` checks what the params module doc promises: the ranges of
/// [`QParams::check`], the sizes and `bias_action < n_actions`.
#[test]
fn q_learning_new_rejects_bad_params() {
    let bad = |params: QParams, n_actions: usize| match QLearning::new(8, n_actions, params) {
        Err(AgentError::Param(e)) => e.name,
        other => panic!("expected a parameter error, got {other:?}"),
    };
    let alpha = QParams {
        alpha: 0.0,
        ..Default::default()
    };
    assert_eq!(bad(alpha, 3), "alpha");
    let floor = QParams {
        epsilon: 0.1,
        epsilon_min: 0.5,
        ..Default::default()
    };
    assert_eq!(bad(floor, 3), "epsilon_min");
    let bias = QParams {
        bias_action: Some(3),
        ..Default::default()
    };
    assert_eq!(bad(bias, 3), "bias_action");
    assert_eq!(bad(QParams::default(), 0), "n_actions");
    assert!(QLearning::new(8, 3, QParams::default()).is_ok());
}

#[test]
fn inspect_rejects_bad_models_naming_the_field() {
    let good = r#"{"A": [[1.0, 0.0], [0.0, 1.0]], "B": [[[1.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [1.0, 0.0]]],
        "C": [0.0, 1.0], "D": [0.5, 0.5], "obs": [0, 1], "actions": [1], "policy_len": 2, "gamma": 1.0}"#;
    let out = inspect_json(good).unwrap();
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["policies"].as_array().unwrap().len(), 4);
    let bad_b = good.replace("[[0.0, 1.0], [1.0, 0.0]]]", "[[0.0, 1.0], [0.9, 0.0]]]");
    match inspect_json(&bad_b) {
        Err(InspectError::Invalid(m)) => assert!(m.starts_with("B[1] column 0 sums to 0.9"), "{m}"),
        other => panic!("{other:?}"),
    }
    let bad_obs = good.replace("\"obs\": [0, 1]", "\"obs\": [0, 5]");
    assert!(matches!(inspect_json(&bad_obs), Err(InspectError::Invalid(m)) if m.contains("obs[1]")));
    let bad_c = good.replace("\"C\": [0.0, 1.0]", "\"C\": [0.0]");
    assert!(matches!(inspect_json(&bad_c), Err(InspectError::Invalid(m)) if m.starts_with("C has")));
    assert!(matches!(inspect_json("{"), Err(InspectError::Json(_))));
    // 100 one-state actions at policy length 8 would be 10^16 policies (an allocation
    // abort): refused with the bound.
    let b: Vec<&str> = vec!["[[1.0]]"; 100];
    let many = format!(
        r#"{{"A": [[1.0]], "B": [{}], "C": [0.0], "D": [1.0], "obs": [0], "actions": [], "policy_len": 8, "gamma": 1.0}}"#,
        b.join(",")
    );
    assert!(matches!(inspect_json(&many), Err(InspectError::Invalid(m)) if m.contains("policies")));
}
