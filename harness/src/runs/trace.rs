//! The request of one episode traced step by step ([`TraceRequest`], paper Figs. 6-7),
//! asked for by every front as one serde value. Its planning ([`TraceRequest::plan`])
//! checks the fields, loads the map, the parameters and the agent (the batch's one choice
//! of agents: an agent given loaded, the agent file, or one trained with the run seed)
//! and checks the outputs (the folder and the replay page); the planned job
//! ([`TraceJob`]) runs the episode into a [`TraceReport`] and writes trace.csv, theta.svg,
//! filmstrip.svg and the replay page, all or none.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_sim::Map;

use crate::episodes::methods::Method;
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::{EpisodeResult, Tick};
use crate::episodes::trace::trace;
use crate::error::Error;
use crate::files::{Csv, all_or_none, num, write_atomic};
use crate::limits::MAX_EPISODES;
use crate::progress::Progress;
use crate::reports::figures::{filmstrip, theta_trace};
use crate::reports::replay_page::replay_html;
use crate::reports::{Lamp, nearest_in_path};
use crate::runs::batch::AgentChoice;
use crate::runs::batch::request::AgentFields;
use crate::runs::outputs::{Outputs, Own};

/// The files a trace writes into its folder, in order (the replay page goes where
/// `html` says).
pub const TRACE_FILES: [&str; 3] = ["trace.csv", "theta.svg", "filmstrip.svg"];

/// Every choice of a trace, with its defaults ([`TraceRequest::default`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TraceRequest {
    /// The map (file or embedded name). Default `jaywalk`.
    pub map: String,
    /// The method traced. Default `scaled`.
    pub method: Method,
    /// The evaluation episode traced (0 = the first), at most [`MAX_EPISODES`]. Under
    /// the continual protocol the agent first runs and learns from the episodes before
    /// it. Default 0.
    pub episode: u64,
    /// The protocol of the traced episode: zero-shot (from the trained state) or
    /// continual (after learning from the episodes before it). Default zero-shot.
    pub protocol: Protocol,
    /// Scaled-agent parameter overrides, one `KEY=VALUE` each. Default: none.
    pub sets: Vec<String>,
    /// Evaluation seed (and, without an agent, the training seed). Default 7.
    pub seed: u64,
    /// The folder of trace.csv, theta.svg and filmstrip.svg (files from an earlier run
    /// there are replaced); none: no files. Default `out/trace`.
    pub out: Option<PathBuf>,
    /// The episode as one self-contained HTML page that plays it (no network). Default:
    /// none.
    pub html: Option<PathBuf>,
    /// An agent file (from `unforeseen train`); without one (or an agent given loaded),
    /// one is trained on `intersection` with the default episodes and `seed`. Default:
    /// none.
    pub agent: Option<PathBuf>,
    /// Replace an output that holds something other than what this run writes there
    /// (the output guard refuses it otherwise). Default: false.
    pub force: bool,
}

impl Default for TraceRequest {
    fn default() -> Self {
        TraceRequest {
            map: crate::maps::DEFAULT_TEST_MAP.to_string(),
            method: Method::Scaled,
            episode: 0,
            protocol: Protocol::ZeroShot,
            sets: Vec::new(),
            seed: unforeseen_env::seeds::DEFAULT_SEED,
            out: Some(PathBuf::from("out/trace")),
            html: None,
            agent: None,
            force: false,
        }
    }
}

/// A trace planned ([`TraceRequest::plan`]).
#[derive(Debug, Clone)]
pub struct TraceJob {
    /// The map.
    pub map: Box<Map>,
    /// The scaled agent's parameters, overrides applied.
    pub params: ScaledParams,
    /// The agent: given, or to train.
    pub agent: AgentChoice,
    /// The request.
    pub request: TraceRequest,
}

/// One episode step by step ([`TraceJob::run`]).
#[derive(Debug, Clone)]
pub struct TraceReport {
    /// How the episode went.
    pub result: EpisodeResult,
    /// Every tick, the last one the world after the episode ended (no decision).
    pub ticks: Vec<Tick>,
}

impl TraceReport {
    /// The ticks with a decision: all but the last.
    pub fn decided(&self) -> &[Tick] {
        &self.ticks[..self.ticks.len().saturating_sub(1)]
    }

    /// How the episode ended: `reached the destination`, `hit a pedestrian`, `hit a
    /// vehicle` (another vehicle and no pedestrian in the world at the end), `hit a
    /// pedestrian or a vehicle` (both there: the world reports a collision, not with
    /// what) or `ran out of time`.
    pub fn outcome(&self) -> &'static str {
        let last = self.ticks.last().map(|t| &t.snapshot);
        let vehicles = last.is_some_and(|s| !s.vehicles.is_empty());
        let pedestrians = last.is_some_and(|s| !s.pedestrians.is_empty());
        if self.result.success {
            "reached the destination"
        } else if !self.result.collision {
            "ran out of time"
        } else if !vehicles {
            "hit a pedestrian"
        } else if pedestrians {
            "hit a pedestrian or a vehicle"
        } else {
            "hit a vehicle"
        }
    }

    /// The episode in one line: `reached the destination after 24 ticks, return 9.10,
    /// reasoned on 3 ticks`.
    pub fn summary(&self) -> String {
        let r = &self.result;
        format!(
            "{} after {} ticks, return {:.2}, reasoned on {} ticks",
            self.outcome(),
            r.ticks,
            r.ret,
            r.reasoning_ticks
        )
    }
}

/// What a tick did: `reasoning` (it ran planning) or `feed-forward`.
pub fn mode(reasoned: bool) -> &'static str {
    if reasoned { "reasoning" } else { "feed-forward" }
}

/// A tick's surprise in bits (the runner measures nats), if its method measures one.
pub fn surprise_bits(tick: &Tick) -> Option<f64> {
    tick.surprise.map(|s| s / std::f64::consts::LN_2)
}

impl TraceRequest {
    /// Checks the request and resolves it before any work: the episode, the map, the
    /// outputs (the folder's files and the replay page, none of them an input), the
    /// overrides and the agent (`given`: an agent given loaded, such as Python's,
    /// instead of the file `agent`). Trains and writes nothing.
    pub fn plan(&self, given: Option<AgentBundle>) -> Result<TraceJob, Error> {
        if self.episode > MAX_EPISODES {
            return Err(Error::OutOfRange {
                field: "episode".into(),
                value: self.episode.to_string(),
                expected: format!("0..={MAX_EPISODES}"),
            });
        }
        let fields = AgentFields::one(self.agent.as_deref(), self.seed);
        fields.check(given.is_some(), "trace one agent")?;
        let map = crate::maps::load(&self.map)?;
        if let (Some(html), Some(dir)) = (&self.html, &self.out) {
            let same = |a: &std::path::Path, b: &std::path::Path| {
                std::path::absolute(a)
                    .ok()
                    .is_some_and(|a| std::path::absolute(b).ok() == Some(a))
            };
            if let Some(name) = TRACE_FILES.iter().find(|n| same(html, &dir.join(n))) {
                return Err(Error::request(
                    "html",
                    format!(
                        "{} is the trace's own {name} in out; give the page another file",
                        html.display()
                    ),
                ));
            }
        }
        if self.out.is_some() || self.html.is_some() {
            let mut guard = Outputs::new().input("map", &self.map);
            if let Some(agent) = &self.agent {
                guard = guard.input("agent", agent);
            }
            if let Some(html) = &self.html {
                guard = guard.file("html", html, Own::Html);
            }
            if let Some(dir) = &self.out {
                guard = guard.files_in("out", dir, &TRACE_FILES, &[Own::Csv, Own::Svg, Own::Svg]);
            }
            guard.check(self.force)?;
        }
        let params = crate::overrides::on_map(&map, crate::overrides::pairs(&self.sets)?)?;
        let (agent, _, _) = fields.choose(given, None)?;
        Ok(TraceJob {
            map: Box::new(map),
            params,
            agent,
            request: self.clone(),
        })
    }
}

impl TraceJob {
    /// The agent traced (a scripted method's controller is built from it too): the one
    /// given, or one trained (one phase of `progress`).
    pub fn agent(&self, progress: &dyn Progress) -> Result<AgentBundle, Error> {
        self.agent.one(progress)?.ok_or_else(|| Error::Agent {
            problem: "a trace needs a trained agent".into(),
            fix: "give an agent file, or let one be trained".into(),
        })
    }

    /// Runs the episode (and, under the continual protocol, those before it) with
    /// `bundle` ([`TraceJob::agent`]) and reports it. Writes nothing.
    pub fn run(&self, bundle: &AgentBundle) -> Result<TraceReport, Error> {
        let r = &self.request;
        let (result, ticks) = trace(bundle, &self.params, r.method, &self.map, r.seed, r.protocol, r.episode)?;
        Ok(TraceReport { result, ticks })
    }

    /// Writes trace.csv, theta.svg and filmstrip.svg into the request's `out` folder and
    /// the replay page to `html`, all or none: a failed write (a full disk) leaves the
    /// previous run's set. The paths written, in that order.
    pub fn write(&self, report: &TraceReport) -> Result<Vec<PathBuf>, Error> {
        let r = &self.request;
        let (method, map, seed) = (r.method, &self.map, r.seed);
        let epsilon = self.params.gate.epsilon;
        let mut paths: Vec<PathBuf> = match &r.out {
            Some(dir) => TRACE_FILES.iter().map(|n| dir.join(n)).collect(),
            None => Vec::new(),
        };
        all_or_none(|| -> Result<(), Error> {
            if let Some([csv, theta, film]) = paths.get(..3) {
                trace_csv(map, report.decided()).write(csv)?;
                let points: Vec<_> = report
                    .decided()
                    .iter()
                    .map(|t| (t.step, t.theta, t.reasoned, t.action.to_string()))
                    .collect();
                theta_trace(
                    theta,
                    &format!("{method} on {}: normalized surprise", map.name),
                    &points,
                    epsilon,
                )?;
                filmstrip(
                    film,
                    &format!(
                        "{method} on {}, seed {seed}: {} after {} ticks (from above, one strip per decision tick)",
                        map.name,
                        report.outcome(),
                        report.result.ticks
                    ),
                    map,
                    &report.ticks,
                )?;
            }
            if let Some(html) = &r.html {
                let title = format!("{method} on {}, seed {seed}", map.name);
                let outcome = format!("{method} {}", report.summary());
                let page = replay_html(&title, &outcome, map, &report.ticks, epsilon)?;
                write_atomic(html, page.as_bytes())?;
            }
            Ok(())
        })?;
        paths.extend(r.html.clone());
        Ok(paths)
    }
}

/// Whether a trace of `map` lists the street around the car: the map has a junction or
/// traffic. The paper's maps have neither, and their trace.csv keeps the columns it had
/// before there were vehicles.
pub fn shows_street(map: &Map) -> bool {
    map.junction.is_some() || !map.traffic.is_empty()
}

/// `trace.csv`: one row per decision tick (the state, the action and how it was
/// chosen, the surprise and theta, the reward, the policy and psi, the car and the
/// light). On a map with a junction or traffic ([`shows_street`]) the columns after
/// those add the vehicles: how many, whether one is in the car's path, the nearest of
/// those in its path (metres from the car's front bumper to its body, its speed; `-`
/// with none), and what the road's and the cross street's heads show (`dark` in an
/// outage, whatever `light`, the car's reading, says).
fn trace_csv(map: &Map, decided: &[Tick]) -> Csv {
    let mut columns = vec![
        "step",
        "d",
        "v",
        "L",
        "p",
        "action",
        "mode",
        "surprise_bits",
        "theta",
        "reward",
        "policy",
        "psi",
        "car_x",
        "car_speed",
        "light",
    ];
    let street = shows_street(map);
    if street {
        columns.extend([
            "vehicles",
            "vehicle_in_path",
            "nearest_in_path_m",
            "nearest_in_path_speed",
            "road_head",
            "cross_head",
        ]);
    }
    let mut csv = Csv::new(&columns);
    let opt = |x: Option<f64>, d| x.map(|v| num(v, d)).unwrap_or_else(|| "-".into());
    let cells = |x: &[f64]| x.iter().map(|p| num(*p, 6)).collect::<Vec<_>>().join(" ");
    for t in decided {
        let s = t.state;
        let mut row = vec![
            t.step.to_string(),
            s.d.to_string(),
            s.v.to_string(),
            s.l.to_string(),
            s.p.to_string(),
            t.action.to_string(),
            mode(t.reasoned).into(),
            opt(surprise_bits(t), 6),
            opt(t.theta, 6),
            num(t.reward, 4),
            cells(&t.policy),
            t.psi.as_deref().map(cells).unwrap_or_default(),
            num(t.snapshot.car_x, 3),
            num(t.snapshot.car_speed, 3),
            format!("{:?}", t.snapshot.light),
        ];
        if street {
            let snap = &t.snapshot;
            let nearest = nearest_in_path(map, snap);
            row.extend([
                snap.vehicles.len().to_string(),
                u8::from(snap.vehicle_in_path).to_string(),
                opt(nearest.map(|(_, gap)| gap), 3),
                opt(nearest.map(|(v, _)| v.speed), 3),
                Lamp::of_aspect(snap.signals.road).name().into(),
                Lamp::of_aspect(snap.signals.cross).name().into(),
            ]);
        }
        csv.row(row);
    }
    csv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::request::from_fields;

    #[test]
    fn the_page_is_not_one_of_the_traces_own_files() {
        let e = TraceRequest {
            out: Some(PathBuf::from("some/dir")),
            html: Some(PathBuf::from("some/dir/./trace.csv")),
            ..TraceRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(
            e.to_string().starts_with("html: ") && e.to_string().contains("trace.csv"),
            "{e}"
        );
    }

    fn fields(v: serde_json::Value) -> serde_json::Map<String, serde_json::Value> {
        v.as_object().cloned().unwrap()
    }

    #[test]
    fn a_bad_field_is_named_by_the_request() {
        let e = from_fields::<TraceRequest>(fields(serde_json::json!({"protocol": "twice"}))).unwrap_err();
        assert!(e.to_string().starts_with("protocol: "), "{e}");
        let e = from_fields::<TraceRequest>(fields(serde_json::json!({"episodes": 3}))).unwrap_err();
        assert!(e.to_string().starts_with("episodes: not a field"), "{e}");
        let e = TraceRequest {
            episode: MAX_EPISODES + 1,
            ..TraceRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(e.to_string().starts_with("episode "), "{e}");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let map = dir.path().join("theta.svg");
        std::fs::write(&map, unforeseen_sim::embedded::source("jaywalk").unwrap()).unwrap();
        let e = TraceRequest {
            map: map.display().to_string(),
            out: Some(dir.path().to_path_buf()),
            ..TraceRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(e.to_string().contains("given as map"), "{e}");
        // The replay page too, with no folder.
        let e = TraceRequest {
            map: map.display().to_string(),
            out: None,
            html: Some(map.clone()),
            ..TraceRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(e.to_string().starts_with("html "), "{e}");
        assert_eq!(
            std::fs::read_to_string(&map).unwrap(),
            unforeseen_sim::embedded::source("jaywalk").unwrap()
        );
    }
}
