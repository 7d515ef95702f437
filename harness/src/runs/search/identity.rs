//! What determines a search's results ([`SearchIdentity`]): the first line of
//! `candidates.jsonl`.

use super::*;

/// What determines a search's results (the first line of `candidates.jsonl`,
/// `{"search": {...}}`); the shard is not part of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SearchIdentity {
    /// Program version and code fingerprint.
    pub program: String,
    /// The space: name and a hash of its file.
    pub space: (String, String),
    /// The base map: name and a hash of its contents.
    pub base: (String, String),
    /// The method searched.
    pub method: String,
    /// The agents.
    pub agents: String,
    /// Training seeds.
    pub train_seeds: Vec<Option<u64>>,
    /// Protocol.
    pub protocol: Protocol,
    /// Budget.
    pub budget: usize,
    /// Episodes per evaluation.
    pub episodes: u64,
    /// Seed.
    pub seed: u64,
    /// Share of the Sobol stage.
    pub sobol_share: f64,
    /// Adaptive rounds.
    pub rounds: usize,
    /// Failures minimised.
    pub max_failures: usize,
}

impl SearchIdentity {
    /// One phrase per field that differs from `other` (`self` is the file's).
    pub fn differences(&self, other: &SearchIdentity) -> Vec<String> {
        crate::runs::resume::differences(self, other)
    }
}
