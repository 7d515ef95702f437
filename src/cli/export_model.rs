//! `unforeseen export-model`: a trained agent's planning model in the `inspect` JSON
//! layout, so that the reasoning tick can be rerun elsewhere (e.g. in pymdp, see
//! `scripts/pymdp_bench.py` and BENCHMARKS.md). The layout holds one transition model, the
//! planning one (episode-ending states absorbing); the agent's first planning step goes
//! through the learned `B` instead (`root_step`), which differs only from a state that
//! ends the episode, so from every other observation the exported tree is the agent's.

use clap::Args;
use std::path::PathBuf;
use unforeseen_agent::inspect::InspectModel;

use super::AgentArgs;
use unforeseen_harness::error::Error;
use unforeseen_harness::files::write_json;

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
    super::outputs::file("--out", &args.out, args.agent.inputs())?;
    let params = args.agent.params()?;
    let values: Vec<usize> = args
        .obs
        .split(',')
        .map(|v| v.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|e| {
            Error::flag(
                format!("--obs {}", args.obs),
                format!("{e} (expected integers, e.g. 2,3,1,1)"),
            )
        })?;
    let bundle = args.agent.bundle()?;
    let model = &bundle.world_model;
    let structure = model.structure();
    let factors = structure.factors();
    if values.len() != factors.len() {
        return Err(Error::flag(
            format!("--obs {}", args.obs),
            format!(
                "{} values given, the model has {} factors ({})",
                values.len(),
                factors.len(),
                factors.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(",")
            ),
        )
        .into());
    }
    if let Some((v, f)) = values.iter().zip(factors).find(|(v, f)| **v >= f.size) {
        return Err(Error::flag(
            format!("--obs {}", args.obs),
            format!("{}={v} is out of range (0..{})", f.name, f.size),
        )
        .into());
    }
    let gm = model.planning_generative();
    let exported = InspectModel::from_generative(
        gm,
        vec![structure.encode(&values)],
        vec![],
        params.planning.horizon,
        params.planning.gamma,
    );
    // JSON has no NaN or infinity (serde_json writes them as null): refuse rather than
    // write a model no reader can use. A checked agent file never gets here.
    let value = serde_json::to_value(&exported)?;
    if let Some(at) = first_null(&value, String::new()) {
        return Err(Error::Agent {
            problem: format!("the planning model has a value that is not a finite number at {at}"),
            fix: "retrain the agent with `unforeseen train`".into(),
        }
        .into());
    }
    super::warn_replacing_file(&args.out);
    write_json(&args.out, &exported)?;
    outln!(
        "wrote {} ({} states, {} actions, horizon {}, gamma {})",
        args.out.display(),
        gm.n_states(),
        gm.n_actions(),
        params.planning.horizon,
        params.planning.gamma
    );
    Ok(())
}

/// The path of the first null (a non-finite number) in `v`, e.g. `A[3][2]`.
fn first_null(v: &serde_json::Value, at: String) -> Option<String> {
    match v {
        serde_json::Value::Null => Some(at),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| first_null(x, format!("{at}[{i}]"))),
        serde_json::Value::Object(m) => m.iter().find_map(|(k, x)| {
            let here = if at.is_empty() { k.clone() } else { format!("{at}.{k}") };
            first_null(x, here)
        }),
        _ => None,
    }
}
