//! `unforeseen merge`: join the shard files of one batch run, produced anywhere, into the
//! results file and summary one machine would have written ([`unforeseen_harness::runs::merge`]).

use clap::Args;
use std::path::PathBuf;

use super::batch::{failures, print_summary};
use unforeseen_harness::runs::merge::{merge, write_merged};

/// Arguments of `merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// The shard files (`unforeseen batch --shard I/N --out part-I.jsonl`), in any order.
    #[arg(value_name = "PART", required = true)]
    pub parts: Vec<PathBuf>,
    /// Merged results file; the summary goes beside it (`sweep.summary.json`).
    #[arg(long, value_name = "FILE", default_value = "results.jsonl")]
    pub out: PathBuf,
}

/// Runs `merge`: refuses parts of different runs, overlapping parts and gaps (naming the
/// missing units, exit 2); fails (exit 1) when an expectation fails on the mean over
/// training seeds, as `batch` does.
pub fn run(args: MergeArgs) -> anyhow::Result<()> {
    use super::outputs;
    outputs::file("--out", &args.out)?;
    let summary = unforeseen_harness::runs::batch::summary_path(&args.out);
    outputs::file("--out (its summary)", &summary)?;
    let inputs: Vec<(&str, &std::path::Path)> = args.parts.iter().map(|p| ("PART", p.as_path())).collect();
    outputs::not_an_input("--out", &args.out, &inputs)?;
    outputs::not_an_input("--out (its summary)", &summary, &inputs)?;
    let merged = merge(&args.parts)?;
    let report = write_merged(&merged, &args.out)?;
    print_summary(&report.rows);
    outln!(
        "merged {} part(s) into {} ({} lines) and {}; {} expectation(s) checked on the mean over training seeds, {} failed",
        args.parts.len(),
        report.out.display(),
        merged.lines.len(),
        report.summary.display(),
        report.checked,
        report.failed
    );
    let failures = failures(&report.rows);
    if !failures.is_empty() {
        for f in &failures {
            errln!("expectation failed: {f}");
        }
        anyhow::bail!("{} expectation(s) failed", failures.len());
    }
    Ok(())
}
