//! The identity of a batch run ([`RunIdentity`]), the first line of its results file,
//! and the identities of its agents (trained per seed, or from an agent file).

use serde::{Deserialize, Serialize};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_sim::Map;

use crate::episodes::methods::Method;
use crate::episodes::protocol::Protocol;
use crate::error::Error;

use super::scenario::Scenario;
use super::sweep::ParamSet;

/// What determines agents trained on `train_map` with `config` and each of `seeds` (the
/// config's seed replaced by each), for a run's identity: their cache keys (training map
/// contents, episodes, seed, training configuration such as what a time-out is to the
/// learners, version and training code; the agent cache's key, `cache_key` in `training/seed_agents.rs`).
pub fn trained_agents_identity(
    train_map: &Map,
    seeds: &[Option<u64>],
    config: &crate::training::TrainConfig,
) -> Result<String, Error> {
    let keys = seeds
        .iter()
        .flatten()
        .map(|&seed| {
            let config = crate::training::TrainConfig { seed, ..config.clone() };
            crate::training::seed_agents::cache_key(train_map, &config)
        })
        .collect::<Result<Vec<_>, Error>>()?;
    Ok(format!(
        "trained on {} for {} episodes, agents {}",
        train_map.name,
        config.episodes,
        unforeseen_env::seeds::content_hash(keys.join(",").as_bytes())
    ))
}

/// The agents of a run of scripted methods only given neither an agent file nor
/// training seeds, for its identity: none is trained or loaded (the units' training
/// seed is none).
pub const SCRIPTED_ONLY: &str = "none (scripted methods only)";

/// What determines an agent read from a file, for a run's identity: its contents.
pub fn agent_file_identity(bundle: &AgentBundle) -> String {
    format!(
        "agent file with contents {}",
        unforeseen_env::seeds::content_hash(bundle.to_ron_string().as_bytes())
    )
}

/// What determines a batch run's results, written as the first line of its results file
/// (`{"run": {...}}`). `--resume` continues a file only if its identity is this run's;
/// the shard is not part of it (shards of one run concatenate into one file).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunIdentity {
    /// The program that ran the units: crate version and a fingerprint of all the source
    /// that determines results (the crates, `src/` and Cargo.lock; build.rs), so a
    /// rebuilt program with changed code does not continue another's file.
    pub program: String,
    /// The agents: an agent file's content hash, or how they were trained.
    pub agents: String,
    /// The scenarios in order: name and a hash of the map's full contents (bases merged),
    /// or of a stream's name, maps, weights and order.
    pub maps: Vec<(String, String)>,
    /// Methods in order.
    pub methods: Vec<String>,
    /// Parameter sets in order (labels).
    pub param_sets: Vec<String>,
    /// Protocols in order.
    pub protocols: Vec<Protocol>,
    /// Training seeds in order.
    pub train_seeds: Vec<Option<u64>>,
    /// Episodes per unit.
    pub episodes: u64,
    /// Evaluation seed.
    pub seed: u64,
}

impl RunIdentity {
    /// The identity of a run of these inputs.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scenarios: &[Scenario],
        methods: &[Method],
        params: &[ParamSet],
        protocols: &[Protocol],
        train_seeds: &[Option<u64>],
        episodes: u64,
        seed: u64,
        agents: &str,
    ) -> Self {
        RunIdentity {
            program: format!(
                "unforeseen {} (code {})",
                env!("CARGO_PKG_VERSION"),
                env!("UNFORESEEN_CODE_FINGERPRINT")
            ),
            agents: agents.to_string(),
            maps: scenarios
                .iter()
                .map(|s| (s.name().to_string(), s.content_hash()))
                .collect(),
            methods: methods.iter().map(|m| m.name().to_string()).collect(),
            param_sets: params.iter().map(ParamSet::label).collect(),
            protocols: protocols.to_vec(),
            train_seeds: train_seeds.to_vec(),
            episodes,
            seed,
        }
    }

    /// One phrase per field that differs from `other` (`this` is the file's).
    pub fn differences(&self, other: &RunIdentity) -> Vec<String> {
        let a = serde_json::to_value(self).unwrap_or_default();
        let b = serde_json::to_value(other).unwrap_or_default();
        let short = |v: &serde_json::Value| {
            let t = v.to_string();
            if t.chars().count() > 160 {
                format!("{}...", t.chars().take(160).collect::<String>())
            } else {
                t
            }
        };
        let mut out = Vec::new();
        if let (Some(a), Some(b)) = (a.as_object(), b.as_object()) {
            for (k, va) in a {
                let vb = &b[k];
                if va != vb {
                    out.push(format!("{k}: the file has {}, this run {}", short(va), short(vb)));
                }
            }
        }
        out
    }

    /// The identity as the first line of a results file.
    pub(crate) fn to_line(&self) -> String {
        let mut s = serde_json::json!({ "run": self }).to_string();
        s.push('\n');
        s
    }
}

/// The first line of a results file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct IdentityLine {
    pub(super) run: RunIdentity,
}
