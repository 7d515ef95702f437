//! Merging the shard files of one batch run, produced anywhere (`--shard i/n` on a Slurm
//! array, a Kubernetes indexed job, GNU parallel, or the tasks of a Ray cluster), into the
//! file one machine would have written.
//!
//! Every results file starts with the [`RunIdentity`] of its run (the shard is not part of
//! it), and the identity says everything that determines the run's units: its scenarios,
//! methods, parameter sets, protocols and training seeds. So [`merge`] recomputes the
//! run's units from the parts alone, checks that every part was written by the same run
//! (saying what differs), that every line is a unit of it with the run's fields, that no
//! unit is in two places, and that every unit is somewhere (naming the ones that are
//! not). [`write_merged`] then writes the lines in canonical order, byte for byte as
//! their parts hold them, and the summary over training seeds beside them, each file
//! atomically: a merge that fails leaves no half-written file.
//!
//! A search's candidates and an estimate's draws are refused, saying how their shards
//! are merged: concatenated, then finished by the command's `--resume`, which walks the
//! run's stages again from the lines (each stage depends on the earlier ones' results).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::episodes::methods::Method;
use crate::error::Error;
use crate::runs::batch::results_file::line_problem;
use crate::runs::batch::{
    KeptLine, ParamSet, ResultLine, RunIdentity, SummaryRow, Unit, UnitKey, read_results, stream_learning, summarize,
    units,
};
use crate::runs::file_kinds::Held;
use crate::runs::outputs::summary_path;

/// The merged results of one run.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The run's identity (the first line of every part).
    pub identity: RunIdentity,
    /// Every line of the run, in canonical unit order, each as its part holds it.
    pub lines: Vec<KeptLine>,
}

impl Merged {
    /// The parsed result lines, in canonical order.
    pub fn results(&self) -> Vec<ResultLine> {
        self.lines.iter().map(|l| l.parsed.clone()).collect()
    }
}

/// What [`write_merged`] wrote.
#[derive(Debug, Clone)]
pub struct MergeReport {
    /// The merged results file.
    pub out: PathBuf,
    /// The summary beside it ([`summary_path`]).
    pub summary: PathBuf,
    /// The summary rows (one per scenario, method, parameter set and protocol).
    pub rows: Vec<SummaryRow>,
    /// Expectations checked on the mean over training seeds.
    pub checked: usize,
    /// How many of them failed.
    pub failed: usize,
}

/// The parameter set whose [`ParamSet::label`] is `label` (`default`, or `k=v,k=v`).
fn param_set_of(label: &str) -> Option<ParamSet> {
    if label == "default" {
        return Some(ParamSet(Vec::new()));
    }
    let pairs: Option<Vec<(String, String)>> = label
        .split(',')
        .map(|kv| kv.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect();
    let set = ParamSet(pairs?);
    (set.label() == label).then_some(set)
}

/// The units of the run `identity` describes, in canonical order (as
/// [`crate::runs::batch::BatchConfig::units`] gives them for that run), with their keys.
pub fn units_of(identity: &RunIdentity) -> Result<Vec<(Unit, UnitKey)>, String> {
    let methods = identity
        .methods
        .iter()
        .map(|m| {
            m.parse::<Method>()
                .map_err(|e| format!("its identity names method {m:?}: {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let params = identity
        .param_sets
        .iter()
        .map(|p| param_set_of(p).ok_or_else(|| format!("its identity has parameter set {p:?}, not KEY=VALUE,...")))
        .collect::<Result<Vec<_>, _>>()?;
    let all = units(
        identity.maps.len(),
        &methods,
        &params,
        &identity.protocols,
        &identity.train_seeds,
    )
    .map_err(|e| format!("its identity's parameter sets do not apply: {}", e.full_message()))?;
    Ok(all
        .into_iter()
        .map(|u| {
            let key = (
                identity.maps[u.scenario].0.clone(),
                u.method.name().to_string(),
                u.params.label(),
                u.protocol,
                u.train_seed,
            );
            (u, key)
        })
        .collect())
}

/// `unit 3 (jaywalk scaled default zero-shot, training seed 2)`.
fn unit_text(index: usize, key: &UnitKey) -> String {
    let seed = key.4.map_or_else(|| "none".to_string(), |s| s.to_string());
    format!(
        "unit {index} ({} {} {} {}, training seed {seed})",
        key.0,
        key.1,
        key.2,
        key.3.name()
    )
}

/// Most missing units named one by one in an error (the rest are counted).
const MAX_NAMED: usize = 12;

/// The missing units as ranges of positions, the first [`MAX_NAMED`] of them named.
fn missing_text(missing: &[usize], all: &[(Unit, UnitKey)], place: &str) -> String {
    let mut ranges: Vec<(usize, usize)> = Vec::new();
    for &i in missing {
        match ranges.last_mut() {
            Some((_, end)) if *end + 1 == i => *end = i,
            _ => ranges.push((i, i)),
        }
    }
    let positions: Vec<String> = ranges
        .iter()
        .map(|&(a, b)| if a == b { a.to_string() } else { format!("{a}-{b}") })
        .collect();
    let named: Vec<String> = missing
        .iter()
        .take(MAX_NAMED)
        .map(|&i| unit_text(i, &all[i].1))
        .collect();
    let more = missing.len().saturating_sub(MAX_NAMED);
    format!(
        "units {} are {place}: {}{}",
        positions.join(", "),
        named.join("; "),
        if more > 0 {
            format!("; and {more} more")
        } else {
            String::new()
        }
    )
}

/// What a reader of one results file checks before it reports on the run the file's
/// identity names ([`read_run`]): the units of that run missing from `lines` (a shard,
/// a run cut short), as `(missing, units of the run, text naming them)`; `None` when
/// every unit is there.
pub fn missing_units(identity: &RunIdentity, lines: &[ResultLine]) -> Result<Option<(usize, usize, String)>, String> {
    let all = units_of(identity)?;
    let present: std::collections::BTreeSet<usize> = lines
        .iter()
        .filter(|l| all.get(l.unit).is_some_and(|(_, key)| *key == l.key()))
        .map(|l| l.unit)
        .collect();
    let missing: Vec<usize> = (0..all.len()).filter(|i| !present.contains(i)).collect();
    Ok((!missing.is_empty()).then(|| {
        (
            missing.len(),
            all.len(),
            missing_text(&missing, &all, "not in the file"),
        )
    }))
}

/// A results file as a reader that reports on the run its first line names sees it
/// ([`read_run`]).
#[derive(Debug, Clone, Default)]
pub struct RunLines {
    /// The result lines, each unit once (its first line).
    pub lines: Vec<ResultLine>,
    /// The number of the last line when it was cut (no newline: a killed run or a full
    /// disk); it is not read.
    pub cut_line: Option<usize>,
    /// Lines left out because they repeat a unit read already.
    pub repeated: usize,
    /// When read with `partial`: which units of the run are missing (`N of the run's M
    /// units are missing: ...`).
    pub missing: Option<String>,
}

/// Reads the results file `path` for a reader that reports on the run its identity names
/// (`plot-sweep`, Python's `summarize`): refuses a file holding two runs (two different
/// `{"run": ...}` lines: concatenated results of different runs), and, unless `partial`,
/// a file missing units of its run (a shard, a run cut short), listing them. Lines of
/// no unit of the run (Python's `evaluate(append=True)` beside a batch run's) are read
/// with the rest; a file without an identity (result lines alone) names no run and is
/// read whole.
pub fn read_run(path: &Path, partial: bool) -> Result<RunLines, Error> {
    let file = read_results(path)?;
    let bad = |problem: String| Error::Results {
        path: path.to_path_buf(),
        problem,
    };
    if let Some((first_line, first)) = file.identities.first()
        && let Some((line, other)) = file.identities.iter().find(|(_, id)| id != first)
    {
        return Err(bad(format!(
            "holds two runs (line {line} differs from line {first_line}: {}); read each run's results file on its own",
            other.differences(first).join("; ")
        )));
    }
    let mut seen = std::collections::BTreeSet::new();
    let mut run = RunLines {
        cut_line: file.cut_line,
        ..RunLines::default()
    };
    for l in file.lines {
        if seen.insert((l.parsed.unit, l.parsed.key())) {
            run.lines.push(l.parsed);
        } else {
            run.repeated += 1;
        }
    }
    if let Some((_, identity)) = file.identities.first()
        && let Some((n, total, text)) = missing_units(identity, &run.lines).map_err(bad)?
    {
        let what = format!("{n} of the run's {total} units are missing: {text}");
        if !partial {
            return Err(bad(format!(
                "{what}; read the whole run (`unforeseen merge` its shards, or `unforeseen batch --resume`), or add --partial (partial=True) to read what is there"
            )));
        }
        run.missing = Some(what);
    }
    Ok(run)
}

/// Reads the parts and merges them into the lines of their run, in canonical order.
///
/// Refuses (an [`Error::Results`] naming the part, or an [`Error::Flag`] about the parts
/// together, saying what to do) a part that is not a results file or has no identity,
/// parts of different runs (saying what differs), a line that is not a unit of the run or
/// whose fields are not the run's, a unit in two places (naming both), and a run not
/// covered (naming the missing units). A part whose last line was cut (a killed shard)
/// loses that line, so its unit is missing.
pub fn merge(parts: &[PathBuf]) -> Result<Merged, Error> {
    let flag = "PART";
    if parts.is_empty() {
        return Err(Error::flag(
            flag,
            "no results files given; give the shard files, e.g. unforeseen merge part-*.jsonl --out sweep.jsonl",
        ));
    }
    let mut identity: Option<(PathBuf, RunIdentity)> = None;
    let mut all: Vec<(Unit, UnitKey)> = Vec::new();
    // Unit position -> (part, line number, line).
    let mut found: BTreeMap<usize, (PathBuf, usize, KeptLine)> = BTreeMap::new();
    let mut cut: Vec<String> = Vec::new();
    let mut seen: Vec<(PathBuf, &PathBuf)> = Vec::new();
    for part in parts {
        if !part.exists() {
            return Err(Error::flag(
                flag,
                format!("{}: no such file; give the shard files the run wrote", part.display()),
            ));
        }
        if !part.is_file() {
            return Err(Error::flag(
                flag,
                format!(
                    "{}: not a regular file (a folder, a pipe, a device); give the shard files the run wrote",
                    part.display()
                ),
            ));
        }
        let real = std::fs::canonicalize(part).map_err(|e| Error::io("read", part, e))?;
        if let Some((_, first)) = seen.iter().find(|(r, _)| *r == real) {
            return Err(Error::flag(
                flag,
                format!(
                    "{} is given twice (also as {}); give each shard file once",
                    part.display(),
                    first.display()
                ),
            ));
        }
        seen.push((real, part));
        if let Some((command, file)) = merged_by_resume(part) {
            return Err(Error::Results {
                path: part.clone(),
                problem: format!(
                    "holds {}: `merge` joins a batch run's shards; concatenate the {command}'s shard files into \
                     its --out as {file} and finish with `unforeseen {command} --resume`",
                    Held::of(part).describe()
                ),
            });
        }
        let file = read_results(part)?;
        let Some((first_line, first)) = file.identities.first() else {
            return Err(Error::Results {
                path: part.clone(),
                problem: "no run identity (its first line is not {\"run\": ...}): not a results file of `unforeseen batch`; give the files its shards wrote".into(),
            });
        };
        if let Some((line, other)) = file.identities.iter().find(|(_, id)| id != first) {
            return Err(Error::Results {
                path: part.clone(),
                problem: format!(
                    "mixes two runs (line {line} differs from line {first_line}: {}); give parts of one run",
                    other.differences(first).join("; ")
                ),
            });
        }
        match &identity {
            None => {
                all = units_of(first).map_err(|problem| Error::Results {
                    path: part.clone(),
                    problem: format!("{problem}; give results files written by `unforeseen batch`"),
                })?;
                identity = Some((part.clone(), first.clone()));
            }
            Some((path, id)) if id != first => {
                return Err(Error::Results {
                    path: part.clone(),
                    problem: format!(
                        "written by another run than {} ({}); merge only the parts of one run",
                        path.display(),
                        first
                            .differences(id)
                            .join("; ")
                            .replace("the file has", "this part has")
                            .replace("this run", "the other")
                    ),
                });
            }
            Some(_) => {}
        }
        let (_, run) = identity.as_ref().expect("set above");
        if let Some(line) = file.cut_line {
            cut.push(format!("{} (line {line})", part.display()));
        }
        for l in file.lines {
            let bad = |problem: String| Error::Results {
                path: part.clone(),
                problem: format!(
                    "line {} (unit {}, {} {} {}) {problem}; give the files the run's shards wrote, unedited",
                    l.line, l.parsed.unit, l.parsed.scenario, l.parsed.method, l.parsed.param_set
                ),
            };
            let Some((unit, _)) = all.get(l.parsed.unit).filter(|(_, key)| *key == l.parsed.key()) else {
                return Err(bad("is not a unit of this run".into()));
            };
            if let Some(problem) = line_problem(&l.parsed, unit, run) {
                return Err(bad(problem));
            }
            if let Some((other, other_line, _)) = found.get(&l.parsed.unit) {
                return Err(Error::flag(
                    flag,
                    format!(
                        "{} is in two places, {} line {other_line} and {} line {}: the parts overlap; give each shard's file once (shards of one --shard I/N split do not overlap)",
                        unit_text(l.parsed.unit, &all[l.parsed.unit].1),
                        other.display(),
                        part.display(),
                        l.line
                    ),
                ));
            }
            found.insert(l.parsed.unit, (part.clone(), l.line, l));
        }
    }
    let (_, identity) = identity.expect("at least one part");
    let missing: Vec<usize> = (0..all.len()).filter(|i| !found.contains_key(i)).collect();
    if !missing.is_empty() {
        let cut = if cut.is_empty() {
            String::new()
        } else {
            format!(
                " ({} ended in a cut line: a shard killed while writing)",
                cut.join(", ")
            )
        };
        return Err(Error::flag(
            flag,
            format!(
                "the parts do not cover the run: it has {} units, {} {}{cut}; run the missing shards (or `unforeseen batch --resume` on a part) and merge again",
                all.len(),
                found.len(),
                missing_text(&missing, &all, "in no part")
            ),
        ));
    }
    Ok(Merged {
        identity,
        lines: found.into_values().map(|(_, _, l)| l).collect(),
    })
}

/// The command whose `--resume` merges the shards of the run that wrote `part`, and the
/// file its shards are concatenated into, when that run is not a batch: a search's
/// candidates and an estimate's draws come in stages that the command walks again from
/// the lines (the later stages depend on the earlier ones' results), so their shards'
/// files concatenated and resumed are the merge.
fn merged_by_resume(part: &Path) -> Option<(&'static str, &'static str)> {
    match Held::of(part) {
        Held::Candidates => Some(("search", "candidates.jsonl")),
        Held::Estimates => Some(("estimate", "estimate.jsonl")),
        _ => None,
    }
}

/// The summary file of a run's results (as `unforeseen batch` writes it beside
/// `results`): the rows over training seeds and the expectations checked on their means,
/// and for a stream run under both protocols what learning does to each map within it
/// (`learning`, [`stream_learning`]; left out otherwise).
pub fn summary_document(
    results: &Path,
    shard: Option<&str>,
    identity: &RunIdentity,
    rows: &[SummaryRow],
) -> serde_json::Value {
    let checked: usize = rows.iter().map(|r| r.checks.len()).sum();
    let failed: usize = rows.iter().map(|r| r.checks.iter().filter(|c| !c.pass).count()).sum();
    let mut doc = serde_json::json!({
        "schema": 1,
        "results": results.display().to_string(),
        "shard": shard,
        "run": identity,
        "checked": checked,
        "failed": failed,
        "rows": rows,
    });
    let learning = stream_learning(rows);
    if !learning.is_empty() {
        doc["learning"] = serde_json::json!(learning);
    }
    doc
}

/// Writes the merged results to `out` (the identity, then every line in canonical order)
/// and the summary beside it ([`summary_path`]), each atomically.
pub fn write_merged(merged: &Merged, out: &Path) -> Result<MergeReport, Error> {
    let text: String = std::iter::once(merged.identity.to_line())
        .chain(merged.lines.iter().map(|l| l.raw.clone()))
        .collect();
    let rows = summarize(&merged.results());
    let summary = summary_path(out);
    let doc = summary_document(out, None, &merged.identity, &rows);
    crate::files::all_or_none(|| {
        crate::files::write_atomic(out, text.as_bytes())?;
        crate::files::write_json(&summary, &doc)
    })?;
    Ok(MergeReport {
        out: out.to_path_buf(),
        summary,
        checked: doc["checked"].as_u64().unwrap_or(0) as usize,
        failed: doc["failed"].as_u64().unwrap_or(0) as usize,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameter_set_labels_read_back() {
        assert_eq!(param_set_of("default"), Some(ParamSet(Vec::new())));
        let set = param_set_of("horizon=2,omega=0.2").unwrap();
        assert_eq!(set.label(), "horizon=2,omega=0.2");
        assert_eq!(set.0.len(), 2);
        assert_eq!(param_set_of("horizon"), None);
    }
}
