//! The driving agent's planner beside the general code (`unforeseen_agent::aif`) on the
//! same beliefs (issue 46, docs/ARCHITECTURE.md §4.12): does the trained agent's planning
//! run through the general path, where do the two differ, and what does each cost?
//!
//! ```sh
//! cargo build --release -p unforeseen-agent --example driving_through_aif
//! target/release/unforeseen train --out agent7.ron
//! target/release/examples/driving_through_aif agent7.ron [TICKS] [REPS]
//! ```
//!
//! The driving planner is the scaled agent's EFE tree (`planning::EfeTree`, default
//! parameters): the first step through the learned `B` (the root step), later ones through
//! the planning `B` (episode-ending states absorbing), the crash model's hazard and risk,
//! and a transition cost where the model has one. Two models in pymdp's layout are built
//! from the same agent (`unforeseen_agent::aif::driving`): **exported**, what `unforeseen
//! export-model` writes (one factor, the planning `B`, no crash terms), and
//! **equivalent**, with the root step and the crash terms expressed in the layout. A
//! transition cost has no form there: on an agent with one, `equivalent` is built without
//! it and its disagreements are the cost's.
//!
//! Beliefs: every one-hot state, then `TICKS` (default 2000) exact filtering steps of a
//! walk through the learned model (true state drawn from `D` and the learned `B`,
//! observation from `A`, action the driving planner's argmax `ψ`; a new walk every 40
//! ticks or in an episode-ending state). On each belief: the largest `|ΔG|` over policies,
//! and whether the argmax of the first-action marginal `ψ` agrees. Each disagreement of
//! the exported model is put down to the root step, the crash terms (with the transition
//! cost, where there is one), or both, by evaluating the driving tree without them. Per-tick cost: the median over the beliefs of
//! the fastest of `REPS` (default 5) timed evaluations of each. Prints one JSON object.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use unforeseen_agent::aif::action::marginals;
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::driving::{equivalent, exported};
use unforeseen_agent::aif::process::sample;
use unforeseen_agent::maths::argmax;
use unforeseen_agent::model::GenerativeModel;
use unforeseen_agent::params::{RootStep, ScaledParams};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::planning::EfeTree;
use unforeseen_agent::scaled_agent::ScaledAgent;

/// `G`, `ψ` of the general agent from `qs`.
fn general(agent: &Agent, qs: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let post = agent.infer_policies(qs);
    let psi = marginals(&post.q_pi, agent.policies(), agent.model().num_controls()).swap_remove(0);
    (post.G, psi)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// The fastest of `reps` timings of `f`, in µs.
fn fastest(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e6
        })
        .fold(f64::INFINITY, f64::min)
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or("usage: driving_through_aif AGENT.ron [TICKS] [REPS]")?;
    let ticks: usize = args.get(1).map_or(Ok(2000), |s| s.parse())?;
    let reps: usize = args.get(2).map_or(Ok(5), |s| s.parse())?;
    let bundle = AgentBundle::from_ron_str(&std::fs::read_to_string(path)?)?;
    let params = ScaledParams::default();
    let (horizon, gamma) = (params.planning.horizon, params.planning.gamma);
    let learned_root = params.planning.root_step == RootStep::Learned;
    let scaled = ScaledAgent::new(bundle.world_model, &bundle.q_learning, params)?;
    let plan = scaled.model().planning_generative().clone();
    let root = if learned_root {
        scaled.model().generative().clone()
    } else {
        plan.clone()
    };
    let (n, no, na) = (plan.n_states(), plan.n_obs(), plan.n_actions());
    // The driving tree without its crash terms (and transition cost): for attribution.
    let strip = |gm: &GenerativeModel| GenerativeModel {
        crash: None,
        transition_cost: None,
        ..gm.clone()
    };
    let (plan_bare, root_bare) = (strip(&plan), strip(&root));
    let ap = AgentParams {
        policy_len: horizon,
        gamma,
        ..AgentParams::default()
    };
    let exp = Agent::new(exported(&plan)?, ap, None)?;
    let no_cost = |gm: &GenerativeModel| GenerativeModel {
        transition_cost: None,
        ..gm.clone()
    };
    let eqv = Agent::new(equivalent(&no_cost(&plan), &no_cost(&root))?, ap, None)?;
    let mut tree = EfeTree::new(n, no, na, horizon);

    // The beliefs: one-hot states, then a filtered walk.
    let mut beliefs: Vec<Vec<f64>> = (0..n)
        .map(|s| {
            let mut q = vec![0.0; n];
            q[s] = 1.0;
            q
        })
        .collect();
    let absorbing = |s: usize| (0..na).all(|u| plan.b[u][(s, s)] == 1.0);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut s_true, mut prior, mut age) = (0usize, plan.d.clone(), usize::MAX);
    for _ in 0..ticks {
        if age >= 40 || absorbing(s_true) {
            s_true = sample(plan.d.iter().copied(), &mut rng);
            prior = plan.d.clone();
            age = 0;
        }
        let o = sample((0..no).map(|o| root.a[(o, s_true)]), &mut rng);
        let mut q: Vec<f64> = (0..n).map(|s| root.a[(o, s)] * prior[s]).collect();
        let z: f64 = q.iter().sum();
        if z <= 0.0 {
            age = usize::MAX;
            continue;
        }
        q.iter_mut().for_each(|x| *x /= z);
        tree.evaluate(&plan, &root, &q, gamma);
        let u = argmax(&tree.psi);
        beliefs.push(q.clone());
        s_true = sample((0..n).map(|s2| root.b[u][(s2, s_true)]), &mut rng);
        prior = (0..n)
            .map(|s2| (0..n).map(|s| root.b[u][(s2, s)] * q[s]).sum())
            .collect();
        age += 1;
    }

    let (mut dg_exp, mut dg_eqv) = (0.0f64, 0.0f64);
    let (mut differ_exp, mut differ_eqv) = (0usize, 0usize);
    let (mut by_root, mut by_crash, mut by_both, mut needs_both) = (0usize, 0usize, 0usize, 0usize);
    let (mut t_tree, mut t_exp, mut t_eqv) = (Vec::new(), Vec::new(), Vec::new());
    for q in &beliefs {
        tree.evaluate(&plan, &root, q, gamma);
        let (g_drv, psi_drv) = (tree.g.clone(), tree.psi.clone());
        let u_drv = argmax(&psi_drv);
        let (g_exp, psi_exp) = general(&exp, std::slice::from_ref(q));
        let mut q_eqv = q.clone();
        q_eqv.push(0.0);
        let (g_eqv, psi_eqv) = general(&eqv, &[q_eqv.clone(), vec![1.0, 0.0]]);
        dg_exp = dg_exp.max(max_abs_diff(&g_drv, &g_exp));
        dg_eqv = dg_eqv.max(max_abs_diff(&g_drv, &g_eqv));
        if argmax(&psi_eqv) != u_drv {
            differ_eqv += 1;
        }
        if argmax(&psi_exp) != u_drv {
            differ_exp += 1;
            // Which of the driving tree's extras moves the decision off the exported one.
            let u_exp = argmax(&psi_exp);
            tree.evaluate(&plan_bare, &root_bare, q, gamma);
            let root_only = argmax(&tree.psi) != u_exp;
            tree.evaluate(&plan, &plan, q, gamma);
            let crash_only = argmax(&tree.psi) != u_exp;
            match (root_only, crash_only) {
                (true, false) => by_root += 1,
                (false, true) => by_crash += 1,
                (true, true) => by_both += 1,
                (false, false) => needs_both += 1,
            }
        }
        t_tree.push(fastest(reps, || tree.evaluate(&plan, &root, q, gamma)));
        t_exp.push(fastest(reps, || {
            std::hint::black_box(exp.infer_policies(std::slice::from_ref(q)));
        }));
        let qs_eqv = [q_eqv, vec![1.0, 0.0]];
        t_eqv.push(fastest(reps, || {
            std::hint::black_box(eqv.infer_policies(&qs_eqv));
        }));
    }
    let out = serde_json::json!({
        "agent": path,
        "states": n, "observations": no, "actions": na, "horizon": horizon, "gamma": gamma,
        "root_step_learned": learned_root,
        "crash_model": plan.crash.is_some(),
        "transition_cost": plan.transition_cost.is_some() || root.transition_cost.is_some(),
        "beliefs": beliefs.len(),
        "exported": {
            "max_abs_dG": dg_exp,
            "argmax_psi_differs": differ_exp,
            "differs_by_root_step": by_root,
            "differs_by_crash_terms_or_transition_cost": by_crash,
            "differs_by_either_alone": by_both,
            "differs_only_by_both_together": needs_both,
            "us_per_tick_median": median(t_exp),
        },
        "equivalent": {
            "max_abs_dG": dg_eqv,
            "argmax_psi_differs": differ_eqv,
            "us_per_tick_median": median(t_eqv),
        },
        "driving_tree_us_per_tick_median": median(t_tree),
    });
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}
