//! The surprise gate on a general model (`unforeseen_agent::aif::gate`), in pymdp's
//! T-maze (the model of `tests/data/pymdp/tmaze.json`, which is also the world).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::gate::{GatedAgent, Habit};
use unforeseen_agent::aif::model::Model;
use unforeseen_agent::aif::process::Process;
use unforeseen_agent::aif::run::{RunConfig, run};

fn tmaze() -> (Model, AgentParams) {
    let v: Value = serde_json::from_str(include_str!("../data/pymdp/tmaze.json")).unwrap();
    let params = AgentParams {
        policy_len: v["model"]["policy_len"].as_u64().unwrap() as usize,
        ..AgentParams::default()
    };
    (Model::from_json(&v["model"]).unwrap(), params)
}

const CFG: RunConfig = RunConfig {
    episodes: 6,
    steps: 10,
    seed: 7,
    learn: false,
};

/// With ε < 0 the gate is open on every tick and the gated agent acts as the plain one.
#[test]
fn an_open_gate_plans_every_tick_as_pymdp_does() {
    let (model, params) = tmaze();
    let agent = Agent::new(model.clone(), params, None).unwrap();
    let mut gated = GatedAgent::new(agent.clone(), -1.0, Habit::Learned).unwrap();
    let mut world = Process::new(model);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut obs = world.reset(&mut rng);
    let mut prior = agent.initial_prior();
    for _ in 0..10 {
        let (tick, qs) = gated.step(&obs, &mut rng).unwrap();
        assert!(tick.planned);
        let plain_qs = agent.infer_states(&obs, &prior).unwrap();
        assert_eq!(qs, plain_qs);
        let post = agent.infer_policies(&plain_qs);
        assert_eq!(tick.q_pi.as_ref(), Some(&post.q_pi));
        assert_eq!(
            tick.action,
            agent.sample_action(&post.q_pi, &mut ChaCha8Rng::seed_from_u64(0))
        );
        prior = agent.update_empirical_prior(&tick.action, &plain_qs).unwrap();
        obs = world.step(&tick.action, &mut rng).unwrap();
    }
}

/// A closed gate (ε above every surprise) with the learned habit plans only in states it
/// has never planned in, so it plans less; the same seed gives the same run.
#[test]
fn a_gate_plans_less_and_is_deterministic() {
    let (model, params) = tmaze();
    let go = |eps: f64| {
        let agent = Agent::new(model.clone(), params, None).unwrap();
        let mut gated = GatedAgent::new(agent, eps, Habit::Learned).unwrap();
        run(&mut gated, &mut Process::new(model.clone()), CFG).unwrap()
    };
    let open = go(-1.0);
    assert_eq!(open.planned_fraction, 1.0);
    let shut = go(1e6);
    assert!(shut.planned_fraction < 0.5, "planned {}", shut.planned_fraction);
    assert!(shut.planned_fraction > 0.0);
    assert_eq!(go(1e6), shut);
    // The prior habit needs an E.
    let agent = Agent::new(model, params, None).unwrap();
    let e = GatedAgent::new(agent, 1.0, Habit::Prior).unwrap_err().to_string();
    assert!(e.contains("no E"), "{e}");
}

/// A habit given as a function (`step_with`) acts whenever the gate is closed, with the
/// observation and the posterior it is asked with; an open gate never asks it; an action
/// outside the model is refused naming `habit`, and the function's own error carries
/// through.
#[test]
fn a_given_habit_acts_when_the_gate_is_closed_and_is_checked() {
    let (model, params) = tmaze();
    let agent = Agent::new(model.clone(), params, None).unwrap();
    let mut world = Process::new(model);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let obs = world.reset(&mut rng);

    let mut closed = GatedAgent::new(agent.clone(), 1e9, Habit::Learned).unwrap();
    let (mut asked_obs, mut asked_qs) = (Vec::new(), Vec::new());
    let (tick, qs) = closed
        .step_with(&obs, &mut rng, |o, q| {
            asked_obs = o.to_vec();
            asked_qs = q.to_vec();
            Ok::<_, unforeseen_agent::aif::error::ModelError>(vec![2, 0])
        })
        .unwrap();
    assert!(!tick.planned);
    assert_eq!(tick.action, vec![2, 0]);
    assert_eq!((asked_obs, asked_qs), (obs.clone(), qs));

    let mut open = GatedAgent::new(agent.clone(), -1.0, Habit::Learned).unwrap();
    let (tick, _) = open
        .step_with(
            &obs,
            &mut rng,
            |_, _| -> Result<Vec<usize>, unforeseen_agent::aif::error::ModelError> {
                panic!("an open gate asked the habit")
            },
        )
        .unwrap();
    assert!(tick.planned);

    let err = closed
        .step_with(&obs, &mut rng, |_, _| {
            Ok::<_, unforeseen_agent::aif::error::ModelError>(vec![9, 0])
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("habit") && err.contains("[9, 0]"), "{err}");

    #[derive(Debug, PartialEq)]
    enum Mine {
        Model,
        Policy,
    }
    impl From<unforeseen_agent::aif::error::ModelError> for Mine {
        fn from(_: unforeseen_agent::aif::error::ModelError) -> Mine {
            Mine::Model
        }
    }
    let err = closed.step_with(&obs, &mut rng, |_, _| Err(Mine::Policy)).unwrap_err();
    assert_eq!(err, Mine::Policy);
}
