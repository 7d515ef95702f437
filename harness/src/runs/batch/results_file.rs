//! Reading a results file back: its identity and lines, the lines `--resume` keeps, and
//! the checks that each kept line is a line of this run with figures in range.

use std::collections::BTreeSet;
use std::path::Path;

use crate::error::Error;

use super::identity::{IdentityLine, RunIdentity};
use super::result_line::ResultLine;
use super::scenario::Scenario;
use super::units::Unit;
use crate::episodes::metrics::MarginFigures;

/// A result line read back from a results file, with its text as written.
#[derive(Debug, Clone, PartialEq)]
pub struct KeptLine {
    /// 1-based line number in the file.
    pub line: usize,
    /// The text of the line, newline included, kept byte for byte.
    pub raw: String,
    /// The parsed line.
    pub parsed: ResultLine,
}

/// The complete lines of a results file: its run identities (one, or one per
/// concatenated shard) and its result lines.
#[derive(Debug, Clone, Default)]
pub struct ResultsFile {
    /// Identity lines, with their line numbers.
    pub identities: Vec<(usize, RunIdentity)>,
    /// Result lines.
    pub lines: Vec<KeptLine>,
    /// The number of the last line when it was cut (no newline at the end: a killed
    /// run or a full disk); it is not read.
    pub cut_line: Option<usize>,
}

fn results_error(path: &Path, problem: String) -> Error {
    Error::Results {
        path: path.to_path_buf(),
        problem,
    }
}

/// Reads the complete lines of a results file (a missing file has none; a truncated last
/// line from a killed run or a full disk is dropped, whatever byte it ends on, even
/// inside a UTF-8 character, so that unit runs again: [`ResultsFile::cut_line`]). A
/// complete line that is not UTF-8 text (a binary file) is refused.
pub fn read_results(path: &Path) -> Result<ResultsFile, Error> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(ResultsFile::default()),
        Ok(m) if !m.is_file() => {
            return Err(Error::NotRegularFile {
                path: path.to_path_buf(),
            });
        }
        _ => {}
    }
    let bytes = std::fs::read(path).map_err(|e| Error::io("read", path, e))?;
    let mut file = ResultsFile::default();
    for (i, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        if !raw.ends_with(b"\n") {
            file.cut_line = Some(i + 1); // truncated by a kill or a full disk: redo that unit
            break;
        }
        let Ok(raw) = std::str::from_utf8(raw) else {
            return Err(results_error(
                path,
                format!(
                    "line {}: not text (invalid UTF-8): not a batch results file; give the results file `unforeseen batch` wrote",
                    i + 1
                ),
            ));
        };
        let body = raw.trim_end();
        if body.starts_with("{\"run\":") {
            let id: IdentityLine = serde_json::from_str(body).map_err(|e| {
                results_error(
                    path,
                    format!("line {}: not a run identity ({e}); remove the line or the file", i + 1),
                )
            })?;
            file.identities.push((i + 1, id.run));
            continue;
        }
        let parsed: ResultLine = serde_json::from_str(body).map_err(|e| {
            results_error(
                path,
                format!(
                    "line {}: not a batch result line ({e}); remove the line or the file",
                    i + 1
                ),
            )
        })?;
        file.lines.push(KeptLine {
            line: i + 1,
            raw: raw.to_string(),
            parsed,
        });
    }
    Ok(file)
}

/// The result lines of a results file (see [`read_results`]).
pub fn read_lines(path: &Path) -> Result<Vec<ResultLine>, Error> {
    Ok(read_results(path)?.lines.into_iter().map(|l| l.parsed).collect())
}

/// The lines of `out` that `--resume` keeps for a run of identity `identity` and units
/// `units`: refuses a file written by another run (saying what differs), a file that
/// mixes runs or lacks an identity, and lines that are not units of this run or repeat one.
pub fn resume_lines(
    out: &Path,
    identity: &RunIdentity,
    units: &[Unit],
    scenarios: &[Scenario],
) -> Result<Vec<KeptLine>, Error> {
    let file = read_results(out)?;
    let fix = "give another --out, or leave out --resume to start it over (the file is replaced)";
    let Some((first_line, first)) = file.identities.first() else {
        if file.lines.is_empty() {
            return Ok(Vec::new());
        }
        return Err(results_error(
            out,
            format!("--resume: the file does not say which run wrote it (no identity line; an older version?); {fix}"),
        ));
    };
    if let Some((line, other)) = file.identities.iter().find(|(_, id)| id != first) {
        return Err(results_error(
            out,
            format!(
                "--resume: the file mixes two runs (line {line} differs from line {first_line}: {}); {fix}",
                other.differences(first).join("; ")
            ),
        ));
    }
    if first != identity {
        return Err(results_error(
            out,
            format!(
                "--resume: the file was written by another run ({}); {fix}",
                first.differences(identity).join("; ")
            ),
        ));
    }
    let mut seen: BTreeSet<usize> = BTreeSet::new();
    for l in &file.lines {
        let unit = units.get(l.parsed.unit).filter(|u| u.key(scenarios) == l.parsed.key());
        if let Some(u) = unit
            && let Some(problem) = line_problem(&l.parsed, u, identity)
        {
            return Err(results_error(
                out,
                format!(
                    "--resume: line {} (unit {}, {} {} {}) {problem}; {fix}",
                    l.line, l.parsed.unit, l.parsed.scenario, l.parsed.method, l.parsed.param_set
                ),
            ));
        }
        if unit.is_none() {
            return Err(results_error(
                out,
                format!(
                    "line {}: unit {} ({} {} {}) is not a unit of this run; {fix}",
                    l.line, l.parsed.unit, l.parsed.scenario, l.parsed.method, l.parsed.param_set
                ),
            ));
        }
        if !seen.insert(l.parsed.unit) {
            return Err(results_error(
                out,
                format!(
                    "line {}: unit {} is in the file twice; remove one of its lines",
                    l.line, l.parsed.unit
                ),
            ));
        }
    }
    Ok(file.lines)
}

/// Largest magnitude a figure of a result line may have (a return, ticks, µs per tick):
/// far above what any map allows, far below what only a corrupt line holds.
pub const MAX_FIGURE: f64 = 1e9;

/// What is wrong with result line `l` as the line of unit `u` of the run `identity`: a
/// field of its own that is not this run's (seed, episodes, parameters,
/// protocols covered), or a figure out of its range (rates in [0, 1]; others finite,
/// non-negative where they count, at most [`MAX_FIGURE`] in magnitude), its own or of a
/// map within a stream (whose episodes must add up to the line's).
pub(crate) fn line_problem(l: &ResultLine, u: &Unit, identity: &RunIdentity) -> Option<String> {
    if l.seed != identity.seed {
        return Some(format!("has seed {}, the run's header {}", l.seed, identity.seed));
    }
    if l.episodes != identity.episodes {
        return Some(format!(
            "has {} episodes, the run's header {}",
            l.episodes, identity.episodes
        ));
    }
    if l.params != u.params.0 {
        return Some(format!(
            "has parameters {:?}, the unit's are {:?}",
            l.params, u.params.0
        ));
    }
    if l.covers != u.covers {
        return Some(format!("covers {:?}, the unit covers {:?}", l.covers, u.covers));
    }
    figures_problem(l)
}

/// What is wrong with the figures of result line `l` (its own, and those of each map
/// within a stream, whose episodes must add up to the line's): rates in [0, 1]; others
/// finite, non-negative where they count, at most [`MAX_FIGURE`] in magnitude. `batch
/// --resume`, `merge` and `search --resume` check every kept line with it.
pub(crate) fn figures_problem(l: &ResultLine) -> Option<String> {
    let own = figure_problem(
        "",
        [l.success_rate, l.collision_rate, l.timeout_rate, l.inference_rate],
        [l.efe_matvecs_per_tick, l.mean_ticks, l.timing_us_per_tick],
        l.mean_reward,
    )
    .or_else(|| margins_problem("", &l.margins));
    if own.is_some() {
        return own;
    }
    if !l.per_map.is_empty() {
        let total: u64 = l.per_map.iter().map(|f| f.episodes).sum();
        if total != l.episodes {
            return Some(format!(
                "has per_map episodes adding up to {total}, the line's {}",
                l.episodes
            ));
        }
    }
    l.per_map.iter().find_map(|f| {
        figure_problem(
            &format!("per_map {}: ", f.map),
            [f.success_rate, f.collision_rate, f.timeout_rate, f.inference_rate],
            [f.efe_matvecs_per_tick, f.mean_ticks, f.timing_us_per_tick],
            f.mean_reward,
        )
        .or_else(|| margins_problem(&format!("per_map {}: ", f.map), &f.margins))
    })
}

/// What is wrong with a line's (or one of its maps', `prefix`) margins
/// (docs/ARCHITECTURE.md §2, "Margins"): the clearances, the TTC and the PET, where given,
/// outside [0, [`MAX_FIGURE`]], the stopping margin not finite within ±[`MAX_FIGURE`], or
/// the share that could stop outside [0, 1].
fn margins_problem(prefix: &str, m: &MarginFigures) -> Option<String> {
    let (stop, could_stop) = (m.min_stop_margin_m, m.could_stop_rate);
    for (name, x) in [
        ("min_clearance_m", m.min_clearance_m),
        ("min_vehicle_clearance_m", m.min_vehicle_clearance_m),
        ("min_ttc_s", m.min_ttc_s),
        ("min_pet_s", m.min_pet_s),
    ] {
        if let Some(x) = x.filter(|x| !(0.0..=MAX_FIGURE).contains(x)) {
            return Some(format!("has {prefix}{name} {x}, outside [0, {MAX_FIGURE:e}]"));
        }
    }
    if let Some(x) = stop.filter(|x| !(x.is_finite() && x.abs() <= MAX_FIGURE)) {
        return Some(format!(
            "has {prefix}min_stop_margin_m {x}, not finite within ±{MAX_FIGURE:e}"
        ));
    }
    (!(0.0..=1.0).contains(&could_stop)).then(|| format!("has {prefix}could_stop_rate {could_stop}, outside [0, 1]"))
}

/// What is wrong with a line's (or one of its maps', `prefix`) figures: the rates
/// (success, collision, time-out, inference) outside [0, 1], the counts (EFE mat-vecs,
/// ticks, µs per tick) outside [0, [`MAX_FIGURE`]], or a return not finite within it.
fn figure_problem(prefix: &str, rates: [f64; 4], counts: [f64; 3], reward: f64) -> Option<String> {
    let rate_names = ["success_rate", "collision_rate", "timeout_rate", "inference_rate"];
    for (name, x) in rate_names.into_iter().zip(rates) {
        if !(0.0..=1.0).contains(&x) {
            return Some(format!("has {prefix}{name} {x}, outside [0, 1]"));
        }
    }
    let count_names = ["efe_matvecs_per_tick", "mean_ticks", "timing_us_per_tick"];
    for (name, x) in count_names.into_iter().zip(counts) {
        if !(0.0..=MAX_FIGURE).contains(&x) {
            return Some(format!("has {prefix}{name} {x}, outside [0, {MAX_FIGURE:e}]"));
        }
    }
    if !(reward.is_finite() && reward.abs() <= MAX_FIGURE) {
        return Some(format!(
            "has {prefix}mean_reward {reward}, not a finite return within ±{MAX_FIGURE:e}"
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn margins_out_of_their_ranges_are_named() {
        let m = |clearance, ttc, stop, could_stop_rate| MarginFigures {
            min_clearance_m: clearance,
            min_ttc_s: ttc,
            min_stop_margin_m: stop,
            could_stop_rate,
            ..MarginFigures::default()
        };
        assert_eq!(margins_problem("", &m(Some(2.3), None, Some(-4.0), 0.5)), None);
        assert_eq!(margins_problem("", &m(None, None, None, 1.0)), None);
        let named = |m: MarginFigures| margins_problem("p: ", &m).unwrap_or_default();
        assert!(named(m(Some(-0.1), None, None, 1.0)).contains("p: min_clearance_m -0.1"));
        assert!(named(m(None, Some(f64::NAN), None, 1.0)).contains("min_ttc_s NaN"));
        assert!(named(m(None, None, Some(f64::INFINITY), 1.0)).contains("min_stop_margin_m inf"));
        assert!(named(m(None, None, None, 1.5)).contains("could_stop_rate 1.5"));
        let pet = MarginFigures {
            min_pet_s: Some(-1.0),
            ..MarginFigures::default()
        };
        assert!(named(pet).contains("min_pet_s -1"));
        let vehicle = MarginFigures {
            min_vehicle_clearance_m: Some(f64::NAN),
            ..MarginFigures::default()
        };
        assert!(named(vehicle).contains("min_vehicle_clearance_m NaN"));
    }
}
