//! `--resume`: the complete candidates of an earlier run of the same search, checked
//! line by line.

use super::*;
use crate::runs::resume::{ReadLine, START_OVER, read_lines};

/// The lines of a candidate, complete: two witnesses and one method line per seed.
pub(super) fn lines_per_candidate(cfg: &SearchConfig<'_>) -> usize {
    2 + cfg.train_seeds.len()
}

/// Reads the complete candidates of `out` for `--resume` (see the module doc).
pub(super) fn resume_lines(cfg: &SearchConfig<'_>, out: &Path) -> Result<BTreeMap<usize, Vec<RawLine>>, Error> {
    let bad = |problem: String| Error::Results {
        path: out.to_path_buf(),
        problem,
    };
    let fix = START_OVER;
    let lines = read_lines::<SearchIdentity, CandidateLine>(out, "search", &cfg.identity(), "a candidate line")?;
    let mut by: BTreeMap<usize, Vec<RawLine>> = BTreeMap::new();
    for ReadLine { line, raw, parsed } in lines {
        if let Some(problem) = kept_line_problem(cfg, &parsed, &raw) {
            return Err(bad(format!(
                "--resume: line {line} (candidate {}, {:?}) {problem}; {fix}",
                parsed.candidate, parsed.role
            )));
        }
        let entry = by.entry(parsed.candidate).or_default();
        if entry
            .iter()
            .any(|l| (l.parsed.role, l.parsed.result.train_seed) == (parsed.role, parsed.result.train_seed))
        {
            return Err(bad(format!(
                "line {line}: candidate {} {:?} is in the file twice; remove one of its lines",
                parsed.candidate, parsed.role
            )));
        }
        entry.push(RawLine { raw, parsed });
    }
    // Only complete candidates are kept: a candidate cut by a kill runs again.
    let need = lines_per_candidate(cfg);
    by.retain(|_, v| v.len() == need);
    for (candidate, v) in by.iter_mut() {
        v.sort_by_key(|l| (l.parsed.role, l.parsed.result.train_seed));
        // The verdicts follow from the witnesses' figures, on every line alike.
        let fair = Fairness::of(v[0].parsed.result.success_rate, v[1].parsed.result.success_rate);
        if let Some(l) = v.iter().find(|l| {
            l.parsed.fairness != fair
                || l.parsed.values != v[0].parsed.values
                || l.parsed.stage != v[0].parsed.stage
                || l.parsed.fails
                    != (l.parsed.role == Role::Method
                        && fair.is_fair()
                        && fairness::fails(l.parsed.result.success_rate))
        }) {
            return Err(bad(format!(
                "--resume: candidate {candidate} ({:?} line): its fairness, failure verdict, stage or values do not follow from its lines (fairness {:?} from the witnesses); {fix}",
                l.parsed.role, fair
            )));
        }
    }
    Ok(by)
}

/// What is wrong with a kept candidate line `l` (read from `raw`) as a line of the
/// search `cfg`: fields this program does not write, a field of the batch line that is
/// not this search's (unit, scenario, source, method, protocol, training seed, seed,
/// episodes, parameters), or a figure out of range (as `batch --resume` checks them).
fn kept_line_problem(cfg: &SearchConfig<'_>, l: &CandidateLine, raw: &str) -> Option<String> {
    let written = serde_json::to_value(l).ok();
    if written != serde_json::from_str::<serde_json::Value>(raw.trim_end()).ok() {
        return Some("is not a line this program writes (an unknown or edited field)".into());
    }
    let r = &l.result;
    let method = match l.role {
        Role::SurvivableWitness => Method::BrakeOnPedestrian,
        Role::DangerousWitness => Method::NeverBrake,
        Role::Method => cfg.method,
    };
    let seed_ok = match l.role {
        Role::Method => cfg.train_seeds.contains(&r.train_seed),
        _ => r.train_seed.is_none(),
    };
    let expected = [
        ("unit", r.unit == l.candidate),
        ("scenario", r.scenario == candidate_name(cfg.space, l.candidate)),
        ("source", r.source == format!("search:{}", cfg.space.source)),
        ("method", r.method == method.name()),
        ("protocol", r.protocol == cfg.protocol && r.covers == [cfg.protocol]),
        ("train_seed", seed_ok),
        ("seed", r.seed == cfg.seed),
        ("episodes", r.episodes == cfg.episodes),
        ("param_set", r.param_set == "default" && r.params.is_empty()),
    ];
    if let Some((field, _)) = expected.iter().find(|(_, ok)| !ok) {
        return Some(format!("has a {field} that is not this search's"));
    }
    crate::runs::batch::results_file::figures_problem(r)
}
