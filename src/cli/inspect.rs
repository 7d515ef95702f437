//! `unforeseen inspect --model FILE.json`: the agent's math on a model in pymdp's layout,
//! for cross-checking against the reference library: a single-factor model, or one with
//! several factors and modalities (`unforeseen_agent::aif::inspect`).

use clap::Args;
use std::path::PathBuf;

use unforeseen_harness::error::Error;

/// Arguments of `inspect`.
#[derive(Debug, Clone, Args)]
pub struct InspectArgs {
    /// Model JSON in pymdp's layout: {"A", "B", "C", "D", "obs", "actions", "policy_len", "gamma"}
    /// for one factor (obs a list of indices), or with A[m][o, s...], B[f][s', s..., u],
    /// "A_dependencies", "B_dependencies", "E", "pA", "pB" and obs a list of lists (one index
    /// per modality and step).
    #[arg(long, value_name = "FILE.json")]
    pub model: PathBuf,
}

/// Runs `inspect`, printing the report as JSON on stdout.
pub fn run(args: InspectArgs) -> anyhow::Result<()> {
    let text = unforeseen_harness::limits::read_model_file(&args.model)?;
    let out = unforeseen_agent::inspect::inspect_json(&text).map_err(|e| Error::ModelFile {
        path: args.model.clone(),
        problem: e.to_string(),
    })?;
    outln!("{out}");
    Ok(())
}
