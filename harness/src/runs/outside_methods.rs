//! Methods given from outside the library (a Python policy, or the scaled agent around a
//! Python habit): evaluated by the episode runner the built-in methods use
//! ([`run_episodes_in_order`]), their figures from [`Aggregate`], and reported as the batch's
//! result lines ([`ResultLine`]), so that they sit in a results file beside the built-in
//! methods and the batch summary reads them alike. The fronts only make the controller.
//!
//! A method given from outside is known by its name alone: the name its lines carry, from
//! which its episodes' controller seeds derive
//! ([`eval_seeds_named`](crate::episodes::evaluation::eval_seeds_named); the world seeds
//! depend on the map and the episode only, so every method meets the same pedestrians).
//! A policy given under a built-in method's name, and acting as it does, gives that
//! method's line (timing aside); its line carries no expectation checks (a map's
//! expectations are about the built-in methods) and the parameter set `default`.

use unforeseen_agent::params::ScaledParams;
use unforeseen_env::EnvConfig;

use crate::episodes::evaluation::{MakeControllerMut, run_episodes_in_order};
use crate::episodes::metrics::{Aggregate, efe_prefix_tree};
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::EpisodeResult;
use crate::error::Error;
use crate::progress::Progress;
use crate::runs::batch::{ResultLine, Scenario, UnitLabel};

/// A method given from outside, as the runner and its lines know it.
#[derive(Debug, Clone)]
pub struct ExternalMethod<'a> {
    /// Its name in the lines; its controller seeds derive from it ([`eval_seeds_named`]).
    ///
    /// [`eval_seeds_named`]: crate::episodes::evaluation::eval_seeds_named
    pub name: &'a str,
    /// How the env observes for it (the form its policy reads).
    pub config: EnvConfig,
    /// Whether it learns across episodes: then it runs once per protocol asked, else once,
    /// its line covering every protocol asked (as the batch does for built-in methods).
    pub learns: bool,
    /// The scaled agent's parameters, for a method that plans by expected free energy (the
    /// scaled agent around a habit): its lines' reasoning compute counts that planner's
    /// prefix tree ([`efe_prefix_tree`]). None for a method that does not plan by EFE.
    pub planning: Option<&'a ScaledParams>,
}

/// Where a method's lines stand in a results file.
#[derive(Debug, Clone, Copy, Default)]
pub struct LinePlace {
    /// Unit index of the first line; the next ones follow.
    pub first_unit: usize,
    /// Training seed of the policy (None for a policy without one).
    pub train_seed: Option<u64>,
    /// Training episodes of the policy (None when unknown).
    pub train_episodes: Option<u64>,
}

/// One run of a method given from outside: its result line and its episodes.
#[derive(Debug, Clone)]
pub struct ExternalRun {
    /// The result line (the batch's schema).
    pub line: ResultLine,
    /// Every episode, in order.
    pub episodes: Vec<EpisodeResult>,
}

/// Evaluates `method` on the map of `scenario` under `protocols` (once per protocol if it
/// learns across episodes, else once for all: [`ExternalMethod::learns`]), `episodes`
/// episodes from `seed` each, in order on the calling thread ([`run_episodes_in_order`]:
/// zero-shot makes a fresh controller per episode, continual one throughout), and reports
/// each run as a result line placed at `place`. A stream scenario, or no protocol, is an
/// [`Error::OutOfRange`].
#[allow(clippy::too_many_arguments)]
pub fn evaluate_external(
    scenario: &Scenario,
    method: &ExternalMethod<'_>,
    make: &mut MakeControllerMut<'_, '_>,
    protocols: &[Protocol],
    place: LinePlace,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<ExternalRun>, Error> {
    let map = scenario.map().ok_or_else(|| Error::OutOfRange {
        field: "map".into(),
        value: scenario.source.clone(),
        expected: "a map (a deployment stream runs built-in methods only)".into(),
    })?;
    let runs: Vec<(Protocol, Vec<Protocol>)> = match (method.learns, protocols.first()) {
        (_, None) => {
            return Err(Error::OutOfRange {
                field: "protocols".into(),
                value: "[]".into(),
                expected: "at least one of zero-shot, continual".into(),
            });
        }
        (true, _) => protocols.iter().map(|&p| (p, vec![p])).collect(),
        (false, Some(&first)) => vec![(first, protocols.to_vec())],
    };
    let tree = method.planning.map_or(0, efe_prefix_tree);
    progress.phase(&format!("{} {}", method.name, map.name), episodes * runs.len() as u64);
    let mut out = Vec::with_capacity(runs.len());
    for (i, (protocol, covers)) in runs.into_iter().enumerate() {
        // A method that does not learn runs as zero-shot (a fresh controller per episode),
        // whatever protocol its line names first, as the batch runs built-in methods.
        let mode = if method.learns { protocol } else { Protocol::ZeroShot };
        let results = run_episodes_in_order(
            mode,
            map,
            method.config.clone(),
            method.name,
            make,
            episodes,
            seed,
            progress,
        )?;
        let label = UnitLabel {
            unit: place.first_unit + i,
            scenario: scenario.name().to_string(),
            source: scenario.source.clone(),
            method: method.name.to_string(),
            param_set: "default".into(),
            params: Vec::new(),
            protocol,
            covers,
            train_seed: place.train_seed,
            train_episodes: place.train_episodes,
            seed,
        };
        let line = ResultLine::new(label, &Aggregate::of(&results), tree, Vec::new(), Vec::new());
        out.push(ExternalRun {
            line,
            episodes: results,
        });
    }
    progress.finish();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::episodes::evaluation::run_scripted_episodes;
    use crate::episodes::methods::Method;
    use crate::episodes::reference::NeverBrake;
    use crate::progress::NoProgress;
    use unforeseen_agent::controller::{Controller, Decision};
    use unforeseen_env::ObservationForm;

    fn untimed(mut results: Vec<EpisodeResult>) -> Vec<EpisodeResult> {
        for r in &mut results {
            (r.decide_ns, r.reasoning_ns) = (0, 0);
        }
        results
    }

    fn jaywalk() -> Scenario {
        Scenario::of_map(unforeseen_sim::embedded::load("jaywalk").unwrap(), "embedded:jaywalk")
    }

    fn named(name: &str, observation: ObservationForm) -> ExternalMethod<'_> {
        ExternalMethod {
            name,
            config: EnvConfig {
                observation,
                ..EnvConfig::default()
            },
            learns: false,
            planning: None,
        }
    }

    #[test]
    fn a_controller_given_under_a_built_in_name_runs_that_methods_episodes() {
        let scenario = jaywalk();
        let mut make = || Ok(Box::new(NeverBrake) as Box<dyn Controller>);
        let protocols = [Protocol::Continual, Protocol::ZeroShot];
        let method = named("never-brake", ObservationForm::Discrete);
        let place = LinePlace {
            first_unit: 4,
            ..LinePlace::default()
        };
        let runs = evaluate_external(&scenario, &method, &mut make, &protocols, place, 6, 3, &NoProgress).unwrap();
        // It does not learn: one run, covering both protocols, named by the first.
        assert_eq!(runs.len(), 1);
        let run = &runs[0];
        assert_eq!((run.line.unit, run.line.protocol), (4, Protocol::Continual));
        assert_eq!(run.line.covers, protocols);
        let map = scenario.map().unwrap();
        let built_in = run_scripted_episodes(map, Method::NeverBrake, 6, 3, &NoProgress).unwrap();
        assert_eq!(untimed(run.episodes.clone()), untimed(built_in.clone()));
        let agg = Aggregate::of(&built_in);
        assert_eq!(run.line.collision_rate, agg.collision_rate);
        assert!(agg.collision_rate > 0.0);
        // Under another name, the same world (never-brake ignores its seed).
        let other = named("careless", ObservationForm::Discrete);
        let runs = evaluate_external(&scenario, &other, &mut make, &protocols, place, 6, 3, &NoProgress).unwrap();
        assert_eq!(untimed(runs[0].episodes.clone()), untimed(built_in));
    }

    /// Records the length of each vector it is handed, and checks one comes before each act.
    struct Sees<'a> {
        lens: &'a std::sync::Mutex<Vec<usize>>,
        seen: usize,
        acted: usize,
    }

    impl Controller for Sees<'_> {
        fn name(&self) -> &'static str {
            "sees"
        }
        fn begin_episode(&mut self, _seed: u64) {}
        fn see_features(&mut self, features: &[f32]) {
            self.seen += 1;
            self.lens.lock().unwrap().push(features.len());
        }
        fn act(&mut self, _obs: usize) -> Decision {
            self.acted += 1;
            Decision {
                // An action the env refuses if no vector came first.
                action: if self.seen == self.acted { 1 } else { 3 },
                ..Decision::default()
            }
        }
    }

    #[test]
    fn a_kinematic_env_hands_the_controller_its_vector_before_each_act() {
        let scenario = jaywalk();
        for (form, len) in [
            (
                ObservationForm::Kinematic,
                Some(unforeseen_env::kinematic::len(
                    unforeseen_env::kinematic::Slots::pedestrians(4),
                )),
            ),
            (ObservationForm::Discrete, None),
        ] {
            let lens = std::sync::Mutex::new(Vec::new());
            let mut make = || {
                Ok(Box::new(Sees {
                    lens: &lens,
                    seen: 0,
                    acted: 0,
                }) as Box<dyn Controller + '_>)
            };
            let method = named("sees", form);
            let one = LinePlace::default();
            let result = evaluate_external(
                &scenario,
                &method,
                &mut make,
                &[Protocol::ZeroShot],
                one,
                1,
                1,
                &NoProgress,
            );
            let lens = lens.into_inner().unwrap();
            match len {
                Some(len) => {
                    let ticks = result.unwrap()[0].line.mean_ticks as usize;
                    assert!(ticks > 0);
                    assert_eq!(lens, vec![len; ticks]);
                }
                // No vector: the controller answers with an action the env refuses.
                None => assert!(result.is_err() && lens.is_empty()),
            }
        }
    }

    #[test]
    fn the_planning_tree_counts_every_prefix() {
        let mut p = ScaledParams::default();
        p.planning.horizon = 3;
        assert_eq!(efe_prefix_tree(&p), 3 + 9 + 27);
    }
}
