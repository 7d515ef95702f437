//! The general model (`unforeseen_agent::aif`) against pymdp 1.0.4 (JAX, float64) on
//! pymdp's own environments: the T-maze, the generalized T-maze, the grid world and cue
//! chaining, built by pymdp's code with their default arguments. Data from
//! `scripts/pymdp_envs_reference.py` in `tests/data/pymdp/*.json` (no JAX needed here).
//!
//! Per step of a 50-step rollout (reset every 10), replayed on pymdp's observations and
//! actions: qs, the VFE, G per policy (`−neg_efe`), q_π and the chosen action (full and
//! marginal) agree to 1e-6, and so they do for 20 steps with the parameter information
//! gain; after 10 episodes of Dirichlet learning, pA and pB agree to 1e-6. A copy of the EFE with the
//! information gain's sign flipped, and one with `C` normalised, are caught.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;
use serde_json::Value;
use unforeseen_agent::aif::action::Sampling;
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::efe::{EfeTerms, Preferences};
use unforeseen_agent::aif::learning::expected_value;
use unforeseen_agent::aif::model::{Model, parts_from_json};
use unforeseen_agent::aif::tensor::Tensor;

const TOL: f64 = 1e-6;
const ENVS: [(&str, &str); 4] = [
    ("tmaze", include_str!("../data/pymdp/tmaze.json")),
    (
        "generalized_tmaze",
        include_str!("../data/pymdp/generalized_tmaze.json"),
    ),
    ("grid_world", include_str!("../data/pymdp/grid_world.json")),
    ("cue_chaining", include_str!("../data/pymdp/cue_chaining.json")),
];

#[derive(Deserialize)]
#[allow(non_snake_case)]
struct Step {
    reset: bool,
    obs: Vec<usize>,
    vfe: f64,
    qs: Vec<Vec<f64>>,
    G: Vec<f64>,
    q_pi: Vec<f64>,
    action: Vec<usize>,
    action_marginal: Vec<usize>,
}

#[derive(Deserialize)]
struct Episode {
    obs: Vec<Vec<usize>>,
    actions: Vec<Vec<usize>>,
}

#[derive(Deserialize)]
#[allow(non_snake_case)]
struct Learning {
    pA0: Vec<Value>,
    pB0: Vec<Value>,
    episodes: Vec<Episode>,
    pA: Vec<Value>,
    pB: Vec<Value>,
}

#[derive(Deserialize)]
struct Reference {
    pymdp_version: String,
    dtype: String,
    model: Value,
    policies: Vec<Vec<Vec<usize>>>,
    rollout: Vec<Step>,
    learning: Learning,
    param_info_gain: Vec<Step>,
}

fn reference(text: &str) -> Reference {
    let r: Reference = serde_json::from_str(text).unwrap();
    assert_eq!(r.pymdp_version, "1.0.4");
    assert_eq!(r.dtype, "float64");
    r
}

fn params(r: &Reference) -> AgentParams {
    AgentParams {
        policy_len: r.model["policy_len"].as_u64().unwrap() as usize,
        gamma: r.model["gamma"].as_f64().unwrap(),
        num_iter: r.model["num_iter"].as_u64().unwrap() as usize,
        ..AgentParams::default()
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn flat(v: &[Vec<f64>]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

/// Whether our action may differ from pymdp's only by a tie: the best policy starting with
/// our action has pymdp's largest q_π within 1e-12 (an argmax among equals decided by
/// rounding in the last bit).
fn tied(step: &Step, policies: &[Vec<Vec<usize>>], ours: &[usize]) -> bool {
    let best = step.q_pi.iter().copied().fold(f64::MIN, f64::max);
    policies
        .iter()
        .zip(&step.q_pi)
        .any(|(p, q)| p[0] == ours && (best - q).abs() <= 1e-12 * best.max(1.0))
}

/// [`tied`] for the marginal mode: for each factor, pymdp's marginal of our action is
/// within 1e-12 of its largest.
fn tied_marginal(step: &Step, policies: &[Vec<Vec<usize>>], ours: &[usize]) -> bool {
    ours.iter().enumerate().all(|(f, &u)| {
        let n = policies.iter().map(|p| p[0][f]).max().unwrap_or(0) + 1;
        let mut m = vec![0.0; n];
        for (p, q) in policies.iter().zip(&step.q_pi) {
            m[p[0][f]] += q;
        }
        let best = m.iter().copied().fold(f64::MIN, f64::max);
        (best - m[u]).abs() <= 1e-12
    })
}

/// Replay pymdp's steps (its observations and actions; the prior back to D at each
/// reset): the worst difference of (qs, VFE, G, q_pi) over every step, and the number of
/// steps whose action differs (other than by a tie) and of ties.
fn replay(steps: &[Step], policies: &[Vec<Vec<usize>>], agent: &Agent, marginal: &Agent) -> ([f64; 4], usize, usize) {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut prior = agent.initial_prior();
    let mut worst = [0.0f64; 4];
    let (mut wrong, mut ties) = (0, 0);
    for s in steps {
        if s.reset {
            prior = agent.initial_prior();
        }
        let qs = agent.infer_states(&s.obs, &prior).unwrap();
        let post = agent.infer_policies(&qs);
        worst[0] = worst[0].max(max_diff(&flat(&qs), &flat(&s.qs)));
        worst[1] = worst[1].max((agent.vfe(&s.obs, &prior, &qs) - s.vfe).abs());
        worst[2] = worst[2].max(max_diff(&post.G, &s.G));
        worst[3] = worst[3].max(max_diff(&post.q_pi, &s.q_pi));
        let ours = agent.sample_action(&post.q_pi, &mut rng);
        if ours != s.action {
            if tied(s, policies, &ours) {
                ties += 1;
            } else {
                wrong += 1;
            }
        }
        let ours_m = marginal.sample_action(&marginal.infer_policies(&qs).q_pi, &mut rng);
        if ours_m != s.action_marginal {
            if tied_marginal(s, policies, &ours_m) {
                ties += 1;
            } else {
                wrong += 1;
            }
        }
        prior = agent.update_empirical_prior(&s.action, &qs).unwrap();
    }
    (worst, wrong, ties)
}

fn check(name: &str, what: &str, steps: &[Step], policies: &[Vec<Vec<usize>>], agent: &Agent, marginal: &Agent) {
    let (worst, wrong, ties) = replay(steps, policies, agent, marginal);
    eprintln!(
        "{name} {what}: {} steps, max |qs| {:.1e}, |vfe| {:.1e}, |G| {:.1e}, |q_pi| {:.1e}; actions tied with pymdp's (argmax among equals): {ties}",
        steps.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
    for (w, x) in ["qs", "vfe", "G", "q_pi"].iter().zip(worst) {
        assert!(x < TOL, "{name} {what}: {w} differs from pymdp by {x:e}");
    }
    assert_eq!(wrong, 0, "{name} {what}: {wrong} actions differ from pymdp's");
}

fn marginal_twin(agent: &Agent) -> Agent {
    let params = AgentParams {
        sampling_mode: Sampling::Marginal,
        ..*agent.params()
    };
    Agent::new(agent.model().clone(), params, None).unwrap()
}

#[test]
fn rollouts_match_pymdp_on_its_environments() {
    for (name, text) in ENVS {
        let r = reference(text);
        let agent = Agent::new(Model::from_json(&r.model).unwrap(), params(&r), None).unwrap();
        assert_eq!(
            agent.policies().to_vec(),
            r.policies,
            "{name}: policies in pymdp's order"
        );
        assert_eq!(r.rollout.len(), 50);
        check(name, "rollout", &r.rollout, &r.policies, &agent, &marginal_twin(&agent));
    }
}

/// The parameter information gain (pymdp's `use_param_info_gain=True`, exact Dirichlet
/// weights) on the weak counts pA0, pB0.
#[test]
fn parameter_information_gain_matches_pymdp() {
    for (name, text) in ENVS {
        let r = reference(text);
        let params = AgentParams {
            terms: EfeTerms {
                param_info_gain: true,
                ..EfeTerms::default()
            },
            ..params(&r)
        };
        let agent = Agent::new(learning_model(&r), params, None).unwrap();
        check(
            name,
            "param info gain",
            &r.param_info_gain,
            &r.policies,
            &agent,
            &marginal_twin(&agent),
        );
    }
}

fn counts(vs: &[Value], key: &str) -> Vec<Tensor> {
    vs.iter()
        .enumerate()
        .map(|(i, v)| Tensor::from_json(&format!("{key}[{i}]"), v).unwrap())
        .collect()
}

/// The model with the weak counts pA0, pB0 and `A`, `B` their expected values.
fn learning_model(r: &Reference) -> Model {
    let mut parts = parts_from_json(&r.model).unwrap();
    let (pa, pb) = (counts(&r.learning.pA0, "pA0"), counts(&r.learning.pB0, "pB0"));
    parts.A = pa.iter().map(expected_value).collect();
    parts.B = pb.iter().map(expected_value).collect();
    parts.pA = Some(pa);
    parts.pB = Some(pb);
    Model::new(parts).unwrap()
}

#[test]
fn dirichlet_learning_matches_pymdp_after_ten_episodes() {
    for (name, text) in ENVS {
        let r = reference(text);
        let l = &r.learning;
        let mut agent = Agent::new(learning_model(&r), params(&r), None).unwrap();
        assert_eq!(l.episodes.len(), 10);
        for ep in &l.episodes {
            let mut prior = agent.initial_prior();
            let mut beliefs = Vec::new();
            for (o, u) in ep.obs.iter().zip(&ep.actions) {
                let qs = agent.infer_states(o, &prior).unwrap();
                prior = agent.update_empirical_prior(u, &qs).unwrap();
                beliefs.push(qs);
            }
            agent
                .infer_parameters(&beliefs, &ep.obs, &ep.actions, Some(1.0), Some(1.0))
                .unwrap();
        }
        let m = agent.model();
        for (key, ours, theirs) in [
            ("pA", m.pa().unwrap(), counts(&l.pA, "pA")),
            ("pB", m.pb().unwrap(), counts(&l.pB, "pB")),
        ] {
            for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
                assert_eq!(a.shape, b.shape, "{name}: {key}[{i}] shape");
                let d = max_diff(&a.data, &b.data);
                assert!(d < TOL, "{name}: {key}[{i}] differs from pymdp by {d:e}");
            }
        }
        // The counts moved: learning did something the comparison can see.
        let moved = max_diff(&m.pb().unwrap()[0].data, &counts(&l.pB0, "pB0")[0].data);
        assert!(moved >= 1.0, "{name}: pB[0] moved by {moved} only");
    }
}

/// The comparison is sharp: a copy of the EFE with the information gain's sign flipped
/// (`G' = −U + IG` instead of `−U − IG`, built from the utility-only and full planners)
/// and one with `C` normalised (the paper's `ln softmax C`) both differ from pymdp's G by
/// far more than the tolerance; the normalised one leaves q_π unchanged (the shift is the same for every policy).
#[test]
fn a_wrong_sign_or_normalisation_is_caught() {
    let r = reference(ENVS[0].1);
    let model = Model::from_json(&r.model).unwrap();
    let full = Agent::new(model.clone(), params(&r), None).unwrap();
    let utility_only = Agent::new(
        model.clone(),
        AgentParams {
            terms: EfeTerms {
                states_info_gain: false,
                ..EfeTerms::default()
            },
            ..params(&r)
        },
        None,
    )
    .unwrap();
    let normalised = Agent::new(
        model,
        AgentParams {
            preferences: Preferences::LnSoftmax,
            ..params(&r)
        },
        None,
    )
    .unwrap();
    let (mut flipped_err, mut norm_err, mut norm_q_err) = (0.0f64, 0.0f64, 0.0f64);
    let mut prior = full.initial_prior();
    for s in &r.rollout {
        if s.reset {
            prior = full.initial_prior();
        }
        let qs = full.infer_states(&s.obs, &prior).unwrap();
        let g = full.infer_policies(&qs).G;
        let gu = utility_only.infer_policies(&qs).G;
        let flipped: Vec<f64> = g.iter().zip(&gu).map(|(g, u)| 2.0 * u - g).collect();
        flipped_err = flipped_err.max(max_diff(&flipped, &s.G));
        let n = normalised.infer_policies(&qs);
        norm_err = norm_err.max(max_diff(&n.G, &s.G));
        norm_q_err = norm_q_err.max(max_diff(&n.q_pi, &s.q_pi));
        prior = full.update_empirical_prior(&s.action, &qs).unwrap();
    }
    assert!(
        flipped_err > 1e3 * TOL,
        "a flipped information gain went unseen ({flipped_err:e})"
    );
    assert!(
        norm_err > 1e3 * TOL,
        "normalised preferences went unseen ({norm_err:e})"
    );
    assert!(norm_q_err < TOL, "normalising C changed q_pi by {norm_q_err:e}");
}

/// `inspect` on a general model (the T-maze's, with pymdp's first five observations and
/// actions) reports pymdp's step 5.
#[test]
fn inspect_json_runs_a_multi_factor_model() {
    let r = reference(ENVS[0].1);
    let mut v = r.model.clone();
    let steps = &r.rollout[..5];
    assert!(steps[1..].iter().all(|s| !s.reset));
    v["obs"] = serde_json::json!(steps.iter().map(|s| s.obs.clone()).collect::<Vec<_>>());
    v["actions"] = serde_json::json!(steps[..4].iter().map(|s| s.action.clone()).collect::<Vec<_>>());
    let out: Value = serde_json::from_str(&unforeseen_agent::inspect::inspect_json(&v.to_string()).unwrap()).unwrap();
    let qs: Vec<Vec<f64>> = serde_json::from_value(out["qs"].clone()).unwrap();
    let g: Vec<f64> = serde_json::from_value(out["G"].clone()).unwrap();
    assert!(max_diff(&flat(&qs), &flat(&steps[4].qs)) < TOL);
    assert!(max_diff(&g, &steps[4].G) < TOL);
    assert!((out["vfe"].as_f64().unwrap() - steps[4].vfe).abs() < TOL);
    v["B"][1] = serde_json::json!([[[0.5], [0.0]], [[0.2], [1.0]]]);
    let e = unforeseen_agent::inspect::inspect_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert_eq!(e, "B[1] column (s=0, u=0) sums to 0.7, must be 1 (within 1e-6)");
}

/// The exhaustive policies' prefix tree gives every policy's G bit for bit as evaluating
/// each policy from the root (the same policies given as a list) does.
#[test]
fn the_prefix_tree_equals_policy_by_policy_bit_for_bit() {
    for (name, text) in ENVS {
        let r = reference(text);
        let model = Model::from_json(&r.model).unwrap();
        let tree = Agent::new(model.clone(), params(&r), None).unwrap();
        let listed = Agent::new(model, params(&r), Some(&r.policies)).unwrap();
        assert!(tree.policies().is_exhaustive() && !listed.policies().is_exhaustive());
        let s = &r.rollout[1];
        let qs = tree.infer_states(&s.obs, &tree.initial_prior()).unwrap();
        let (a, b) = (tree.infer_policies(&qs), listed.infer_policies(&qs));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.G), bits(&b.G), "{name}");
        assert_eq!(bits(&a.q_pi), bits(&b.q_pi), "{name}");
    }
}
