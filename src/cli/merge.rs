//! `unforeseen merge`: join the shard files of one batch run, produced anywhere, into the
//! results file and summary one machine would have written ([`unforeseen_harness::runs::merge`]).

use clap::Args;
use std::path::PathBuf;

use super::batch::print_summary;
use unforeseen_harness::runs::batch::expectation_failures;
use unforeseen_harness::runs::merge::{merge, write_merged};
use unforeseen_harness::runs::outputs::Outputs;

/// Arguments of `merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// The shard files (`unforeseen batch --shard I/N --out part-I.jsonl`), in any order.
    #[arg(value_name = "PART", required = true)]
    pub parts: Vec<PathBuf>,
    /// Merged results file; the summary goes beside it (`sweep.summary.json`).
    #[arg(long, value_name = "FILE", default_value = "results.jsonl")]
    pub out: PathBuf,
    /// Replace --out even when it holds something other than a batch's results (a file
    /// whose first line is not `{"run": ...}`); without it such a file is refused.
    #[arg(long)]
    pub force: bool,
}

/// Runs `merge`: refuses parts of different runs, overlapping parts and gaps (naming the
/// missing units, exit 2); fails (exit 1) when an expectation fails on the mean over
/// training seeds, as `batch` does.
pub fn run(args: MergeArgs) -> anyhow::Result<()> {
    let guard = args
        .parts
        .iter()
        .fold(Outputs::results("--out", &args.out), |g, p| g.input("PART", p));
    guard.check(args.force)?;
    super::outputs::note_created("--out", args.out.parent().unwrap_or(std::path::Path::new("")));
    let _guard = guard.guard(args.force)?;
    let merged = merge(&args.parts)?;
    let report = write_merged(&merged, &args.out)?;
    print_summary(&report.rows);
    outln!(
        "merged {} part(s) into {} ({}) and {}; {} expectation(s) checked on the mean over training seeds, {} failed",
        args.parts.len(),
        report.out.display(),
        super::outputs::lines(merged.lines.len()),
        report.summary.display(),
        report.checked,
        report.failed
    );
    let failures = expectation_failures(&report.rows);
    if !failures.is_empty() {
        for f in &failures {
            errln!("expectation failed: {f}");
        }
        anyhow::bail!("{} expectation(s) failed", failures.len());
    }
    Ok(())
}
