//! What a search is given ([`SearchConfig`]) and its defaults.

use super::*;

/// Default share of the budget that the Sobol stage takes.
pub const DEFAULT_SOBOL_SHARE: f64 = 0.5;
/// Default rounds of the adaptive stage.
pub const DEFAULT_ROUNDS: usize = 5;
/// Default number of failures minimised and written as maps.
pub const DEFAULT_MAX_FAILURES: usize = 5;
/// Most candidates one search may have.
pub const MAX_BUDGET: usize = sampler::MAX_POINTS;

/// Everything a search needs.
pub struct SearchConfig<'a> {
    /// The space (with its base map).
    pub space: &'a Space,
    /// The method searched for failures.
    pub method: Method,
    /// Its trained agents (none for a scripted method), one per training seed.
    pub agents: &'a [Agent],
    /// The training seeds, in order (`[None]` for a scripted method).
    pub train_seeds: &'a [Option<u64>],
    /// What determines the agents (as in batch: an agent file's hash or the recipe).
    pub agents_identity: String,
    /// The evaluation protocol of the method.
    pub protocol: Protocol,
    /// Candidates of the Sobol and adaptive stages.
    pub budget: usize,
    /// Episodes per candidate and method (and training seed).
    pub episodes: u64,
    /// Run seed.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// A shard of the Sobol stage (then only that slice runs).
    pub shard: Option<Shard>,
    /// Share of the budget the Sobol stage takes, in (0, 1].
    pub sobol_share: f64,
    /// Rounds of the adaptive stage.
    pub rounds: usize,
    /// Failures minimised and written as maps.
    pub max_failures: usize,
    /// The command that ran the search, for the failure maps' comments.
    pub command: String,
}

impl SearchConfig<'_> {
    /// Candidates of the Sobol stage.
    pub fn sobol_count(&self) -> usize {
        ((self.budget as f64 * self.sobol_share).ceil() as usize).clamp(1, self.budget.max(1))
    }

    /// Sizes of the adaptive stage's rounds.
    pub fn round_sizes(&self) -> Vec<usize> {
        let rest = self.budget.saturating_sub(self.sobol_count());
        let rounds = self.rounds.max(1).min(rest.max(1));
        (0..rounds)
            .map(|r| rest * (r + 1) / rounds - rest * r / rounds)
            .filter(|&n| n > 0)
            .collect()
    }

    /// Checks the settings.
    pub fn check(&self) -> Result<(), Error> {
        Self::check_arguments(self.space, self.budget, self.sobol_share)?;
        if self.method.is_scripted() != self.agents.is_empty() && !self.method.is_scripted() {
            return Err(Error::MissingAgent { train_seed: None });
        }
        Ok(())
    }

    /// The checks of [`SearchConfig::check`] that need no agent, for a front to make
    /// before training any: the budget, the Sobol share and the space's dimensions.
    pub fn check_arguments(space: &Space, budget: usize, sobol_share: f64) -> Result<(), Error> {
        if budget == 0 || budget > MAX_BUDGET {
            return Err(Error::Request {
                field: "budget".into(),
                value: Some(budget.to_string()),
                problem: format!("expected 1 to {MAX_BUDGET} candidates"),
            });
        }
        if !(sobol_share > 0.0 && sobol_share <= 1.0) {
            return Err(Error::Request {
                field: "sobol_share".into(),
                value: Some(sobol_share.to_string()),
                problem: "expected a share in (0, 1]".into(),
            });
        }
        if space.params.len() > sampler::MAX_DIMENSIONS {
            return Err(Error::request("space", "too many parameters for the Sobol sequence"));
        }
        Ok(())
    }

    /// The run's identity (the first line of `candidates.jsonl`).
    pub fn identity(&self) -> SearchIdentity {
        let hash = |s: &str| unforeseen_env::seeds::content_hash(s.as_bytes());
        SearchIdentity {
            program: format!(
                "unforeseen {} (code {})",
                env!("CARGO_PKG_VERSION"),
                env!("UNFORESEEN_CODE_FINGERPRINT")
            ),
            space: (self.space.name.clone(), hash(&self.space.text)),
            base: (
                self.space.base.name.clone(),
                hash(&serde_json::to_string(&self.space.base).unwrap_or_default()),
            ),
            method: self.method.name().to_string(),
            agents: self.agents_identity.clone(),
            train_seeds: self.train_seeds.to_vec(),
            protocol: self.protocol,
            budget: self.budget,
            episodes: self.episodes,
            seed: self.seed,
            sobol_share: self.sobol_share,
            rounds: self.rounds,
            max_failures: self.max_failures,
        }
    }
}
