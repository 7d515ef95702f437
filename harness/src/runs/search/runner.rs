//! A running search's shared state (the file being appended, the lines kept) and the
//! evaluation of one candidate: the two witnesses, then the method per training seed.

use super::*;

/// The shared state of a running search: the part being appended, the file resumed
/// and the lines kept.
pub(super) struct Runner<'a, 'b> {
    pub(super) cfg: &'a SearchConfig<'b>,
    pub(super) sink: Mutex<crate::files::Streamed>,
    /// The file `--resume` read (or the candidates file), for errors.
    pub(super) out: &'a Path,
    pub(super) kept: BTreeMap<usize, Vec<RawLine>>,
    pub(super) written: Mutex<BTreeMap<usize, Vec<RawLine>>>,
    pub(super) progress: &'a dyn Progress,
    /// Where candidates are evaluated when not here.
    pub(super) remote: Option<&'a dyn Evaluator>,
    /// Lines the remote evaluator made for a stage, taken by [`Runner::one`].
    pub(super) prefetched: Mutex<BTreeMap<usize, Vec<RawLine>>>,
}

impl Runner<'_, '_> {
    /// Evaluates `candidates` in parallel (reusing kept lines), as one phase.
    pub(super) fn stage(&self, name: &str, candidates: Vec<Candidate>) -> Result<Vec<Evaluated>, Error> {
        let todo = candidates
            .iter()
            .filter(|c| c.map.is_ok() && !self.kept.contains_key(&c.index))
            .count();
        self.progress.phase(name, todo as u64);
        if self.remote.is_some() {
            let todo: Vec<Candidate> = candidates
                .iter()
                .filter(|c| c.map.is_ok() && !self.kept.contains_key(&c.index))
                .cloned()
                .collect();
            self.fetch(&todo)?;
        }
        let done = candidates
            .into_par_iter()
            .map(|c| self.one(c, true))
            .collect::<Result<Vec<_>, Error>>();
        self.progress.finish();
        done
    }

    /// Evaluates one candidate (or takes its kept lines), appending fresh lines.
    pub(super) fn one(&self, candidate: Candidate, advance: bool) -> Result<Evaluated, Error> {
        let Ok(map) = &candidate.map else {
            return Ok(Evaluated {
                candidate,
                lines: Vec::new(),
            });
        };
        let named = candidate.named_values(self.cfg.space);
        if let Some(kept) = self.kept.get(&candidate.index) {
            if let Some(bad) = kept
                .iter()
                .find(|l| l.parsed.values != named || l.parsed.stage != candidate.stage)
            {
                return Err(Error::Results {
                    path: self.out.to_path_buf(),
                    problem: format!(
                        "--resume: candidate {} in the file has other values or another stage than this run's ({:?} vs {:?}); \
                         give another --out, or leave out --resume to start over",
                        bad.parsed.candidate, bad.parsed.values, named
                    ),
                });
            }
            self.written
                .lock()
                .expect("lines lock")
                .insert(candidate.index, kept.clone());
            let lines = kept.iter().map(|l| l.parsed.clone()).collect();
            return Ok(Evaluated { candidate, lines });
        }
        let remote = if self.remote.is_some() {
            let got = self.prefetched.lock().expect("lines lock").remove(&candidate.index);
            match got {
                Some(raws) => Some(raws),
                None => {
                    self.fetch(std::slice::from_ref(&candidate))?;
                    self.prefetched.lock().expect("lines lock").remove(&candidate.index)
                }
            }
        } else {
            None
        };
        if let Some(raws) = remote {
            if let Some(bad) = raws
                .iter()
                .find(|l| l.parsed.values != named || l.parsed.stage != candidate.stage)
            {
                return Err(Error::Results {
                    path: self.out.to_path_buf(),
                    problem: format!(
                        "candidate {}: the evaluator returned lines of other values or another stage ({:?} vs {:?})",
                        candidate.index, bad.parsed.values, named
                    ),
                });
            }
            return self.write(candidate, raws, advance);
        }
        let lines = evaluate_candidate(self.cfg, &candidate, map, named, self.progress)?;
        let raws: Vec<RawLine> = lines
            .iter()
            .map(|l| {
                let mut raw = serde_json::to_string(l)?;
                raw.push('\n');
                Ok(RawLine { raw, parsed: l.clone() })
            })
            .collect::<Result<_, Error>>()?;
        self.write(candidate, raws, advance)
    }

    /// Appends a candidate's fresh lines to the part and keeps them.
    pub(super) fn write(&self, candidate: Candidate, raws: Vec<RawLine>, advance: bool) -> Result<Evaluated, Error> {
        let lines = raws.iter().map(|r| r.parsed.clone()).collect();
        let text: String = raws.iter().map(|r| r.raw.as_str()).collect();
        self.sink.lock().expect("file lock").append(text.as_bytes())?;
        self.written.lock().expect("lines lock").insert(candidate.index, raws);
        if advance {
            crate::progress::step(self.progress)?;
        }
        Ok(Evaluated { candidate, lines })
    }

    /// Has the remote evaluator make the lines of `candidates`, parsed, for [`Runner::one`].
    pub(super) fn fetch(&self, candidates: &[Candidate]) -> Result<(), Error> {
        let Some(remote) = self.remote else { return Ok(()) };
        if candidates.is_empty() {
            return Ok(());
        }
        if self.progress.cancelled() {
            return Err(Error::Interrupted);
        }
        let wires: Vec<CandidateWire> = candidates.iter().map(CandidateWire::of).collect();
        let got = remote.evaluate(&wires)?;
        let bad = |problem: String| Error::Results {
            path: self.out.to_path_buf(),
            problem,
        };
        if got.len() != candidates.len() {
            return Err(bad(format!(
                "the evaluator returned {} candidates' lines for {}",
                got.len(),
                candidates.len()
            )));
        }
        let need = lines_per_candidate(self.cfg);
        let mut parsed = Vec::with_capacity(got.len());
        for (c, lines) in candidates.iter().zip(got) {
            if lines.len() != need {
                return Err(bad(format!(
                    "candidate {}: the evaluator returned {} lines, expected {need}",
                    c.index,
                    lines.len()
                )));
            }
            let raws = lines
                .into_iter()
                .map(|raw| {
                    let parsed: CandidateLine = serde_json::from_str(raw.trim_end()).map_err(|e| {
                        bad(format!(
                            "candidate {}: the evaluator returned a bad line ({e})",
                            c.index
                        ))
                    })?;
                    if parsed.candidate != c.index || !raw.ends_with('\n') {
                        return Err(bad(format!(
                            "candidate {}: the evaluator returned another candidate's line",
                            c.index
                        )));
                    }
                    Ok(RawLine { raw, parsed })
                })
                .collect::<Result<Vec<_>, Error>>()?;
            parsed.push((c.index, raws));
        }
        self.prefetched.lock().expect("lines lock").extend(parsed);
        Ok(())
    }
}

/// One evaluation of a candidate: its role, method, agent, training seed and figures.
type Run<'a> = (Role, Method, Option<&'a Agent>, Option<u64>, Aggregate);

/// Evaluates a candidate's map: the two witnesses, then the method for each training
/// seed, `episodes` episodes each; its lines carry the fairness and failure verdicts.
/// Stops between episodes ([`Error::Interrupted`]) when `cancel` asks; its phase is not
/// advanced.
pub fn evaluate_candidate(
    cfg: &SearchConfig<'_>,
    candidate: &Candidate,
    map: &Map,
    values: Vec<(String, Value)>,
    cancel: &dyn Progress,
) -> Result<Vec<CandidateLine>, Error> {
    let cancel = CancelOnly(cancel);
    let params = crate::overrides::on_map(map, [])?;
    let scripted = |m: Method| -> Result<Aggregate, Error> {
        Ok(Aggregate::of(&run_scripted_episodes(
            map,
            m,
            cfg.episodes,
            cfg.seed,
            &cancel,
        )?))
    };
    let (careful, brake) = careful_witness(map, cfg.episodes, cfg.seed, &cancel)?;
    let careful_cruise = CarefulCruise {
        fraction: careful.cruise,
        speed_mps: at_cruise(map, careful.cruise).vehicle.max_speed,
        success_rate: careful.success_rate,
    };
    let never = scripted(Method::NeverBrake)?;
    let fair = Fairness::of(brake.success_rate, never.success_rate);
    let mut runs: Vec<Run<'_>> = vec![
        (Role::SurvivableWitness, Method::BrakeOnPedestrian, None, None, brake),
        (Role::DangerousWitness, Method::NeverBrake, None, None, never),
    ];
    for &seed in cfg.train_seeds {
        let (agent, agg) = if cfg.method.is_scripted() {
            (None, scripted(cfg.method)?)
        } else {
            let agent = cfg
                .agents
                .iter()
                .find(|a| a.train_seed == seed)
                .ok_or(Error::MissingAgent { train_seed: seed })?;
            let results = run_agent_episodes(
                cfg.protocol,
                map,
                &agent.bundle,
                &params,
                cfg.method,
                cfg.episodes,
                cfg.seed,
                &cancel,
            )?;
            (Some(agent), Aggregate::of(&results))
        };
        runs.push((Role::Method, cfg.method, agent, seed, agg));
    }
    Ok(runs
        .into_iter()
        .map(|(role, method, agent, train_seed, agg)| {
            let result = result_line(cfg, candidate, map, method, agent, train_seed, &params, &agg);
            CandidateLine {
                candidate: candidate.index,
                stage: candidate.stage,
                role,
                values: values.clone(),
                fairness: fair,
                fails: role == Role::Method && fair.is_fair() && fairness::fails(agg.success_rate),
                careful_cruise: Some(careful_cruise),
                result,
            }
        })
        .collect())
}

/// The batch line of one evaluation (the same fields `batch` writes).
#[allow(clippy::too_many_arguments)]
fn result_line(
    cfg: &SearchConfig<'_>,
    candidate: &Candidate,
    map: &Map,
    method: Method,
    agent: Option<&Agent>,
    train_seed: Option<u64>,
    params: &ScaledParams,
    agg: &Aggregate,
) -> ResultLine {
    let label = UnitLabel {
        unit: candidate.index,
        scenario: map.name.clone(),
        source: format!("search:{}", cfg.space.source),
        method: method.name().into(),
        param_set: "default".into(),
        params: Vec::new(),
        protocol: cfg.protocol,
        covers: covered(method, params, cfg.protocol, &[cfg.protocol]),
        train_seed,
        train_episodes: agent.and_then(|a| a.train_episodes),
        seed: cfg.seed,
    };
    ResultLine::new(label, agg, method.reasoning_tree(params), Vec::new(), Vec::new())
}
