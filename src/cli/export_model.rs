//! `unforeseen export-model`: a trained agent's planning model in the `inspect` JSON
//! layout, so that the reasoning tick can be rerun elsewhere (e.g. in pymdp, see
//! `scripts/pymdp_bench.py` and BENCHMARKS.md).

use clap::Args;
use std::path::PathBuf;
use unforeseen_agent::inspect::InspectModel;

use super::{AgentArgs, BadInput};
use crate::report::write_json;

/// Arguments of `export-model`.
#[derive(Debug, Clone, Args)]
pub struct ExportModelArgs {
    /// The observation to evaluate, as factor values `d,v,L,p` (default: the jaywalk
    /// observation of `reasoning_tick/H`: d=2, v=3, green, pedestrian on the crosswalk).
    #[arg(long, default_value = "2,3,1,1", value_name = "d,v,L,p")]
    pub obs: String,
    /// Output file.
    #[arg(long, default_value = "out/model.json", value_name = "FILE.json")]
    pub out: PathBuf,
    /// Trained agent; `--set horizon=H --set gamma=G` choose the exported policy length
    /// and precision.
    #[command(flatten)]
    pub agent: AgentArgs,
}

/// Runs `export-model`: writes A, the planning B (terminal states absorbing), C, D, the
/// observation, the horizon and γ of the scaled agent's parameters.
pub fn run(args: ExportModelArgs) -> anyhow::Result<()> {
    let params = args.agent.params()?;
    let values: Vec<usize> = args
        .obs
        .split(',')
        .map(|v| v.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|e| BadInput(format!("--obs {}: {e} (expected integers, e.g. 2,3,1,1)", args.obs)))?;
    let bundle = args.agent.bundle()?;
    let model = &bundle.world_model;
    let structure = model.structure();
    let factors = structure.factors();
    if values.len() != factors.len() {
        return Err(BadInput(format!(
            "--obs {}: {} values given, the model has {} factors ({})",
            args.obs,
            values.len(),
            factors.len(),
            factors.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(",")
        ))
        .into());
    }
    if let Some((v, f)) = values.iter().zip(factors).find(|(v, f)| **v >= f.size) {
        return Err(BadInput(format!(
            "--obs {}: {}={v} is out of range (0..{})",
            args.obs, f.name, f.size
        ))
        .into());
    }
    let gm = model.planning_generative();
    let exported = InspectModel::from_generative(
        gm,
        vec![structure.encode(&values)],
        vec![],
        params.horizon,
        params.gamma,
    );
    super::warn_replacing_file(&args.out);
    write_json(&args.out, &exported)?;
    println!(
        "wrote {} ({} states, {} actions, horizon {}, gamma {})",
        args.out.display(),
        gm.n_states(),
        gm.n_actions(),
        params.horizon,
        params.gamma
    );
    Ok(())
}
